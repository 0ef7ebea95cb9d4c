//! What a frame says about a track it did not observe: negative evidence, and whether the
//! frame counts as one in which the track was in view.
//!
//! Two kinds of evidence, kept apart because they do not depend on the same thing:
//! * **what the rays show** — the track's footprint seen empty (every ray across it returned
//!   from beyond), or an anchored doorway seen shut or without its jambs — is evidence in any
//!   frame, whichever method ran;
//! * **a miss** — in plain view and not detected — is evidence only when a method that has
//!   seen the track looked in this frame. A track only Method B has seen is not missed in a
//!   frame Method B did not run in (skipped by the overrun policy, or on its own thread and
//!   not finished: a Pi 3's schedule), and that frame does not count against its detection
//!   rate either. Nor is it missed where its footprint returned fewer rays than
//!   [`TrackConfig::miss_min_returns`] (too few for a method to find it by), unless it was
//!   born on floor seen empty.
//!
//! One setting, off by default, weighs the evidence by what the track's own footprint returned
//! when it was detected ([`Track::hit_returns`]): with [`TrackConfig::empty_revs`] above 1, a
//! place seen empty only through rays with no return, where the piece had returned rays, counts
//! once it has been so in that many views in a row (a dark chair's two or three leg returns at
//! 2–2.5 m drop out together now and then, and the rest of its footprint is floor between the
//! legs). Held out it raised the annex's phantoms (`docs/world.md`, 50th session).
//!
//! And one for a track it did observe: furniture born on floor seen empty whose footprint the
//! rays pass while its detections go on beside it ([`seen_through`]): legs that stood there a
//! moment and walked on.

use super::{Track, TrackConfig};
use crate::class::ObjectClass;
use crate::geometry::Pose2;
use crate::sight::{BINS, DoorView, View, doorway_view, footprint_view, view};

/// Which methods looked in a frame (ran, and their detections are among the frame's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Looked {
    /// Method A.
    pub a: bool,
    /// Method B.
    pub b: bool,
}

impl Looked {
    /// Both methods looked.
    pub const BOTH: Looked = Looked { a: true, b: true };

    /// Whether a method that has seen `t` looked.
    fn for_track(self, t: &Track) -> bool {
        (self.a && t.seen_a) || (self.b && t.seen_b)
    }
}

/// What a frame's rays said of a track it did not observe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Said {
    /// Nothing: out of view, hidden, too few returns, or a doorway seen open.
    Nothing,
    /// In plain view and not detected (or a doorway seen shut): `miss_loss`.
    Missed,
    /// Its place seen empty (or a doorway without its jambs): `free_loss`.
    Empty,
}

/// Returns a revolution needs before its rays with no return count as passing through a
/// piece's footprint (`trust_none` of [`unobserved`]; a tenth of the bins).
pub(super) const MIN_RETURNS: usize = BINS / 10;

/// Applies this frame's negative evidence to `t`, which took no observation. `trust_none`:
/// whether a ray with no return across a piece of furniture's footprint within reach passed
/// through it ([`footprint_view`]; not in a revolution that returned almost nothing).
pub(super) fn unobserved(
    t: &mut Track,
    lidar: &Pose2,
    ranges: &[f32; BINS],
    looked: Looked,
    trust_none: bool,
    cfg: &TrackConfig,
) {
    let looked_for = looked.for_track(t);
    let (said, in_view) = if t.held_door(cfg) {
        // An opening in a wall: seen through is what it looks like.
        let jambs = if t.width_m > 0.0 {
            0.5 * t.width_m
        } else {
            t.radius()
        };
        match doorway_view(t.centre, jambs, lidar, ranges, cfg.max_range_m) {
            DoorView::Closed => (Said::Missed, true),
            DoorView::NoJambs => (Said::Empty, true),
            // In view all the same: a one-method door must be seen at its rate.
            DoorView::Open => (Said::Nothing, looked_for),
            DoorView::Hidden => (Said::Nothing, false),
        }
    } else {
        // A door frame not yet anchored in the map's walls is an opening all the same: rays
        // with no return through it are the room beyond, out of reach.
        let look = if t.class() == ObjectClass::DoorFrame || !trust_none {
            view
        } else {
            footprint_view
        };
        match look(t.centre, t.radius(), lidar, ranges, cfg.max_range_m) {
            View::Empty => (Said::Empty, true),
            // Too few returns for any method to have found it: not a miss — unless it appeared
            // where the floor had been seen empty (legs that stopped, like as not, not a piece
            // of furniture the LiDAR barely reaches).
            View::Plain(n) if looked_for && (n >= cfg.miss_min_returns || t.born_on_free) => {
                (Said::Missed, true)
            }
            View::Plain(_) => {
                t.empty_streak = 0;
                (Said::Nothing, false)
            }
            View::Hidden => (Said::Nothing, false),
        }
    };
    // A place seen empty counts once it has been so in enough views in a row (revolutions
    // that hid it do not break the row; rays ending in it, or a detection, do).
    let said = match said {
        Said::Empty => {
            t.empty_streak = t.empty_streak.saturating_add(1);
            // Rays that returned from beyond it show it empty at once, as do rays that
            // returned nothing across a place that returned nothing when it was detected; across
            // one that did, they count only in a row (a dark piece's few returns at range drop
            // out together now and then).
            if t.empty_streak >= cfg.empty_revs
                || t.hit_returns <= 0.0
                || view(t.centre, t.radius(), lidar, ranges, cfg.max_range_m) == View::Empty
            {
                Said::Empty
            } else {
                Said::Nothing
            }
        }
        Said::Missed => {
            t.empty_streak = 0;
            said
        }
        Said::Nothing => said,
    };
    let loss = match said {
        Said::Missed => cfg.miss_loss,
        Said::Empty => cfg.free_loss,
        Said::Nothing => 0.0,
    };
    if said != Said::Nothing {
        t.tally.unobserved(said == Said::Empty);
    }
    if in_view {
        t.views = t.views.saturating_add(1);
    }
    lose(t, loss, cfg);
}

/// `t`'s existence falls by `loss` (within the cap); below the confirmation level it is no
/// longer reported, until the evidence is back.
fn lose(t: &mut Track, loss: f32, cfg: &TrackConfig) {
    t.existence = (t.existence - loss).max(-cfg.existence_cap);
    if t.existence < cfg.confirm_existence {
        t.confirmed = false;
    }
}

/// What this revolution says of `t`, which took an observation: the returns its footprint
/// gave ([`Track::hit_returns`], only where [`TrackConfig::empty_revs`] reads them), and
/// whether it is seen through ([`seen_through`]).
pub(super) fn observed(
    t: &mut Track,
    lidar: &Pose2,
    ranges: &[f32; BINS],
    trust_none: bool,
    cfg: &TrackConfig,
) {
    if cfg.empty_revs > 1 {
        note_hit_returns(t, lidar, ranges, cfg);
    }
    if trust_none && t.born_on_free && cfg.seen_through_revs > 0 {
        seen_through(t, lidar, ranges, cfg);
    }
}

/// Notes the returns `t`'s footprint gave in this revolution, in which it was detected.
fn note_hit_returns(t: &mut Track, lidar: &Pose2, ranges: &[f32; BINS], cfg: &TrackConfig) {
    if let View::Plain(n) = view(t.centre, t.radius(), lidar, ranges, cfg.max_range_m) {
        let n = n as f32;
        t.hit_returns = if t.hit_returns > 0.0 {
            0.8 * t.hit_returns + 0.2 * n
        } else {
            n
        };
    }
}

/// A track born on free floor and detected this frame: if its footprint is seen empty in
/// [`TrackConfig::seen_through_revs`] revolutions in a row, it loses `free_loss` as if unseen.
fn seen_through(t: &mut Track, lidar: &Pose2, ranges: &[f32; BINS], cfg: &TrackConfig) {
    if footprint_view(t.centre, t.radius(), lidar, ranges, cfg.max_range_m) != View::Empty {
        t.seen_through = 0;
        return;
    }
    t.seen_through = t.seen_through.saturating_add(1);
    if t.seen_through >= cfg.seen_through_revs {
        t.tally.unobserved(true);
        lose(t, cfg.free_loss, cfg);
    }
}
