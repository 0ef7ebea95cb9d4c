//! # umbra models
//!
//! Home of the trained models.
//!
//! | module            | owns                                                           |
//! |-------------------|----------------------------------------------------------------|
//! | [`calibration`]   | the detections' score calibration (`no_std`), from [`calibration_counts`] |
//! | [`conventions`]   | what a Method B file declares about its images (seam, swept labels; `no_std`) |
//! | [`forest`]        | the Method A classifier at run time over `const` tables (`no_std`) |
//! | [`forest_tables`] | the trained forest, generated from `models/data/forest-train.csv` |
//! | `int8_kernel`     | the int8 matrix kernel tract runs on x86-64 AVX2 hosts without VNNI (`yolo`) |
//! | [`report_model`]  | the world model's report model (`no_std`), from `training/fit_report_model.py` |
//! | `train`           | the forest trainer and table emitter (`train` feature: the lab's, host only) |
//! | `yolo`            | the Method B YOLOv8n runner over tract (`yolo` feature, host and Pi) |
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(unsafe_code, missing_docs)]

pub use perception::class::ObjectClass;

pub mod calibration;
#[rustfmt::skip]
pub mod calibration_counts;
pub mod conventions;
pub mod forest;
#[rustfmt::skip]
pub mod forest_tables;
#[cfg(all(feature = "yolo", target_arch = "x86_64"))]
pub mod int8_kernel;
#[rustfmt::skip]
pub mod report_model;
#[cfg(feature = "train")]
pub mod train;
#[cfg(feature = "yolo")]
pub mod yolo;

/// Class order of the model outputs (the index of a class score is its position here).
pub const CLASSES: [ObjectClass; 4] = ObjectClass::ALL;
