//! Merging DBSCAN fragments into objects.
//!
//! At LiDAR height a chair or a desk is four legs, and DBSCAN (ε ≤ 0.32 m) finds each leg as
//! its own cluster; a box may be cut in two by something in front of it. Fragments are merged
//! agglomeratively, closest group centroids first (a group's centroid is the mean of its
//! fragments' centroids, so a leg seen by more rays does not pull it). Two groups merge when
//! **every fragment's centroid lies within `link_m` (1.3 m) of the merged centroid**, the
//! paper's "centroid distance ≤ 1.3 m" read as the object's radius: a 1.9 m desk's legs are
//! 1.04 m from its centre, while the distance between two halves of it is 1.5–1.9 m.
//!
//! On its own that rule fuses neighbours: two chairs 0.7 m apart are one 1.5 m "object". The
//! guards, each a setting so that the evaluation can measure it alone:
//! - **legs**: a fragment whose box is at most `leg_max_m` (0.15 m) long is a leg; a merged
//!   object has at most `max_legs` (4) of them;
//! - **solid**: a fragment longer than a leg (a box face, a wall piece) only merges with other
//!   solid fragments, and only into something no longer than `max_solid_length_m` (0.8 m):
//!   one box cut by an occluder comes back together, nothing else does;
//! - **extent**: the merged object's minimum-area box (over its fragments' box corners) is at
//!   most `max_length_m` × `max_width_m` (2.1 × 1.2 m, the largest desk with margin).
//!
//! A refused pair is not tried again until one of its groups changes. Cost: O(k²) per merge for
//! k fragments (k ≤ [`MAX_CLUSTERS`]).

use crate::dbscan::MAX_CLUSTERS;
use crate::geometry::Point2;
use crate::shape::{self, OrientedBox};

/// Merge settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MergeConfig {
    /// Largest distance from a fragment's centroid to its object's centroid, metres.
    pub link_m: f32,
    /// Longest fragment that counts as a leg, metres.
    pub leg_max_m: f32,
    /// Leg guard on.
    pub guard_legs: bool,
    /// Most legs an object may have.
    pub max_legs: u8,
    /// Solid guard on.
    pub guard_solid: bool,
    /// Longest object that solid fragments may form, metres.
    pub max_solid_length_m: f32,
    /// Extent guard on.
    pub guard_extent: bool,
    /// Longest object, metres.
    pub max_length_m: f32,
    /// Widest object, metres.
    pub max_width_m: f32,
}

impl Default for MergeConfig {
    fn default() -> Self {
        MergeConfig {
            link_m: 1.3,
            leg_max_m: 0.15,
            guard_legs: true,
            max_legs: 4,
            guard_solid: true,
            max_solid_length_m: 0.8,
            guard_extent: true,
            max_length_m: 2.1,
            max_width_m: 1.2,
        }
    }
}

/// A fragment to merge.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fragment {
    /// Its cluster in the DBSCAN output.
    pub cluster: u16,
    /// Centroid.
    pub centroid: Point2,
    /// Minimum-area box.
    pub bbox: OrientedBox,
}

impl Fragment {
    fn is_leg(&self, cfg: &MergeConfig) -> bool {
        self.bbox.length <= cfg.leg_max_m
    }
}

/// Merges refused, by guard (each refusal of a pair counts once per attempt).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MergeStats {
    /// Refused for too many legs.
    pub refused_legs: u32,
    /// Refused because a solid fragment was involved.
    pub refused_solid: u32,
    /// Refused for the merged extent.
    pub refused_extent: u32,
    /// Merges done.
    pub merges: u32,
}

/// Merges `frags`; writes each fragment's group (0..n) to `group` and returns n.
#[allow(clippy::needless_range_loop)] // a and b index four parallel arrays
pub fn merge(
    frags: &[Fragment],
    cfg: &MergeConfig,
    group: &mut [u8],
    stats: &mut MergeStats,
) -> usize {
    let k = frags.len().min(MAX_CLUSTERS).min(group.len());
    for (i, g) in group.iter_mut().enumerate().take(k) {
        *g = i as u8;
    }
    let mut refused = [0u128; MAX_CLUSTERS];
    let mut alive = [false; MAX_CLUSTERS];
    alive[..k].fill(true);
    // Per group: sum of fragment centroids and their number.
    let mut sum = [Point2::default(); MAX_CLUSTERS];
    let mut cnt = [0.0f32; MAX_CLUSTERS];
    for (i, f) in frags[..k].iter().enumerate() {
        sum[i] = f.centroid;
        cnt[i] = 1.0;
    }
    let mean =
        |sum: &[Point2], cnt: &[f32], g: usize| Point2::new(sum[g].x / cnt[g], sum[g].y / cnt[g]);
    loop {
        let mut best: Option<(f32, usize, usize)> = None;
        for a in 0..k {
            if !alive[a] {
                continue;
            }
            let ma = mean(&sum, &cnt, a);
            for b in a + 1..k {
                if !alive[b] || refused[a] & (1u128 << b) != 0 {
                    continue;
                }
                let d = ma.distance(mean(&sum, &cnt, b));
                if d <= 2.0 * cfg.link_m && best.is_none_or(|x| d < x.0) {
                    best = Some((d, a, b));
                }
            }
        }
        let Some((_, a, b)) = best else { break };
        let joint = Point2::new(
            (sum[a].x + sum[b].x) / (cnt[a] + cnt[b]),
            (sum[a].y + sum[b].y) / (cnt[a] + cnt[b]),
        );
        if admissible(frags, &group[..k], a as u8, b as u8, joint, cfg, stats) {
            for g in group[..k].iter_mut() {
                if *g == b as u8 {
                    *g = a as u8;
                }
            }
            sum[a] = sum[a] + sum[b];
            cnt[a] += cnt[b];
            alive[b] = false;
            refused[a] = 0;
            for r in refused.iter_mut() {
                *r &= !(1u128 << a);
            }
            stats.merges += 1;
        } else {
            refused[a] |= 1u128 << b;
        }
    }
    // Renumber groups densely in order of first fragment.
    let mut map = [u8::MAX; MAX_CLUSTERS];
    let mut n = 0u8;
    for g in group[..k].iter_mut() {
        if map[*g as usize] == u8::MAX {
            map[*g as usize] = n;
            n += 1;
        }
        *g = map[*g as usize];
    }
    n as usize
}

fn admissible(
    frags: &[Fragment],
    group: &[u8],
    a: u8,
    b: u8,
    centre: Point2,
    cfg: &MergeConfig,
    stats: &mut MergeStats,
) -> bool {
    let members = || {
        frags
            .iter()
            .zip(group)
            .filter(move |(_, g)| **g == a || **g == b)
            .map(|(f, _)| f)
    };
    if members().any(|f| f.centroid.distance(centre) > cfg.link_m) {
        return false;
    }
    let legs = members().filter(|f| f.is_leg(cfg)).count();
    let solids = members().count() - legs;
    if cfg.guard_legs && legs > cfg.max_legs as usize {
        stats.refused_legs += 1;
        return false;
    }
    let mut corners = [Point2::default(); 4 * MAX_CLUSTERS];
    let mut nc = 0;
    for f in members() {
        for c in f.bbox.corners() {
            corners[nc] = c;
            nc += 1;
        }
    }
    let ext = shape::min_area_box(&[&corners[..nc]]);
    if cfg.guard_solid && solids > 0 && (legs > 0 || ext.length > cfg.max_solid_length_m) {
        stats.refused_solid += 1;
        return false;
    }
    if cfg.guard_extent && (ext.length > cfg.max_length_m || ext.width > cfg.max_width_m) {
        stats.refused_extent += 1;
        return false;
    }
    true
}

#[cfg(test)]
mod test {
    use super::*;

    fn leg(x: f32, y: f32) -> Fragment {
        Fragment {
            cluster: 0,
            centroid: Point2::new(x, y),
            bbox: OrientedBox {
                centre: Point2::new(x, y),
                angle: 0.0,
                length: 0.04,
                width: 0.03,
            },
        }
    }

    fn chair(out: &mut std::vec::Vec<Fragment>, x: f32, y: f32) {
        for (dx, dy) in [(-0.2, -0.2), (0.2, -0.2), (0.2, 0.2), (-0.2, 0.2)] {
            out.push(leg(x + dx, y + dy));
        }
    }

    fn groups(frags: &[Fragment], cfg: &MergeConfig) -> (usize, std::vec::Vec<u8>, MergeStats) {
        let mut g = std::vec![0u8; frags.len()];
        let mut st = MergeStats::default();
        let n = merge(frags, cfg, &mut g, &mut st);
        (n, g, st)
    }

    #[test]
    fn a_large_desk_becomes_one_object() {
        let mut f = std::vec::Vec::new();
        for (x, y) in [(0.0, 0.0), (1.85, 0.0), (1.85, 0.9), (0.0, 0.9)] {
            f.push(leg(x, y));
        }
        let (n, _, st) = groups(&f, &MergeConfig::default());
        assert_eq!(n, 1);
        assert_eq!(st.merges, 3);
    }

    #[test]
    fn two_chairs_stay_apart_only_with_the_guard() {
        let mut f = std::vec::Vec::new();
        chair(&mut f, 0.0, 0.0);
        chair(&mut f, 1.1, 0.0);
        let (n, g, st) = groups(&f, &MergeConfig::default());
        assert_eq!(n, 2, "{g:?}");
        assert!(g[..4].iter().all(|&x| x == g[0]) && g[4..].iter().all(|&x| x == g[4]));
        assert!(st.refused_legs > 0);
        let off = MergeConfig {
            guard_legs: false,
            guard_solid: false,
            guard_extent: false,
            ..MergeConfig::default()
        };
        assert_eq!(groups(&f, &off).0, 1);
    }

    #[test]
    fn solid_fragments_do_not_join_legs() {
        let mut f = std::vec::Vec::new();
        chair(&mut f, 0.0, 0.0);
        f.push(Fragment {
            cluster: 4,
            centroid: Point2::new(0.9, 0.0),
            bbox: OrientedBox {
                centre: Point2::new(0.9, 0.0),
                angle: 0.0,
                length: 0.6,
                width: 0.4,
            },
        });
        let (n, g, _) = groups(&f, &MergeConfig::default());
        assert_eq!(n, 2);
        assert_ne!(g[0], g[4]);
    }

    #[test]
    fn nothing_and_one() {
        assert_eq!(groups(&[], &MergeConfig::default()).0, 0);
        assert_eq!(groups(&[leg(0.0, 0.0)], &MergeConfig::default()).0, 1);
    }
}
