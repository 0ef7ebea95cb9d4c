//! Shared helpers of umbra's hardware-in-the-loop and end-to-end tests (in `tests/`).
#![deny(missing_docs)]

use std::path::PathBuf;

/// The shared data folder (`../shared/data` beside the repository), if present.
pub fn shared_data() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    dir.is_dir().then_some(dir)
}
