//! Where a phantom lies: on a piece of clutter, beside furniture, at a doorway, at a wall face,
//! or in the open (`Tally::phantoms_where`), by the distances below.

use perception::geometry::Point2;

use crate::run_truth::{Furniture, RunTruth};

/// A phantom lies at a wall face when within this distance of it.
pub const WALL_FACE_M: f32 = 0.15;
/// A phantom lies on a piece of clutter when within this distance of its centre.
pub const CLUTTER_M: f32 = 0.5;
/// A phantom lies beside a piece of furniture when within this distance of its footprint.
pub const BESIDE_M: f32 = 0.8;
/// A phantom lies at a doorway when within this distance of its centre.
pub const DOORWAY_M: f32 = 1.0;
/// Names of `Tally::phantoms_where`.
pub const PHANTOM_PLACES: [&str; 5] = [
    "clutter",
    "beside furniture",
    "doorway",
    "wall face",
    "open",
];

/// Whether `p` lies within `WALL_FACE_M` of a wall face.
pub(super) fn at_wall_face(truth: &RunTruth, p: Point2) -> bool {
    truth
        .walls
        .iter()
        .any(|(a, b)| p.distance_to_segment(*a, *b) <= WALL_FACE_M)
}

/// Where a phantom at `p` lies: an index into `PHANTOM_PLACES`.
pub(super) fn phantom_place(truth: &RunTruth, alive: &[&Furniture], p: Point2) -> usize {
    if truth
        .clutter
        .iter()
        .any(|(c, _)| c.distance(p) <= CLUTTER_M)
    {
        0
    } else if alive.iter().any(|f| f.distance(p) <= BESIDE_M) {
        1
    } else if truth
        .doors
        .iter()
        .any(|d| d.centre.distance(p) <= DOORWAY_M)
    {
        2
    } else if at_wall_face(truth, p) {
        3
    } else {
        4
    }
}
