//! Association: which observation updates which track. The cheapest (track, observation) pair
//! is taken first until none is left (greedy on the global minimum; `benches/world_model.rs`
//! compares it with an optimal assignment), and the class rule says which pairs may be one
//! object at all. Used by the object tracks and the walker table alike.
//!
//! Each pair's cost is worked out once a frame: the gated pairs are sorted by cost, ties by
//! track and then observation, and taken in that order while both are free ([`greedy`]). That
//! takes exactly the pairs, in the order, that looking for the cheapest free pair again after
//! each take ([`cheapest`]) does, in O(n log n) instead of O(n³) (a pair's cost depends on its
//! own track and observation only). A frame with more than [`MAX_PAIRS`] gated pairs is
//! associated the slow way, with the same result.

use heapless::Vec;

use super::{MAX_TRACKS, TrackConfig};
use crate::class::ObjectClass;

/// Gated (track, observation) pairs sorted at once, at most: a frame gives a few per
/// observation (20–40 observations, 40–64 tracks); more go the slow way (the cheapest free
/// pair looked for again after each take).
pub const MAX_PAIRS: usize = 512;

/// Pairs taken in one frame, at most: one per track.
pub const MAX_TAKEN: usize = MAX_TRACKS;

/// The pairs greedy association on the global minimum takes, in the order it takes them
/// (`cost`: `None` when track `i` and observation `k` cannot be one; not a number: neither),
/// each marked in `matched` (tracks) and `used` (observations) as it is taken; pairs already
/// marked are not taken. The first [`MAX_TAKEN`]; indices below 2¹⁶ (the tables hold far
/// fewer).
pub(super) fn greedy(
    matched: &mut [bool],
    used: &mut [bool],
    tracks: usize,
    obs: usize,
    cost: impl Fn(usize, usize) -> Option<f32>,
) -> Vec<(u16, u16), MAX_TAKEN> {
    let (tracks, obs) = (tracks.min(matched.len()), obs.min(used.len()));
    let finite = |i, k| cost(i, k).filter(|c: &f32| c.is_finite());
    let mut taken = Vec::new();
    let mut pairs: Vec<(f32, u16, u16), MAX_PAIRS> = Vec::new();
    let mut overflow = false;
    'fill: for i in (0..tracks).filter(|&i| !matched[i]) {
        for k in (0..obs).filter(|&k| !used[k]) {
            if let Some(c) = finite(i, k)
                && pairs.push((c, i as u16, k as u16)).is_err()
            {
                overflow = true;
                break 'fill;
            }
        }
    }
    if overflow {
        while let Some((i, k)) = cheapest(matched, used, tracks, obs, finite) {
            if taken.push((i as u16, k as u16)).is_err() {
                break;
            }
            matched[i] = true;
            used[k] = true;
        }
        return taken;
    }
    pairs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    for &(_, i, k) in pairs.iter() {
        let (iu, ku) = (usize::from(i), usize::from(k));
        if matched[iu] || used[ku] {
            continue;
        }
        if taken.push((i, k)).is_err() {
            break; // more pairs than tracks cannot be; none is marked that is not taken
        }
        matched[iu] = true;
        used[ku] = true;
    }
    taken
}

/// The cheapest (track `i`, observation `k`) pair neither of which is taken yet (`matched`,
/// `used`), by `cost` (`None`: they cannot be one); ties go to the first found, tracks in
/// order, then observations: [`greedy`]'s slow way, and its reference in the tests.
fn cheapest(
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

#[cfg(test)]
mod test {
    use super::*;

    /// The slow way: the cheapest free pair, again and again.
    fn reference(
        tracks: usize,
        obs: usize,
        cost: &impl Fn(usize, usize) -> Option<f32>,
    ) -> std::vec::Vec<(usize, usize)> {
        let (mut matched, mut used) = ([false; 64], [false; 200]);
        let mut out = std::vec::Vec::new();
        while let Some((i, k)) = cheapest(&matched, &used, tracks, obs, cost) {
            matched[i] = true;
            used[k] = true;
            out.push((i, k));
        }
        out
    }

    fn wide(pairs: &[(u16, u16)]) -> std::vec::Vec<(usize, usize)> {
        pairs
            .iter()
            .map(|&(i, k)| (usize::from(i), usize::from(k)))
            .collect()
    }

    /// A small deterministic generator (xorshift), so the cases need no crate.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
    }

    #[test]
    fn sorted_pairs_take_what_the_cheapest_pair_again_and_again_takes() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for case in 0..400 {
            let tracks = (rng.next() % 65) as usize;
            let obs = (rng.next() % 41) as usize;
            // Coarse costs make ties common; some pairs gated out.
            let gate = rng.next() % 100;
            let costs: std::vec::Vec<Option<f32>> = (0..tracks * obs)
                .map(|_| (rng.next() % 100 < gate).then(|| (rng.next() % 8) as f32 * 0.25))
                .collect();
            let cost = |i: usize, k: usize| costs[i * obs + k];
            let (mut matched, mut used) = ([false; 64], [false; 200]);
            let taken = wide(&greedy(&mut matched, &mut used, tracks, obs, cost));
            let want = reference(tracks, obs, &cost);
            assert_eq!(taken, want, "case {case}");
            for &(i, k) in &want {
                assert!(matched[i] && used[k]);
            }
        }
    }

    #[test]
    fn more_gated_pairs_than_sorted_at_once_go_the_slow_way_alike() {
        // 64 tracks × 40 observations, every pair gated in: 2,560 > MAX_PAIRS.
        let cost = |i: usize, k: usize| Some(((i * 7 + k * 13) % 17) as f32);
        let (mut matched, mut used) = ([false; 64], [false; 200]);
        let taken = wide(&greedy(&mut matched, &mut used, 64, 40, cost));
        const { assert!(64 * 40 > MAX_PAIRS) };
        assert_eq!(taken, reference(64, 40, &cost));
        assert_eq!(taken.len(), 40);
    }

    #[test]
    fn pairs_already_taken_and_costs_not_a_number_are_left() {
        let (mut matched, mut used) = ([false; 4], [false; 4]);
        matched[0] = true;
        used[1] = true;
        let cost = |i: usize, k: usize| match (i, k) {
            (2, 2) => Some(f32::NAN),
            _ => Some((i + k) as f32),
        };
        let taken = greedy(&mut matched, &mut used, 3, 3, cost);
        // Track 0 and observation 1 were taken; (2, 2) cannot be one.
        assert_eq!(taken.as_slice(), &[(1u16, 0u16)]);
        assert!(!used[2] && !matched[2]);
    }
}
