//! Association: which observation updates which track. The cheapest (track, observation) pair
//! is taken first until none is left (greedy on the global minimum; `benches/world_model.rs`
//! compares it with an optimal assignment), and the class rule says which pairs may be one
//! object at all. Used by the object tracks and the walker table alike.

use super::TrackConfig;
use crate::class::ObjectClass;

/// The cheapest (track `i`, observation `k`) pair neither of which is taken yet (`matched`,
/// `used`), by `cost` (`None`: they cannot be one); ties go to the first found, tracks in
/// order, then observations. Both tables associate greedily on the global minimum with it.
pub(super) fn cheapest(
    matched: &[bool],
    used: &[bool],
    tracks: usize,
    obs: usize,
    cost: impl Fn(usize, usize) -> Option<f32>,
) -> Option<(usize, usize)> {
    let mut best: Option<(f32, usize, usize)> = None;
    for i in (0..tracks).filter(|&i| !matched[i]) {
        for k in (0..obs).filter(|&k| !used[k]) {
            if let Some(c) = cost(i, k)
                && best.is_none_or(|b| c < b.0)
            {
                best = Some((c, i, k));
            }
        }
    }
    best.map(|(_, i, k)| (i, k))
}

/// Class compatibility cost: `None` when the two cannot be one object.
pub(super) fn class_cost(track: ObjectClass, obs: ObjectClass, cfg: &TrackConfig) -> Option<f32> {
    use ObjectClass::DoorFrame;
    match (track == DoorFrame, obs == DoorFrame) {
        (true, true) => Some(0.0),
        (false, false) if track == obs => Some(0.0),
        (false, false) => Some(cfg.class_change_cost_m),
        _ => None,
    }
}
