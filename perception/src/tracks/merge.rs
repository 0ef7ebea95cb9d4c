//! One object seen twice: tracks of one class closer than the class's merge radius (and, where
//! set, furniture tracks of different classes closer than `cross_merge_m`) become one track,
//! which keeps the reported id and takes the other's evidence.

use crate::class::ObjectClass;
use crate::geometry::Point2;

use super::association::class_cost;
use super::{Track, TrackConfig, Tracks};

/// Two tracks of one class closer than this are one object seen twice, m: less than the
/// closest two distinct pieces of the class stand (chairs side by side ~0.45 m, desks back
/// to back ~0.8 m).
fn merge_radius(c: ObjectClass) -> f32 {
    match c {
        ObjectClass::Chair | ObjectClass::Box => 0.35,
        ObjectClass::Desk => 0.7,
        ObjectClass::DoorFrame => 0.5,
    }
}

impl Tracks {
    /// Tracks of one class within its [`merge_radius`] are one object: the confirmed one (then
    /// the one with more hits, then the older) keeps its id and takes the other's evidence.
    /// Tracks of different classes that may be one object (the association's rule,
    /// [`class_cost`]: furniture with furniture) closer than [`TrackConfig::cross_merge_m`]
    /// (0: never) are one piece too: its class is then the one the summed evidence favours.
    pub(super) fn merge_duplicates(&mut self, cfg: &TrackConfig) {
        let mut i = 0;
        while i < self.tracks.len() {
            let mut j = i + 1;
            while j < self.tracks.len() {
                let (a, b) = (&self.tracks[i], &self.tracks[j]);
                let d = a.centre.distance(b.centre);
                let same = !a.motion.moving
                    && !b.motion.moving
                    && if a.class() == b.class() {
                        d < merge_radius(a.class())
                    } else {
                        d < cfg.cross_merge_m && class_cost(a.class(), b.class(), cfg).is_some()
                    };
                if !same {
                    j += 1;
                    continue;
                }
                // A reported id survives a merge: confirmed first, then hits, then age.
                let rank = |t: &Track| (t.confirmed, t.hits, core::cmp::Reverse(t.first_seen));
                let keep_i = rank(a) >= rank(b);
                let (k, g) = if keep_i { (i, j) } else { (j, i) };
                let gone = self.tracks[g];
                let t = &mut self.tracks[k];
                let total = t.weight + gone.weight;
                if total > 0.0 {
                    t.centre = Point2::new(
                        (t.centre.x * t.weight + gone.centre.x * gone.weight) / total,
                        (t.centre.y * t.weight + gone.centre.y * gone.weight) / total,
                    );
                }
                t.weight = total;
                for (e, x) in t.class_evidence.iter_mut().zip(gone.class_evidence) {
                    *e += x;
                }
                t.existence = t.existence.max(gone.existence);
                t.hits = t.hits.saturating_add(gone.hits);
                t.p_sum += gone.p_sum;
                t.tally.absorb(&gone.tally);
                t.views = t.views.max(gone.views);
                t.first_seen = t.first_seen.min(gone.first_seen);
                t.last_seen = t.last_seen.max(gone.last_seen);
                t.view_span = t.view_span.max(gone.view_span);
                t.seen_a |= gone.seen_a;
                t.seen_b |= gone.seen_b;
                t.agreed |= gone.agreed;
                t.confirmed |= gone.confirmed;
                if t.width_m <= 0.0 {
                    t.width_m = gone.width_m;
                }
                t.anchored |= gone.anchored;
                t.box_wide_views = t.box_wide_views.saturating_add(gone.box_wide_views);
                t.narrow_views = t.narrow_views.saturating_add(gone.narrow_views);
                for (v, x) in t.far_jamb_views.iter_mut().zip(gone.far_jamb_views) {
                    *v = v.saturating_add(x);
                }
                self.tracks.swap_remove(g);
                self.stats.merged += 1;
                if g == i {
                    // `i` now holds what was last; look at it afresh.
                    j = i + 1;
                }
            }
            i += 1;
        }
    }
}
