//! The world model's section of the file, `[world]`: the track table's knobs a user may set,
//! and the `perception::tracks::TrackConfig` they give.

use serde::Deserialize;

/// `[world]`: the world model (tracks with stable ids). On by default: on held-out rooms of
/// both scene families it reports fewer phantoms per frame than the frames' own detections,
/// with higher recall and IDF1 (docs/world.md).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WorldSettings {
    /// `objects` become the confirmed tracks, and the frame's detections move to `detections`.
    pub enabled: bool,
    /// Seconds a new object must be seen, and still, before it is reported.
    pub settle_s: f32,
    /// Tell walking people from furniture (moving tracks go to `people`, never `objects`).
    pub people: bool,
    /// Look for people's legs in every revolution (`perception::legs`): a walk they make is a
    /// person in `people` even when neither method took the legs for furniture. Off by
    /// default: on held-out runs it finds 12 % of the people in view and makes up more than
    /// it finds (docs/world.md, 43rd session).
    pub legs: bool,
    /// Furniture whose detections were, on the whole, of the kinds that are right less often
    /// than this is not reported: each detection's probability is how often detections of its
    /// source, class and score stood on a piece of their class in the simulator's tuning runs
    /// (`perception::calibration`, the counts compiled in from `models`), and a track's is
    /// their mean (`perception::tracks::Track::likelihood`). Unset (the default): 0.5 while
    /// Method B runs (`MIN_LIKELIHOOD_WITH_B`), 0 when Method A runs alone. 0: every track
    /// that earns a report is reported; 0.6 trades recall for precision (docs/world.md).
    pub min_likelihood: Option<f32>,
    /// The same for desks alone (the larger of the two applies to them): on by default, since
    /// on the tuning and the held-out runs it cost no desk (docs/world.md).
    pub desk_min_likelihood: f32,
    /// Furniture the report model compiled in (`models::report_model`, fitted on the tuning
    /// runs' track logs with both methods running) finds a phantom with at least this
    /// probability is not reported (`perception::tracks::Track::held_back`). Unset or 1 (the
    /// default): off. 0.4, the threshold chosen on the tuning runs, trades recall for
    /// precision: held out it cut phantoms by 7–21 % and cost 4 of the annex's 122 pieces
    /// (docs/world.md, 41st session), so it is not on by default.
    pub phantom_threshold: Option<f32>,
    /// A door frame seen in this many frames is a doorway of the map: the methods' silence no
    /// longer speaks against it, only rays ending in its middle (shut) or passing where its
    /// jambs should be (`perception::tracks::TrackConfig::door_hold_hits`); only one in the
    /// line of a wall of the map. 0: never. 20 by default (4 s of sightings at 5 Hz): on
    /// held-out runs it kept doors the methods stopped seeing near a run's end (docs/world.md).
    pub door_hold_hits: u32,
    /// Seconds furniture that appears on floor the LiDAR had already seen empty (in three
    /// revolutions) must be seen, and still, before it is reported (`perception::free_floor`):
    /// a person who stops for a moment where people walk is not a box. 0: no longer than
    /// `settle_s`. 3 by default: on the tuning runs it halved the reports of walking people as
    /// furniture at no cost in IDF1 (docs/world.md).
    pub appeared_settle_s: f32,
    /// Returns a piece's footprint must give in a revolution for the methods' silence to
    /// count against it (`perception::tracks::TrackConfig::miss_min_returns`). 2 by default:
    /// held out, it raised recall and IDF1 in every family, with no more walking people
    /// reported as furniture; 3 reported some (docs/world.md).
    pub miss_min_returns: u32,
    /// Frames a piece only one method has seen must be detected in before it is reported
    /// (`perception::tracks::TrackConfig::single_method_hits`; at least 1). Both methods
    /// agreeing in one frame need no more than `confirm_hits` (docs/world.md).
    pub single_method_hits: u32,
    /// Furniture that appeared on floor seen empty, still detected, whose own footprint the
    /// rays pass in this many revolutions in a row, loses as if its place were seen empty
    /// (`perception::tracks::TrackConfig::seen_through_revs`): a person who stopped and walked
    /// on, the detections now matched from beside the place. 0: off. 2 by default: on the
    /// tuning runs it took the reports of walking people as furniture from 17 to 6 (sim) and
    /// 24 to 18 (worn) at no cost in recall; held out nothing changed (docs/world.md, 45th
    /// session).
    pub seen_through_revs: u8,
    /// Views in a row a piece's place must be seen empty only through rays with no return
    /// (where the piece returned rays when detected) before that counts against it
    /// (`perception::tracks::TrackConfig::empty_revs`; at least 1). 1 by default: 2 kept dark
    /// chairs at range in the map on the tuning runs (recall +0.007) but raised the annex's
    /// phantoms held out, +0.007 and +0.019 a frame on two sets of seeds (docs/world.md, 50th
    /// session).
    pub empty_revs: u8,
    /// Furniture tracks of different classes closer than this are one piece, m
    /// (`perception::tracks::TrackConfig::cross_merge_m`). 0 (never) by default: 0.25 raised the
    /// annex's IDF1 held out (0.656 → 0.679) and its phantoms (0.387 → 0.396 a frame;
    /// docs/world.md, 50th session).
    pub cross_merge_m: f32,
}

/// `min_likelihood` while Method B runs, unless set: held out it cut phantoms in every family
/// (the annex's by 12 %) and cost no piece (docs/world.md). It was measured with both methods
/// running; with Method A alone it would hold back most of A's boxes and desks (right 24–60 %
/// of the time at their usual scores), so there the default is 0.
pub const MIN_LIKELIHOOD_WITH_B: f32 = 0.5;

impl Default for WorldSettings {
    fn default() -> Self {
        let m = perception::motion::MotionConfig::default();
        WorldSettings {
            enabled: true,
            settle_s: m.settle_s,
            people: true,
            legs: false,
            min_likelihood: None,
            desk_min_likelihood: 0.6,
            phantom_threshold: None,
            door_hold_hits: 20,
            appeared_settle_s: 3.0,
            miss_min_returns: 2,
            single_method_hits: perception::tracks::TrackConfig::default().single_method_hits,
            seen_through_revs: 2,
            empty_revs: 1,
            cross_merge_m: 0.0,
        }
    }
}

impl WorldSettings {
    /// The track table's tuning these settings give; `method_b`: whether Method B runs.
    pub fn tracks(&self, method_b: bool) -> perception::tracks::TrackConfig {
        let mut c = perception::tracks::TrackConfig::default();
        c.motion.settle_s = if self.settle_s.is_finite() {
            self.settle_s.max(0.0)
        } else {
            c.motion.settle_s
        };
        if !self.people {
            c.motion.moving_m = f32::INFINITY;
        }
        c.walkers = self.people && self.legs;
        c.calibration = models::calibration::calibration();
        let min = self
            .min_likelihood
            .unwrap_or(if method_b { MIN_LIKELIHOOD_WITH_B } else { 0.0 });
        if min.is_finite() {
            c.min_likelihood = min.clamp(0.0, 1.0);
        }
        if self.desk_min_likelihood.is_finite() {
            c.min_desk_likelihood = self.desk_min_likelihood.clamp(0.0, 1.0);
        }
        c.report_model = match self.phantom_threshold {
            Some(t) if t.is_finite() && t < 1.0 => {
                models::report_model::REPORT_MODEL.map(|m| perception::tracks::ReportModel {
                    threshold: t.max(0.0),
                    ..m
                })
            }
            _ => None,
        };
        c.door_hold_hits = self.door_hold_hits;
        if self.appeared_settle_s.is_finite() {
            c.appeared_settle_s = self.appeared_settle_s.max(0.0);
        }
        c.miss_min_returns = self.miss_min_returns.max(1);
        c.single_method_hits = self.single_method_hits.max(1);
        c.seen_through_revs = self.seen_through_revs;
        c.empty_revs = self.empty_revs.max(1);
        if self.cross_merge_m.is_finite() {
            c.cross_merge_m = self.cross_merge_m.clamp(0.0, 1.0);
        }
        c
    }
}
