//! # umbra lab
//!
//! umbra's workbench, for the host only and never flashed to a robot: Method A's training rows
//! and forest, the evaluators of both methods against the simulator's truth, the pose-drift
//! table and the figures the docs quote. It depends on the simulator, the models (with the
//! forest trainer) and the perception core; nothing on the robot's path depends on it.
//!
//! | module            | owns                                                             |
//! |-------------------|------------------------------------------------------------------|
//! | [`scenes_a`]      | Method A run on simulated scenes, with truth labels for training and scoring |
//! | [`eval_a`]        | Method A scored against the simulator's truth; forest training rows |
//! | [`eval_b`]        | Method B scored on a dataset split: P, R, mAP50, mAP50-95 as Ultralytics does |
//! | [`canvas`]        | an RGB canvas with a built-in font, written as PNG (the figures)   |
//! | [`confusion_png`] | the evaluation's confusion matrix as a PNG                        |
//! | [`pose_eval`]     | drift of odometry, compass overwrite and our fusion on the simulator |
//! | [`run_truth`]     | what a world-evaluation run really held (both scene families write it) |
//! | [`world_eval`]    | `eval-world`: `umbra replay`'s world scored on two scene families |
//! | [`annex`]         | the second scene family, written apart and never trained or tuned on |
#![deny(unsafe_code, missing_docs)]

pub mod annex;
pub mod canvas;
pub mod confusion_png;
pub mod eval_a;
pub mod eval_b;
pub mod pose_eval;
pub mod run_truth;
pub mod scenes_a;
pub mod world_eval;
