//! When a track is reported ([`earns_report`]) and when it is deleted
//! ([`Track::delete_below`]), and desks that never settle. A desk never
//! walks (`Motion::observe`'s `may_move`), yet one that Method B sees only now and then is
//! never still by the motion test ([`crate::motion::Motion::settled`]): each sighting follows
//! a gap, which resets the stillness the test counts, and the centre wanders with the view as
//! the legs come and go behind each other. Seen from a robot that drives, from places
//! [`DESK_VIEW_SPAN_M`] apart, such a desk needs only to have been seen a while
//! ([`Track::desk_allowance`]); from one that stands or turns in place the view does not
//! change, and it must settle as anything else does. So must one within [`DESK_BESIDE_M`] of
//! a reported desk: most likely that desk's other end, which Method B boxes on its own now
//! and then.

use crate::class::ObjectClass;
use crate::geometry::Point2;

use super::{Track, TrackConfig};

/// Whether a track has the evidence to be reported: enough hits and existence, and unless
/// both methods agreed on it in one frame, more hits and a steady detection rate while in
/// view (Method A seeing it once and Method B once, in different frames, is not agreement).
pub(super) fn earns_report(t: &Track, cfg: &TrackConfig, beside_desk: bool) -> bool {
    let waited = !t.born_on_free || t.motion.age_s() >= cfg.appeared_settle_s;
    // Still, or a desk seen now and then from a robot that drives (below).
    let still = t.motion.settled(&cfg.motion) || t.desk_allowance(cfg, beside_desk);
    let base = still
        && waited
        && t.hits >= cfg.confirm_hits
        && t.existence >= cfg.confirm_existence
        && !t.door_at_wall_end();
    base && (t.agreed
        || (t.hits >= cfg.single_method_hits
            && t.hits as f32 >= cfg.single_method_rate * t.views as f32))
}

/// A desk seen from places this far apart may be reported while it is not still, m
/// ([`Track::view_span`]): a tour drives it in about 3 s.
pub const DESK_VIEW_SPAN_M: f32 = 0.5;

/// A desk track this close to another, reported desk may be that desk seen again, m: a desk's
/// length (1.3–1.9 m) and its detection's scatter.
pub const DESK_BESIDE_M: f32 = 2.0;

impl Track {
    /// Notes where the LiDAR stood (`sensor`, map frame) when the track was seen.
    pub(super) fn note_view(&mut self, sensor: Point2) {
        let span = sensor.distance(self.first_view);
        if span.is_finite() && span > self.view_span {
            self.view_span = span;
        }
    }

    /// The existence below which it is deleted: [`TrackConfig::delete_existence`], or for a
    /// track once reported, just above the floor (`-existence_cap`). A piece Method B stops
    /// finding for a while (from another side, farther off) is then no longer reported but
    /// kept, and its next detections bring it back under its id, not a new track that must
    /// earn its report again. Its place seen empty takes it to the floor as fast as before.
    pub fn delete_below(&self, cfg: &TrackConfig) -> f32 {
        if self.reported_once {
            cfg.delete_existence.min(0.99 * -cfg.existence_cap)
        } else {
            cfg.delete_existence
        }
    }

    /// A desk that may be reported though the motion test does not find it still (see the
    /// module docs): not walking, seen for [`crate::motion::MotionConfig::settle_s`], from
    /// places [`DESK_VIEW_SPAN_M`] apart, and no reported desk within [`DESK_BESIDE_M`]
    /// (`beside_desk`).
    pub(super) fn desk_allowance(&self, cfg: &TrackConfig, beside_desk: bool) -> bool {
        self.class() == ObjectClass::Desk
            && !beside_desk
            && !self.motion.moving
            && self.motion.age_s() >= cfg.motion.settle_s
            && self.view_span >= DESK_VIEW_SPAN_M
    }
}

/// Whether a reported desk track other than the one at `except` stands within
/// [`DESK_BESIDE_M`] of `p`.
pub(super) fn desk_beside(tracks: &[Track], p: Point2, except: Option<usize>) -> bool {
    tracks.iter().enumerate().any(|(k, d)| {
        Some(k) != except
            && d.confirmed
            && d.class() == ObjectClass::Desk
            && d.centre.distance(p) < DESK_BESIDE_M
    })
}
