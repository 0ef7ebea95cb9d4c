//! Reports the truth cannot call right or wrong yet: at the old place of a piece taken away or
//! moved, before the LiDAR has seen that place empty (`Tally::unrefuted`). Nothing the robot
//! has sensed says the piece went, and a map must keep what is out of view; from the
//! revolution that sees the place empty on (the truth's `seen_empty`), a report there is a
//! phantom like any other.

use perception::geometry::Point2;

use crate::run_truth::RunTruth;

/// Whether `p` lies within `within` m of the old footprint of a piece that had left by frame
/// `fi` and whose place the LiDAR had not yet seen empty then.
pub(super) fn unrefuted(truth: &RunTruth, fi: usize, p: Point2, within: f32) -> bool {
    truth.moves.iter().any(|m| {
        fi >= m.frame
            && m.seen_empty.is_none_or(|s| fi < s)
            && truth
                .furniture
                .get(m.before)
                .is_some_and(|f| f.distance(p) <= within)
    })
}
