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
//! | [`scan_match`] | each revolution laid on a keyframe's (point-to-line ICP): a pose that does not drift |
//! | [`raster`]     | three revolutions as the 64 × 384 × 3 image of Method B (bit-exact spec) |
//! | [`seam`]       | where the raster starts: its edges on a plain wall, not through furniture |
//! | [`sweep`]      | where the LiDAR stood when it read each bearing of a revolution |
//! | [`cloud`]      | Method A's global point cloud: a fixed ring with aging |
//! | [`dbscan`]     | adaptive-ε DBSCAN, grid-indexed and allocation-free |
//! | [`shape`]      | centroid, principal-axes and minimum-area boxes of point sets |
//! | [`walls`]      | the wall test, line segments fitted to walls, corners |
//! | [`doors`]      | door frames from pairs of wall segments |
//! | [`merge`]      | fragments (legs, pieces) merged into objects, with guards |
//! | [`features`]   | the 9-D feature vector, in the object's frame or the map's |
//! | [`method_a`]   | the geometric pipeline end to end, classifier as a parameter |
//! | [`yolo`]       | Method B's output: YOLOv8 decode, suppression, map-frame centres |
//! | [`mirror_look`] | Method B's second look at the mirrored raster; the two looks' boxes fused |
//! | [`plausible`]  | furniture that cannot be: centres in or behind a wall seen this revolution |
//! | [`wall_map`]   | the map's wall lines, gathered over revolutions; what lies in a wall's band |
//! | [`map_doors`]  | doorways in the map's walls that this revolution's rays pass through |
//! | [`wall_piece`] | a detection whose returns lie on a line that goes on as a wall does |
//! | [`outline`]    | a "box" whose returns lie on an arc (a bin, a round pillar) |
//! | [`outline_average`] | a still object's outline averaged over revolutions, fitted as one |
//! | [`fusion`]     | one frame's objects from both methods: A's, and B's joined or added |
//! | [`calibration`] | what a detection's score means: a measured probability per source and class |
//! | [`sight`]      | what a revolution showed of a footprint (hidden, in view, seen empty) or a doorway |
//! | [`free_floor`] | where the floor has been seen empty: revolutions counted per cell around the start |
//! | [`still_legs`] | where leg-sized things stand still: a background for the leg detector |
//! | [`motion`]     | a track's alpha–beta motion filter; walking legs told from furniture |
//! | [`legs`]       | people's legs in a revolution: leg-sized free-standing blobs, paired |
//! | [`tracks`]     | the world model's tracks: stable ids, association, evidence, negative evidence |
//!
//! Each capacity is a named constant listed in
//! `memory-budget.md`.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![deny(unsafe_code, missing_docs)]

pub mod calibration;
pub mod class;
pub mod cloud;
pub mod dbscan;
pub mod doors;
pub mod features;
pub mod free_floor;
pub mod fusion;
pub mod geometry;
pub mod legs;
pub mod map_doors;
pub mod merge;
pub mod method_a;
pub mod mirror_look;
pub mod motion;
pub mod outline;
pub mod outline_average;
pub mod plausible;
pub mod pose;
pub mod raster;
pub mod scan_match;
pub mod seam;
pub mod shape;
pub mod sight;
pub mod still_legs;
pub mod sweep;
pub mod tracks;
pub mod wall_map;
pub mod wall_piece;
pub mod walls;
pub mod yolo;
