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
            View::Plain(_) | View::Hidden => (Said::Nothing, false),
        }
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

/// A track born on free floor and detected this frame: if its footprint is seen empty in
/// [`TrackConfig::seen_through_revs`] revolutions in a row, it loses `free_loss` as if unseen.
pub(super) fn seen_through(t: &mut Track, lidar: &Pose2, ranges: &[f32; BINS], cfg: &TrackConfig) {
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
