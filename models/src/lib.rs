//! # umbra models
//!
//! Home of the trained models: the Method A random forest compiled in as `const` tables and the
//! Method B YOLOv8n runner (tract). Neither has landed yet (their issues are open); until then
//! this crate only fixes the class order both will use.
#![deny(unsafe_code, missing_docs)]

pub use perception::class::ObjectClass;

/// Class order of the model outputs (the index of a class score is its position here).
pub const CLASSES: [ObjectClass; 4] = ObjectClass::ALL;
