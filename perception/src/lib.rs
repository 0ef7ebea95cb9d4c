//! # umbra perception
//!
//! The `no_std`, allocation-free core of umbra's perception. It builds for bare-metal targets
//! (CI checks `thumbv7em-none-eabihf` with no allocator) and never depends on the binary, the
//! simulator or tract.
//!
//! | module         | owns                                                         |
//! |----------------|--------------------------------------------------------------|
//! | [`geometry`]   | 2D points and rigid poses in REP 103 (x forward, y left, CCW) |
//! | [`class`]      | the object classes both methods report, with their wire names |
//! | [`pose`]       | wheel odometry, hard-iron fit, compass/odometry heading filter |
//! | [`raster`]     | three revolutions as the 64 × 384 × 3 image of Method B (bit-exact spec) |
//!
//! The global point cloud, DBSCAN, walls and doors, features and YOLO decoding
//! arrive with their issues; each capacity is a named constant listed in `memory-budget.md`.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(unsafe_code, missing_docs)]

pub mod class;
pub mod geometry;
pub mod pose;
pub mod raster;
