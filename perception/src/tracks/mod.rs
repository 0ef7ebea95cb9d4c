//! The world model's tracks: objects in the map frame that persist across frames, keep a
//! stable id (never reused), gather evidence from both methods and leave when the LiDAR shows
//! their place empty. Fixed capacity, allocation-free, `no_std`.
//!
//! Each frame ([`Tracks::update`]):
//! 1. **Gate and associate.** Every (track, observation) pair within [`TrackConfig::gate_m`]
//!    whose classes may be the same object (a door frame only with a door frame; the furniture
//!    classes with each other, at a cost) is a candidate; the cheapest pair is taken first
//!    until none is left (greedy on the global minimum).
//! 2. **Update matched tracks:** the centre is a score-weighted running mean (total weight
//!    capped, so a moved object is followed), the class evidence adds the observation's score
//!    to its class, existence rises by `hit_gain × score`, the evidence flags note which
//!    method saw it.
//! 3. **Negative evidence** for every unmatched track in range: when the revolution's rays
//!    across the track's footprint all returned from beyond it, the place was seen empty and
//!    existence falls by `free_loss`; in plain view and not observed, by `miss_loss` (only in
//!    a frame in which a method that has seen it looked: [`Looked`], `negative.rs`). Rays
//!    that end before it (something in front) say nothing. A door frame the map's walls showed
//!    as a doorway ([`Tracks::anchor_doors`]), or seen in [`TrackConfig::door_hold_hits`]
//!    frames in a wall's line ([`Track::held_door`]), is an opening: rays through it are what
//!    it looks like; it loses belief when its middle is seen closed, or when the rays pass its
//!    jambs' places too (open floor). A door frame only Method B has seen, at a wall's end (a
//!    corner of the map's walls, or beside an end whose other jamb's place is seen empty) and
//!    in no doorway of them, is not reported ([`Tracks::mark_wall_doors`]).
//! 4. **New tracks** from unmatched observations (non-finite or absurd ones are refused and
//!    counted); when the table is full the weakest tentative track, else the weakest track, is
//!    evicted (counted).
//! 5. **Confirmation and deletion:** a track is reported ([`Track::confirmed`]) once it has
//!    [`TrackConfig::confirm_hits`] hits and existence above [`TrackConfig::confirm_existence`],
//!    and, unless both methods agreed on it in one frame, [`TrackConfig::single_method_hits`]
//!    hits in at least [`TrackConfig::single_method_rate`] of the frames it was in view;
//!    furniture born where the rays had shown the floor empty ([`FreeFloor`], marked from every
//!    revolution's rays) must also have been seen for [`TrackConfig::appeared_settle_s`];
//!    it must be still ([`Motion::settled`]), except a desk seen from places
//!    [`DESK_VIEW_SPAN_M`] apart with no reported desk within [`DESK_BESIDE_M`] (`report.rs`);
//!    it is deleted when existence falls below [`Track::delete_below`] (once reported: the
//!    floor, so a piece found again keeps its id), or when a track never reported goes unseen
//!    for [`TrackConfig::tentative_frames`]. A track out of view keeps its state.
//! 6. **Likelihood:** each observation's calibrated probability ([`TrackConfig::calibration`])
//!    is summed; furniture whose mean is below [`TrackConfig::min_likelihood`] (desks:
//!    [`TrackConfig::min_desk_likelihood`]) is not reported ([`Track::unlikely`],
//!    `likelihood.rs`), nor what the report model finds a phantom (`report_model.rs`).
//!
//! Files: `association.rs` (which observation updates which track), `merge.rs` (one object
//! seen twice), `negative.rs` (what the rays say), `walkers.rs` (the leg detector's tracks),
//! `door_marks.rs` (the map's walls and door frames), `outline_marks.rs` (a box's shape),
//! `report.rs` (when reported, when deleted), `likelihood.rs`, `report_model.rs`, `stats.rs`.

use heapless::Vec;

use crate::calibration::Calibration;
use crate::class::ObjectClass;
use crate::free_floor::FreeFloor;
use crate::fusion::{Evidence, FrameObject};
use crate::geometry::{Point2, Pose2};
use crate::motion::{Motion, MotionConfig};
use crate::outline_average::AveragedOutline;
use crate::sight::BINS;
pub use association::{MAX_PAIRS, MAX_TAKEN};
use association::{class_cost, greedy};
use belief::class_radius;
pub use outline_marks::{
    AVERAGED_ROUND_MAJORITY, AVERAGED_ROUND_VIEWS, OUTLINE_SLOTS, averaged_vote,
};
pub use report::{DESK_BESIDE_M, DESK_VIEW_SPAN_M};
use report::{desk_beside, earns_report};
pub use report_model::{FEATURE_NAMES, REPORT_FEATURES, ReportModel, Tally};
pub use stats::TrackStats;

mod association;
mod belief;
mod door_marks;
mod likelihood;
mod merge;
mod negative;
mod outline_marks;
mod report;
mod report_model;
mod stats;
mod walkers;

pub use door_marks::{JAMB_M, LONE_JAMB_VIEWS};
pub use negative::Looked;
pub use outline_marks::{NARROW_VIEWS, ROUND_CORNER_RATIO, ROUND_LINE_RATIO, ROUND_VIEWS};
pub use walkers::{MAX_WALKERS, SAME_PERSON_M, Walker, Walkers};

/// Tracks held at most.
pub const MAX_TRACKS: usize = 64;

/// A door frame's centre this close to a corner of the map's walls is at the corner, m: a
/// doorway beside a corner has its centre at least half its width (0.38 m) plus the jamb's
/// piece of wall from it.
pub const CORNER_DOOR_M: f32 = 0.45;

/// A person is listed while seen in one of this many frames.
pub const PEOPLE_FRAMES: u64 = 3;

/// Tuning of the track table.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackConfig {
    /// Farthest an observation may be from a track's centre to update it, m.
    pub gate_m: f32,
    /// Extra cost (m) of associating furniture of different classes.
    pub class_change_cost_m: f32,
    /// Hits before a track is reported.
    pub confirm_hits: u32,
    /// Existence before a track is reported.
    pub confirm_existence: f32,
    /// Existence below which a track is deleted.
    pub delete_existence: f32,
    /// Frames a tentative track may go unseen before it is deleted.
    pub tentative_frames: u64,
    /// Existence gained per hit, times the observation's score.
    pub hit_gain: f32,
    /// Existence lost when the place is seen empty: more than a hit gains (rays returned from
    /// beyond a footprint outweigh one detection; `docs/world.md`, 35th session).
    pub free_loss: f32,
    /// Existence lost in a frame whose revolution had the track in plain view (in range, its
    /// bearing not blocked by anything nearer) and no observation matched it.
    pub miss_loss: f32,
    /// Returns its footprint must give in a revolution for that revolution to count as a miss
    /// (and as a view): fewer, and no method could have found it there (a far piece the
    /// LiDAR barely reaches, a dark one that mostly drops out), so its silence says nothing.
    pub miss_min_returns: u32,
    /// Views in a row a piece's place must be seen empty before each costs `free_loss`
    /// (`negative.rs`). 1: every one.
    pub empty_revs: u8,
    /// Furniture tracks of different classes closer than this are one piece, m (`merge.rs`).
    pub cross_merge_m: f32,
    /// Hits a track seen by one method only needs before it is reported (both methods: just
    /// [`TrackConfig::confirm_hits`]): one method's repeated mistake is the commonest phantom.
    pub single_method_hits: u32,
    /// Share of the frames it was in view in which a one-method track must have been seen.
    pub single_method_rate: f32,
    /// Existence is kept within ±this.
    pub existence_cap: f32,
    /// Total position weight at most (a cap lets a moved object be followed).
    pub max_weight: f32,
    /// The LiDAR's useful range, m: negative evidence only within it.
    pub max_range_m: f32,
    /// Farthest from the robot an observation is believed, m (beyond: refused as absurd).
    pub max_observation_m: f32,
    /// What makes a track a walking person's (never furniture).
    pub motion: MotionConfig,
    /// Track the leg detector's person candidates ([`Tracks::update_walkers`]).
    pub walkers: bool,
    /// What each observation's score means ([`Calibration::probability`]): the weight of
    /// its hit and its class evidence.
    pub calibration: Calibration,
    /// Furniture tracks whose observations' mean probability is below this are not reported
    /// ([`Track::unlikely`]); 0: all are.
    pub min_likelihood: f32,
    /// The same for desks alone (the larger of the two applies to them).
    pub min_desk_likelihood: f32,
    /// Furniture it finds a phantom is not reported ([`Track::held_back`]); `None`: off.
    pub report_model: Option<ReportModel>,
    /// A door frame with this many hits is a doorway of the map, as one the map's walls
    /// showed is ([`Track::anchored`]): only what the rays show of it (shut, or no jambs
    /// where they should be) speaks against it, not the methods' silence. A doorway does not
    /// move away; 0: never.
    pub door_hold_hits: u32,
    /// Seconds a piece of furniture must be seen, and still, before it is reported when it
    /// appeared on floor the LiDAR had seen empty ([`FreeFloor`]): where a person walks and
    /// stands for a moment, not where furniture stood when the robot first looked. Below
    /// [`MotionConfig::settle_s`]: no extra wait.
    pub appeared_settle_s: f32,
    /// Revolutions in a row a track born on floor seen empty must be detected while its own
    /// footprint is seen empty (every ray across it returning from beyond) before that counts
    /// against it as if it had gone unseen (`free_loss`): legs that stood there and walked on,
    /// their detections now matched from beside the place. 0: never.
    pub seen_through_revs: u8,
}

impl Default for TrackConfig {
    fn default() -> Self {
        TrackConfig {
            gate_m: 0.5,
            class_change_cost_m: 0.3,
            confirm_hits: 3,
            confirm_existence: 1.5,
            delete_existence: -1.0,
            tentative_frames: 10,
            hit_gain: 1.0,
            free_loss: 1.5,
            miss_loss: 0.7,
            miss_min_returns: 1,
            empty_revs: 1,
            cross_merge_m: 0.0,
            single_method_hits: 8,
            single_method_rate: 0.6,
            existence_cap: 6.0,
            max_weight: 10.0,
            max_range_m: 3.5,
            max_observation_m: 12.0,
            motion: MotionConfig::default(),
            walkers: true,
            calibration: Calibration::IDENTITY,
            min_likelihood: 0.0,
            min_desk_likelihood: 0.0,
            report_model: None,
            door_hold_hits: 0,
            appeared_settle_s: 0.0,
            seen_through_revs: 0,
        }
    }
}

/// One tracked object.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Track {
    /// Stable id: the same object in every frame, never reused.
    pub id: u32,
    /// Centre in the map frame, m.
    pub centre: Point2,
    /// Position weight gathered (capped).
    weight: f32,
    /// Summed scores per class ([`ObjectClass::ALL`] order).
    class_evidence: [f32; 4],
    /// Log-odds-like existence.
    pub existence: f32,
    /// Frames with an observation.
    pub hits: u32,
    /// Frames it was in view (observed, or in plain view, or its place seen empty).
    pub views: u32,
    /// First and last frame with an observation.
    pub first_seen: u64,
    /// See `first_seen`.
    pub last_seen: u64,
    /// Seen by Method A / by Method B so far.
    seen_a: bool,
    seen_b: bool,
    /// Both methods saw it in one frame (an AB observation): the strongest evidence there is.
    agreed: bool,
    /// Reported.
    pub confirmed: bool,
    /// Reported at some time: deleted only at the existence floor ([`Track::delete_below`]).
    pub reported_once: bool,
    /// Width across, m (door frames: the clear width, a running mean of the observations
    /// that carry one); 0 = unknown.
    pub width_m: f32,
    /// Position and velocity from the observations alone; whether it walks.
    pub motion: Motion,
    /// Furniture that appeared on floor seen empty before ([`FreeFloor`]): it waits
    /// [`TrackConfig::appeared_settle_s`] before it is reported.
    pub born_on_free: bool,
    /// Revolutions in a row it was detected while its footprint was seen empty
    /// ([`TrackConfig::seen_through_revs`]).
    pub seen_through: u8,
    /// Returns its footprint gave when detected, a running mean ([`TrackConfig::empty_revs`]).
    pub hit_returns: f32,
    /// Views in a row its place was seen empty, up to now ([`TrackConfig::empty_revs`]).
    pub empty_streak: u8,
    /// A door frame the map's walls have shown as a doorway (a gap seen through): an opening
    /// in a wall, which rays passing through do not speak against.
    pub anchored: bool,
    /// Revolutions in which its returns looked wider than any box's short side, and narrower
    /// than it, while it was a box ([`Tracks::measure_outlines`]).
    pub box_wide_views: u16,
    /// See `box_wide_views`.
    pub narrow_views: u16,
    /// Revolutions in which its returns could lie on an arc, and in which they could not,
    /// while it was a box ([`crate::outline::fits`], [`Tracks::measure_outlines`]).
    pub arc_views: u16,
    /// See `arc_views`.
    pub flat_views: u16,
    /// Over the arc views: the circle's, a right-angled corner's and one line's sums of
    /// squared distances per degree of freedom, summed (m²).
    pub arc_fits: [f32; 3],
    /// Revolutions in which its outline averaged over revolutions was round, and was not,
    /// while it was a still box ([`crate::outline_average`], [`Tracks::measure_outlines`]).
    pub averaged_round: [u16; 2],
    /// A door frame at a corner of the map's walls ([`Tracks::mark_corner_doors`]).
    pub at_corner: bool,
    /// A door frame in the line of one of the map's walls ([`Tracks::mark_corner_doors`]).
    pub in_wall_line: bool,
    /// Revolutions that showed the place of its other jamb, beside a wall's end, empty and
    /// returning ([`Track::lone_jamb`]).
    pub far_jamb_views: [u16; 2],
    /// Sum of its observations' probabilities ([`TrackConfig::calibration`]); over its hits,
    /// how likely what the methods saw there was right ([`Track::likelihood`]).
    pub p_sum: f32,
    /// Where the LiDAR stood when it was first seen (map frame).
    pub first_view: Point2,
    /// How far from [`Track::first_view`] the LiDAR has seen it since, at most, m.
    pub view_span: f32,
    /// What its observations and misses were ([`Tally`]): what the report model reads.
    pub tally: Tally,
}

/// The track table.
#[derive(Debug, Clone)]
pub struct Tracks {
    tracks: Vec<Track, MAX_TRACKS>,
    next_id: u32,
    stats: TrackStats,
    walkers: Walkers,
    floor: FreeFloor,
    /// Still box tracks' outlines averaged over revolutions, by id ([`OUTLINE_SLOTS`]).
    outlines: Vec<(u32, AveragedOutline), OUTLINE_SLOTS>,
}

impl Default for Tracks {
    fn default() -> Self {
        Self::new()
    }
}

impl Tracks {
    /// An empty table.
    pub const fn new() -> Self {
        Tracks {
            tracks: Vec::new(),
            next_id: 0,
            stats: TrackStats {
                created: 0,
                deleted: 0,
                evicted: 0,
                rejected: 0,
                bad_poses: 0,
                merged: 0,
            },
            walkers: Walkers::new(),
            outlines: Vec::new(),
            floor: FreeFloor::new(),
        }
    }

    /// Every track, confirmed or not.
    pub fn all(&self) -> &[Track] {
        &self.tracks
    }

    /// The confirmed tracks: the map's objects.
    pub fn confirmed(&self) -> impl Iterator<Item = &Track> + '_ {
        self.tracks.iter().filter(|t| t.confirmed)
    }

    /// The people among the tracks: moving tracks seen in one of the last [`PEOPLE_FRAMES`]
    /// frames up to `frame`, with at least [`TrackConfig::confirm_hits`] hits, and no listed
    /// walker ([`Walkers::people`]) within [`SAME_PERSON_M`] (that one is the same person).
    pub fn people(&self, frame: u64, cfg: &TrackConfig) -> impl Iterator<Item = &Track> + '_ {
        let hits = cfg.confirm_hits;
        self.tracks.iter().filter(move |t| {
            t.motion.moving
                && t.hits >= hits
                && frame.saturating_sub(t.last_seen) < PEOPLE_FRAMES
                && !self.walker_near(frame, t.centre)
        })
    }

    /// Counters.
    pub fn stats(&self) -> &TrackStats {
        &self.stats
    }

    /// One frame: `obs` are the frame's objects (map frame), `stamp_s` the revolution's time
    /// (s, any origin; it times the motion filter), `lidar` the LiDAR's pose in the map at the
    /// revolution, `ranges` its 360 bins (0 = no return), `looked` the methods that ran
    /// (a track is missed only in a frame in which a method that has seen it looked).
    #[allow(clippy::too_many_arguments)]
    pub fn update(
        &mut self,
        frame: u64,
        stamp_s: f64,
        obs: &[FrameObject],
        lidar: &Pose2,
        ranges: &[f32; BINS],
        looked: Looked,
        cfg: &TrackConfig,
    ) {
        let pose_ok = lidar.x.is_finite() && lidar.y.is_finite() && lidar.theta.is_finite();
        if !pose_ok {
            self.stats.bad_poses += 1;
        }
        let sensor = Point2::new(lidar.x, lidar.y);
        // Which tracks took an observation this frame.
        let mut matched = [false; MAX_TRACKS];
        let mut used: [bool; crate::fusion::MAX_FRAME_OBJECTS] =
            [false; crate::fusion::MAX_FRAME_OBJECTS];
        let obs = &obs[..obs.len().min(used.len())];
        // Refuse what cannot be true.
        for (k, o) in obs.iter().enumerate() {
            let finite = o.centre.x.is_finite() && o.centre.y.is_finite() && o.score.is_finite();
            let near = pose_ok && o.centre.distance(sensor) <= cfg.max_observation_m;
            if !(finite && near) {
                used[k] = true;
                self.stats.rejected += 1;
            }
        }
        // Where each track's walk would have taken it (once per frame, not per pair).
        let mut ahead = [Point2::new(0.0, 0.0); MAX_TRACKS];
        for (a, t) in ahead.iter_mut().zip(self.tracks.iter()) {
            *a = t.motion.predict(stamp_s, &cfg.motion);
        }
        // Greedy on the global minimum cost.
        let taken = greedy(
            &mut matched,
            &mut used,
            self.tracks.len(),
            obs.len(),
            |i, k| {
                let (t, o) = (&self.tracks[i], &obs[k]);
                // Looked for where it stands, or where its walk has taken it.
                let d = t.centre.distance(o.centre).min(ahead[i].distance(o.centre));
                // A desk's centre moves with the view more than a chair's (its legs come and go
                // behind each other): desks gate at their own radius.
                let desks = t.class() == ObjectClass::Desk && o.class == ObjectClass::Desk;
                let gate = if desks {
                    cfg.gate_m.max(class_radius(ObjectClass::Desk))
                } else {
                    cfg.gate_m
                };
                if d > gate {
                    return None;
                }
                class_cost(t.class(), o.class, cfg).map(|extra| d + extra)
            },
        );
        for (i, k) in taken
            .into_iter()
            .map(|(i, k)| (usize::from(i), usize::from(k)))
        {
            // Only a desk, or a track this observation may make one, is asked (`report.rs`).
            let desk = ObjectClass::Desk;
            let beside = (self.tracks[i].class() == desk || obs[k].class == desk)
                && desk_beside(&self.tracks, self.tracks[i].centre, Some(i));
            Self::hit(
                &mut self.tracks[i],
                &obs[k],
                frame,
                stamp_s,
                sensor,
                beside,
                cfg,
            );
        }
        // What the rays say of each track (`negative.rs`). Rays with no return show a place
        // empty only in a revolution that returned elsewhere, not a blinded LiDAR's.
        if pose_ok {
            let returned = ranges.iter().filter(|r| **r > 0.0 && r.is_finite()).count();
            let trust_none = returned >= negative::MIN_RETURNS;
            for (i, t) in self.tracks.iter_mut().enumerate() {
                if matched[i] {
                    negative::observed(t, lidar, ranges, trust_none, cfg);
                } else {
                    negative::unobserved(t, lidar, ranges, looked, trust_none, cfg);
                }
            }
        }
        self.merge_duplicates(cfg);
        // Deletion.
        let mut i = 0;
        while i < self.tracks.len() {
            let t = &self.tracks[i];
            let stale_tentative = !(t.confirmed || t.reported_once)
                && frame.saturating_sub(t.last_seen) > cfg.tentative_frames;
            if t.existence < t.delete_below(cfg) || stale_tentative {
                self.tracks.swap_remove(i);
                self.stats.deleted += 1;
            } else {
                i += 1;
            }
        }
        // New tracks.
        for (k, o) in obs.iter().enumerate() {
            if used[k] {
                continue;
            }
            if self.tracks.is_full() {
                self.evict_weakest();
            }
            let mut t = Track {
                id: self.next_id,
                centre: o.centre,
                weight: 0.0,
                class_evidence: [0.0; 4],
                existence: 0.0,
                hits: 0,
                views: 0,
                first_seen: frame,
                last_seen: frame,
                seen_a: false,
                seen_b: false,
                agreed: false,
                confirmed: false,
                reported_once: false,
                width_m: 0.0,
                motion: Motion::new(o.centre, stamp_s),
                born_on_free: o.class != ObjectClass::DoorFrame && self.floor.seen_free(o.centre),
                seen_through: 0,
                hit_returns: 0.0,
                empty_streak: 0,
                anchored: false,
                box_wide_views: 0,
                narrow_views: 0,
                arc_views: 0,
                flat_views: 0,
                arc_fits: [0.0; 3],
                averaged_round: [0; 2],
                at_corner: false,
                in_wall_line: false,
                far_jamb_views: [0; 2],
                p_sum: 0.0,
                first_view: sensor,
                view_span: 0.0,
                tally: Tally::default(),
            };
            let beside = o.class == ObjectClass::Desk && desk_beside(&self.tracks, o.centre, None);
            Self::hit(&mut t, o, frame, stamp_s, sensor, beside, cfg);
            if self.tracks.push(t).is_ok() {
                self.next_id = self.next_id.wrapping_add(1);
                self.stats.created += 1;
            }
        }
        // What this revolution saw through (after the new tracks: it speaks of the next ones).
        if pose_ok && cfg.appeared_settle_s > 0.0 {
            self.floor.mark(lidar, ranges, cfg.max_range_m);
        }
    }

    fn hit(
        t: &mut Track,
        o: &FrameObject,
        frame: u64,
        stamp_s: f64,
        sensor: Point2,
        beside_desk: bool,
        cfg: &TrackConfig,
    ) {
        t.note_view(sensor);
        if t.hits > 0 {
            let legs = |c: ObjectClass| matches!(c, ObjectClass::Chair | ObjectClass::Box);
            let may_move = legs(o.class) && legs(t.class());
            t.motion.observe(o.centre, stamp_s, &cfg.motion, may_move);
        }
        let p = cfg
            .calibration
            .probability(o.evidence, o.class, o.score)
            .clamp(0.0, 1.0);
        let w = o.score.clamp(0.05, 1.0);
        let total = t.weight + w;
        t.centre = Point2::new(
            (t.centre.x * t.weight + o.centre.x * w) / total,
            (t.centre.y * t.weight + o.centre.y * w) / total,
        );
        t.weight = total.min(cfg.max_weight);
        t.class_evidence[o.class as usize] += o.score.clamp(0.0, 1.0);
        t.p_sum += p;
        let (range, off) = (sensor.distance(o.centre), t.centre.distance(o.centre));
        t.tally.observe(o.evidence, p, o.score, range, off);
        t.existence = (t.existence + cfg.hit_gain * w).min(cfg.existence_cap);
        t.hits = t.hits.saturating_add(1);
        t.views = t.views.saturating_add(1);
        t.last_seen = frame;
        t.empty_streak = 0;
        if o.width_m > 0.0 && o.width_m.is_finite() {
            t.width_m = if t.width_m > 0.0 {
                0.8 * t.width_m + 0.2 * o.width_m
            } else {
                o.width_m
            };
        }
        match o.evidence {
            Evidence::A => t.seen_a = true,
            Evidence::B => t.seen_b = true,
            Evidence::AB => {
                t.seen_a = true;
                t.seen_b = true;
                t.agreed = true;
            }
        }
        if t.motion.moving {
            // A walking person: where the legs are now, never furniture.
            t.centre = t.motion.pos;
            t.confirmed = false;
        } else if earns_report(t, cfg, beside_desk) {
            (t.confirmed, t.reported_once) = (true, true);
        }
    }

    /// Makes room: the weakest tentative track goes, else the weakest of all.
    fn evict_weakest(&mut self) {
        let weakest = |only_tentative: bool| {
            self.tracks
                .iter()
                .enumerate()
                .filter(|(_, t)| !only_tentative || !t.confirmed)
                .min_by(|a, b| a.1.existence.total_cmp(&b.1.existence))
                .map(|(i, _)| i)
        };
        if let Some(i) = weakest(true).or_else(|| weakest(false)) {
            self.tracks.swap_remove(i);
            self.stats.evicted += 1;
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::wall_map::WallMap;

    fn obs(class: ObjectClass, x: f32, y: f32, score: f32, evidence: Evidence) -> FrameObject {
        FrameObject {
            class,
            centre: Point2::new(x, y),
            score,
            evidence,
            bbox: None,
            width_m: 0.0,
        }
    }

    /// The default tuning without the wait before a new track may be reported
    /// ([`MotionConfig::settle_s`]), for the tests about something else.
    fn quick() -> TrackConfig {
        TrackConfig {
            motion: MotionConfig {
                settle_s: 0.0,
                still_frames: 0,
                ..MotionConfig::default()
            },
            ..TrackConfig::default()
        }
    }

    /// One update at frame `f`, five revolutions a second.
    fn step(
        t: &mut Tracks,
        f: u64,
        obs: &[FrameObject],
        lidar: &Pose2,
        ranges: &[f32; BINS],
        cfg: &TrackConfig,
    ) {
        t.update(f, f as f64 * 0.2, obs, lidar, ranges, Looked::BOTH, cfg);
    }

    /// A revolution from the origin facing +x with every ray returning at `r` m.
    fn ranges(r: f32) -> [f32; BINS] {
        [r; BINS]
    }

    const CHAIR: ObjectClass = ObjectClass::Chair;

    /// A map whose walls are `segs`, seen from the origin in enough revolutions to confirm
    /// them.
    fn walls_seen(segs: &[crate::walls::Segment]) -> WallMap {
        let mut walls = WallMap::new();
        for f in 0..3 {
            walls.update(f, segs, Point2::new(0.0, 0.0));
        }
        walls
    }

    #[test]
    fn furniture_seen_only_in_ways_that_are_mostly_wrong_is_unlikely() {
        // Method B's boxes at 0.5 stood on a box 2 times in 10; what both methods agreed on,
        // and Method B's door frames at 0.5, 9 in 10.
        let mut counts = [0u32; crate::calibration::COUNTS_LEN];
        let mut set = |source: usize, class: ObjectClass, bin: usize, n: u32, t: u32| {
            let at = crate::calibration::count_index(source, class as usize, bin);
            counts[at] = n;
            counts[at + 1] = t;
        };
        set(1, ObjectClass::Box, 5, 100, 20);
        set(2, ObjectClass::Box, 5, 100, 90);
        set(1, ObjectClass::DoorFrame, 5, 100, 20);
        let cfg = TrackConfig {
            calibration: Calibration::fit(&counts),
            min_likelihood: 0.6,
            ..quick()
        };
        let far = ranges(4.0);
        let run = |o: FrameObject| {
            let mut t = Tracks::new();
            for f in 0..12 {
                step(&mut t, f, &[o], &Pose2::IDENTITY, &far, &cfg);
            }
            *t.confirmed().next().expect("confirmed")
        };
        let b = run(obs(ObjectClass::Box, 2.0, 0.0, 0.55, Evidence::B));
        assert!((b.likelihood() - 21.0 / 102.0).abs() < 1e-3, "{b:?}");
        assert!(b.unlikely(&cfg));
        let ab = run(obs(ObjectClass::Box, 2.0, 0.0, 0.55, Evidence::AB));
        assert!(!ab.unlikely(&cfg), "{ab:?}");
        // Door frames are judged by the map's walls, not by this.
        let door = run(obs(ObjectClass::DoorFrame, 2.0, 0.0, 0.55, Evidence::B));
        assert!(door.likelihood() < 0.6 && !door.unlikely(&cfg), "{door:?}");
        // 0 keeps all.
        let plain = TrackConfig {
            min_likelihood: 0.0,
            ..cfg
        };
        assert!(!b.unlikely(&plain));
        // The desks' own threshold is for desks alone (a class without counts: its score
        // stands).
        let desks_only = TrackConfig {
            min_desk_likelihood: 0.6,
            ..plain
        };
        assert!(!b.unlikely(&desks_only));
        let desk = run(obs(ObjectClass::Desk, 2.0, 0.0, 0.3, Evidence::A));
        assert!(desk.likelihood() < 0.6, "{desk:?}");
        assert!(desk.unlikely(&desks_only) && !desk.unlikely(&plain));
        // Merged tracks keep the sum over both.
        let mut t = Tracks::new();
        let a = obs(ObjectClass::Box, 2.0, 0.0, 0.55, Evidence::B);
        let c = obs(ObjectClass::Box, 2.3, 0.0, 0.55, Evidence::AB);
        step(&mut t, 0, &[a], &Pose2::IDENTITY, &far, &cfg);
        step(
            &mut t,
            1,
            &[c],
            &Pose2::IDENTITY,
            &far,
            &TrackConfig { gate_m: 0.1, ..cfg },
        );
        // New tracks join the table after the merge pass: the next frame merges them.
        step(&mut t, 2, &[], &Pose2::IDENTITY, &far, &cfg);
        assert_eq!(t.all().len(), 1, "merged");
        let m = t.all()[0];
        assert!(
            (m.likelihood() - (21.0 / 102.0 + 91.0 / 102.0) / 2.0).abs() < 1e-3,
            "{m:?}"
        );
    }

    #[test]
    fn the_report_model_holds_back_what_it_finds_a_phantom() {
        let far = ranges(4.0);
        let run = |o: FrameObject, cfg: &TrackConfig| {
            let mut t = Tracks::new();
            for f in 0..12 {
                step(&mut t, f, &[o], &Pose2::IDENTITY, &far, cfg);
            }
            let first = t.confirmed().next().copied();
            (first, t)
        };
        // A model that reads only the detections' mean score: a phantom below 0.5.
        let mut weights = [0.0; REPORT_FEATURES];
        let score = FEATURE_NAMES.iter().position(|n| *n == "score").unwrap();
        weights[score] = -20.0;
        let model = ReportModel {
            weights,
            bias: 10.0,
            threshold: 0.5,
            max_hits: 100,
        };
        let cfg = TrackConfig {
            report_model: Some(model),
            ..quick()
        };
        let (low, _) = run(obs(ObjectClass::Box, 2.0, 0.0, 0.3, Evidence::B), &cfg);
        let low = low.expect("earned its report");
        let f = low.report_features(11);
        assert_eq!(
            (f[1], f[5], f[12]),
            (1.0, 1.0, 1.0),
            "box, seen by B, all B: {f:?}"
        );
        assert!(
            (f[score] - 0.3).abs() < 1e-6 && (f[8] - 1.0).abs() < 1e-6,
            "{f:?}"
        );
        assert!(model.phantom_probability(&f) > 0.9);
        assert!(low.held_back(11, &cfg) && !low.unlikely(&cfg));
        let (high, _) = run(obs(ObjectClass::Box, 2.0, 0.0, 0.9, Evidence::B), &cfg);
        assert!(!high.expect("earned its report").held_back(11, &cfg));
        // Door frames are the map's walls' to judge; no model, nothing held back.
        let (door, _) = run(
            obs(ObjectClass::DoorFrame, 2.0, 0.0, 0.3, Evidence::B),
            &cfg,
        );
        assert!(!door.expect("earned its report").held_back(11, &cfg));
        let off = TrackConfig {
            report_model: None,
            ..cfg
        };
        assert!(!low.held_back(11, &off));
        // Nor one seen in more frames than the model judges.
        let few = TrackConfig {
            report_model: Some(ReportModel {
                max_hits: low.hits,
                ..model
            }),
            ..cfg
        };
        assert!(!low.held_back(11, &few));
        // A feature that is not a number adds nothing.
        let mut bad = f;
        bad[score] = f32::NAN;
        assert!((model.phantom_probability(&bad) - 1.0 / (1.0 + libm::expf(-10.0))).abs() < 1e-6);
        // Its place seen empty (the rays at 4 m pass through it) is tallied, not as a miss.
        let (_, mut t) = run(obs(ObjectClass::Box, 2.0, 0.0, 0.9, Evidence::B), &cfg);
        for f in 12..14 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &far, &cfg);
        }
        let gone = t.tracks.first().expect("kept once reported");
        assert_eq!(
            (gone.tally.empties, gone.tally.misses),
            (2, 0),
            "{:?}",
            gone.tally
        );
        assert_eq!(gone.tally.hits_by, [0, 12, 0]);
    }

    #[test]
    fn a_box_as_narrow_as_a_post_is_not_reported_until_seen_box_wide() {
        let mut t = Tracks::new();
        let cfg = quick();
        // Something 2 m ahead across `half` bins either side of 0°, the rest of the room at 4 m.
        let thing = |half: usize| {
            let mut r = ranges(4.0);
            for d in 0..=half {
                r[d] = 2.0;
                r[(BINS - d) % BINS] = 2.0;
            }
            crate::sight::returns(&r)
        };
        let seen = obs(ObjectClass::Box, 2.05, 0.0, 0.9, Evidence::AB);
        for f in 0..10 {
            step(&mut t, f, &[seen], &Pose2::IDENTITY, &ranges(4.0), &cfg);
            // A post of 0.14 m (4 bins at 2 m).
            t.measure_outlines(&Pose2::IDENTITY, &thing(2));
        }
        let b = t.confirmed().next().expect("confirmed");
        assert!(b.narrow_views >= NARROW_VIEWS && b.too_narrow(), "{b:?}");
        // Seen once 0.42 m wide (12 bins), it is a box for good: something in front of a box
        // narrows it, nothing widens a post.
        t.measure_outlines(&Pose2::IDENTITY, &thing(6));
        t.measure_outlines(&Pose2::IDENTITY, &thing(1));
        let b = t.confirmed().next().expect("confirmed");
        assert!(!b.too_narrow(), "{b:?}");
        // Two narrow views are not enough.
        let mut two = Tracks::new();
        for f in 0..10 {
            step(&mut two, f, &[seen], &Pose2::IDENTITY, &ranges(4.0), &cfg);
            if f < 2 {
                two.measure_outlines(&Pose2::IDENTITY, &thing(2));
            }
        }
        assert!(!two.confirmed().next().expect("confirmed").too_narrow());
        // Chairs are four posts: the rule is the box's alone.
        let mut c = Tracks::new();
        for f in 0..10 {
            step(
                &mut c,
                f,
                &[obs(CHAIR, 2.05, 0.0, 0.9, Evidence::AB)],
                &Pose2::IDENTITY,
                &ranges(4.0),
                &cfg,
            );
            c.measure_outlines(&Pose2::IDENTITY, &thing(2));
        }
        assert!(!c.confirmed().next().expect("confirmed").too_narrow());
    }

    /// Whether a box track at `c`, measured over 20 revolutions of `clean` (a pillar or a box,
    /// `crate::outline::test::scan`) with range noise `frac`, looks round.
    fn looks_round_over(c: Point2, clean: [f32; BINS], frac: f32) -> bool {
        use crate::outline::test::noisy;
        let cfg = quick();
        let mut t = Tracks::new();
        let seen = obs(ObjectClass::Box, c.x, c.y, 0.9, Evidence::B);
        step(&mut t, 0, &[seen], &Pose2::IDENTITY, &ranges(0.0), &cfg);
        for seed in 0..20 {
            let r = noisy(clean, frac, 7 + seed);
            t.measure_outlines(&Pose2::IDENTITY, &crate::sight::returns(&r));
        }
        t.all()[0].looks_round()
    }

    #[test]
    fn a_pillar_looks_round_over_revolutions_a_box_never_does() {
        use crate::outline::test::{noisy, scan};
        let mut missed = 0;
        for range in [1.0f32, 2.0, 3.0] {
            for rad in [0.15f32, 0.2, 0.25, 0.3] {
                let c = Point2::new(range, 0.2);
                // The annex's sensor (σ 5 mm + 0.6 %) and a good LDS-01 (1 %).
                for frac in [0.006, 0.01] {
                    if !looks_round_over(c, scan(Some((c, rad)), None), frac) {
                        missed += 1;
                    }
                }
            }
            for (w, h) in [(0.6f32, 0.4f32), (0.48, 0.32), (0.8, 0.3)] {
                for yaw in [0.0f32, 0.3, 0.785, 1.2] {
                    let c = Point2::new(range + 0.1, 0.1);
                    // The simulator's noise too (1.5–3.5 %): a box is never round.
                    for frac in [0.006, 0.01, 0.015, 0.025, 0.035] {
                        assert!(
                            !looks_round_over(c, scan(None, Some((c, w, h, yaw))), frac),
                            "box {w}x{h} yaw {yaw} at {range} m, noise {frac}"
                        );
                    }
                }
            }
        }
        // 24 pillar cases at a good sensor's noise: at least two thirds found round (17 when
        // written; the rest small ones far off, where even 20 revolutions do not tell the arc
        // from the noise, and at 1 % noise 3 m away).
        assert!(missed <= 8, "{missed} of 24 pillars not found round");
        // A chair's returns are never judged: the rule is the box's.
        let mut t = Tracks::new();
        let c = Point2::new(2.0, 0.2);
        step(
            &mut t,
            0,
            &[obs(CHAIR, c.x, c.y, 0.9, Evidence::B)],
            &Pose2::IDENTITY,
            &ranges(0.0),
            &quick(),
        );
        for seed in 0..20 {
            let r = noisy(scan(Some((c, 0.2)), None), 0.006, seed);
            t.measure_outlines(&Pose2::IDENTITY, &crate::sight::returns(&r));
        }
        assert!(!t.all()[0].looks_round() && t.all()[0].arc_views == 0);
    }

    /// A box track at `c` measured over `revs` revolutions of a LiDAR at the origin turning
    /// 0.03 rad a revolution, with the pillar or box of `crate::outline::test::scan` (map frame)
    /// and range noise `frac`.
    fn measured_turning(
        round: Option<(Point2, f32)>,
        square: Option<(Point2, f32, f32, f32)>,
        frac: f32,
        revs: u32,
    ) -> Track {
        use crate::outline::test::{noisy, scan_from};
        let c = round.map(|r| r.0).or(square.map(|s| s.0)).unwrap();
        let mut t = Tracks::new();
        let seen = obs(ObjectClass::Box, c.x, c.y, 0.9, Evidence::B);
        step(&mut t, 0, &[seen], &Pose2::IDENTITY, &ranges(0.0), &quick());
        for k in 0..revs {
            let lidar = Pose2::new(0.0, 0.0, -0.03 * k as f32);
            let r = scan_from(&lidar, round, square);
            let pts = crate::sight::returns(&noisy(r, frac, 11 + k * 7919));
            t.measure_outlines(&lidar, &pts);
        }
        t.all()[0]
    }

    #[test]
    fn a_pillar_at_the_simulators_noise_looks_round_once_its_outline_is_averaged() {
        // A pillar of 0.2 m at 2 m, at 2.5 % range noise: the fits summed over revolutions
        // say nothing, the averaged outline does.
        let c = Point2::new(2.0, 0.2);
        let p = measured_turning(Some((c, 0.2)), None, 0.025, 80);
        assert!(p.looks_round(), "{p:?}");
        assert!(p.averaged_round[0] >= AVERAGED_ROUND_VIEWS, "{p:?}");
        let mut summed_only = p;
        summed_only.averaged_round = [0; 2];
        assert!(!summed_only.looks_round(), "the summed fits alone: {p:?}");
        // A box of 0.6 × 0.4 there is not.
        for yaw in [0.0f32, 0.5, 1.0] {
            let b = measured_turning(None, Some((c, 0.6, 0.4, yaw)), 0.025, 80);
            assert!(!b.looks_round(), "yaw {yaw}: {b:?}");
        }
    }

    #[test]
    fn ids_are_stable_and_tracks_confirm_after_three_hits() {
        let mut t = Tracks::new();
        // One method confirms as fast as two here: this test is about something else.
        let cfg = TrackConfig {
            single_method_hits: 3,
            ..quick()
        };
        let scan = ranges(0.0);
        for f in 0..5u64 {
            // Two chairs, listed in a different order every frame, with a little noise.
            let j = f as f32 * 0.01;
            let a = obs(CHAIR, 1.0 + j, 0.0, 0.8, Evidence::A);
            let b = obs(ObjectClass::Box, -1.0, 1.0 - j, 0.9, Evidence::B);
            let list = if f % 2 == 0 { [a, b] } else { [b, a] };
            step(&mut t, f, &list, &Pose2::IDENTITY, &scan, &cfg);
            assert_eq!(t.all().len(), 2);
            assert_eq!(
                t.confirmed().count(),
                if f >= 2 { 2 } else { 0 },
                "frame {f}"
            );
        }
        let chair = t.all().iter().find(|x| x.class() == CHAIR).unwrap();
        let boxx = t
            .all()
            .iter()
            .find(|x| x.class() == ObjectClass::Box)
            .unwrap();
        assert_eq!(
            (chair.id, boxx.id),
            (0, 1),
            "first seen, first numbered; never renumbered"
        );
        assert_eq!(chair.hits, 5);
        assert_eq!(chair.evidence(), Evidence::A);
        assert_eq!(boxx.evidence(), Evidence::B);
        assert!((chair.centre.x - 1.02).abs() < 0.02, "{:?}", chair.centre);
    }

    #[test]
    fn a_flickering_phantom_is_never_confirmed_and_dies_unseen() {
        let mut t = Tracks::new();
        let cfg = quick();
        let scan = ranges(0.0);
        step(
            &mut t,
            0,
            &[obs(CHAIR, 2.0, 0.0, 0.5, Evidence::A)],
            &Pose2::IDENTITY,
            &scan,
            &cfg,
        );
        for f in 1..=cfg.tentative_frames + 1 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &scan, &cfg);
            assert_eq!(t.confirmed().count(), 0);
        }
        assert!(t.all().is_empty());
        assert_eq!(t.stats().deleted, 1);
    }

    #[test]
    fn a_moved_object_leaves_when_its_place_is_seen_empty() {
        let mut t = Tracks::new();
        let cfg = quick();
        // A box 2 m ahead: its rays return at 2 m.
        let mut scan = ranges(3.4);
        for d in [358usize, 359, 0, 1, 2] {
            scan[d] = 1.9;
        }
        for f in 0..6 {
            step(
                &mut t,
                f,
                &[obs(ObjectClass::Box, 2.0, 0.0, 0.9, Evidence::AB)],
                &Pose2::IDENTITY,
                &scan,
                &cfg,
            );
        }
        assert_eq!(t.confirmed().count(), 1);
        // It is carried away: the rays now reach the wall behind.
        let empty = ranges(3.4);
        let mut frames = 0;
        while t.confirmed().count() > 0 {
            frames += 1;
            assert!(frames < 20, "still reported after {frames} frames");
            step(&mut t, 5 + frames, &[], &Pose2::IDENTITY, &empty, &cfg);
        }
        // Seen empty in every revolution, it leaves well within the goal's 2 s (10 frames):
        // three revolutions take it from the cap below the report threshold (`free_loss`).
        assert!(
            frames <= 4,
            "gone from the map within 0.8 s (4 frames): {frames}"
        );
        // Once reported, it is forgotten at the existence floor (`Track::delete_below`).
        while !t.all().is_empty() {
            frames += 1;
            assert!(frames <= 10, "still in the table after {frames} frames");
            step(&mut t, 5 + frames, &[], &Pose2::IDENTITY, &empty, &cfg);
        }
    }

    #[test]
    fn a_piece_the_methods_stop_finding_for_a_while_comes_back_under_its_id() {
        // A box only Method B sees, 2 m ahead, its rays returning from it throughout.
        let cfg = TrackConfig::default();
        let mut scan = ranges(3.4);
        for d in [358usize, 359, 0, 1, 2] {
            scan[d] = 1.9;
        }
        let seen = [obs(ObjectClass::Box, 2.0, 0.0, 0.9, Evidence::B)];
        let mut t = Tracks::new();
        let mut f = 0u64;
        while t.confirmed().count() == 0 {
            assert!(f < 30, "never reported");
            step(&mut t, f, &seen, &Pose2::IDENTITY, &scan, &cfg);
            f += 1;
        }
        let (id, first) = (t.all()[0].id, f);
        // Seen in every revolution for 8 s; then Method B loses it for 2.4 s from where the
        // robot is now: misses in plain view take it off the map ...
        while f < 40 {
            step(&mut t, f, &seen, &Pose2::IDENTITY, &scan, &cfg);
            f += 1;
        }
        for _ in 0..12 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &scan, &cfg);
            f += 1;
        }
        assert_eq!(
            t.confirmed().count(),
            0,
            "a piece missed for 2.4 s is not reported"
        );
        let kept = t.all()[0];
        assert!(kept.existence < cfg.delete_existence, "{kept:?}");
        assert_eq!(t.all().len(), 1, "but the table keeps what it had reported");
        // ... and it is found again: the same track, reported in fewer frames than it first
        // took.
        let again = f;
        while t.confirmed().count() == 0 {
            assert!(f < again + 30, "never reported again");
            step(&mut t, f, &seen, &Pose2::IDENTITY, &scan, &cfg);
            f += 1;
        }
        assert_eq!(t.all()[0].id, id);
        assert!(
            f - again < first,
            "back in {} frames, first in {first}",
            f - again
        );
        // A tentative track never reported is still forgotten when unseen.
        let mut u = Tracks::new();
        step(&mut u, 0, &seen, &Pose2::IDENTITY, &scan, &cfg);
        for g in 1..=cfg.tentative_frames + 1 {
            step(&mut u, g, &[], &Pose2::IDENTITY, &ranges(0.0), &cfg);
        }
        assert!(u.all().is_empty(), "{:?}", u.all());
    }

    #[test]
    fn a_moved_object_leaves_when_the_wall_behind_its_place_is_out_of_reach() {
        // The room returns all round (walls at 1.5 m) but ahead, where the wall is beyond the
        // LiDAR's reach: those rays return nothing.
        let mut room = ranges(1.5);
        room[330..].fill(0.0);
        room[..30].fill(0.0);
        let mut with_box = room;
        for d in [358usize, 359, 0, 1, 2] {
            with_box[d] = 1.9;
        }
        for blinded in [false, true] {
            let mut t = Tracks::new();
            let cfg = quick();
            for f in 0..6 {
                step(
                    &mut t,
                    f,
                    &[obs(ObjectClass::Box, 2.0, 0.0, 0.9, Evidence::AB)],
                    &Pose2::IDENTITY,
                    &with_box,
                    &cfg,
                );
            }
            assert_eq!(t.confirmed().count(), 1);
            // Carried away; or a LiDAR that returns nothing at all (nothing can be said).
            let after = if blinded { ranges(0.0) } else { room };
            let mut frames = 0;
            while t.confirmed().count() > 0 && frames < 20 {
                frames += 1;
                step(&mut t, 5 + frames, &[], &Pose2::IDENTITY, &after, &cfg);
            }
            if blinded {
                assert_eq!(t.confirmed().count(), 1, "a blinded LiDAR erased the map");
            } else {
                assert!(frames <= 10, "gone after {frames} frames (2 s: 10)");
            }
        }
    }

    #[test]
    fn out_of_view_or_occluded_tracks_keep_their_state() {
        let mut t = Tracks::new();
        // One method confirms as fast as two here: this test is about something else.
        let cfg = TrackConfig {
            single_method_hits: 3,
            ..quick()
        };
        let scan = ranges(0.0);
        for f in 0..4 {
            step(
                &mut t,
                f,
                &[obs(CHAIR, 2.0, 0.0, 0.9, Evidence::A)],
                &Pose2::IDENTITY,
                &scan,
                &cfg,
            );
        }
        let before = t.all()[0];
        // Something stands in front of it (returns at 1 m), then nothing returns at all (a
        // blinded LiDAR: no ray with no return is then taken to have passed through).
        for (f, scan) in [(4, ranges(1.0)), (5, ranges(0.0))] {
            step(&mut t, f, &[], &Pose2::IDENTITY, &scan, &cfg);
        }
        assert_eq!(t.all()[0].existence, before.existence);
        assert!(t.all()[0].confirmed);
    }

    /// A chair 2 m ahead, tracked over four frames of a revolution whose rays pass between its
    /// legs (to 3.4 m) except two on legs: the table and that revolution.
    fn chair_on_two_legs(cfg: &TrackConfig) -> (Tracks, [f32; BINS]) {
        let mut t = Tracks::new();
        let mut scan = ranges(3.4);
        scan[4] = 2.1;
        scan[356] = 1.9;
        for f in 0..4 {
            step(
                &mut t,
                f,
                &[obs(CHAIR, 2.0, 0.0, 0.9, Evidence::A)],
                &Pose2::IDENTITY,
                &scan,
                cfg,
            );
        }
        (t, scan)
    }

    #[test]
    fn legs_inside_the_footprint_are_not_seen_as_empty() {
        let cfg = quick();
        let (mut t, scan) = chair_on_two_legs(&cfg);
        let seen = t.all()[0].existence;
        // Not detected for a frame while in plain view: a missed detection, not an empty place.
        step(&mut t, 4, &[], &Pose2::IDENTITY, &scan, &cfg);
        let after = t.all()[0].existence;
        assert!(
            (seen - after - cfg.miss_loss).abs() < 1e-6,
            "{seen} → {after}"
        );
        assert!(cfg.miss_loss < cfg.free_loss);
    }

    #[test]
    fn a_footprint_that_returned_too_little_for_a_method_is_not_missed() {
        let cfg = TrackConfig {
            miss_min_returns: 3,
            ..quick()
        };
        // The revolution caught two of its legs, then three.
        let (mut t, mut scan) = chair_on_two_legs(&cfg);
        let (seen, views) = (t.all()[0].existence, t.all()[0].views);
        step(&mut t, 4, &[], &Pose2::IDENTITY, &scan, &cfg);
        assert_eq!(t.all()[0].existence, seen);
        assert_eq!(t.all()[0].views, views, "not a view either");
        scan[0] = 2.0;
        step(&mut t, 5, &[], &Pose2::IDENTITY, &scan, &cfg);
        let after = t.all()[0].existence;
        assert!(
            (seen - after - cfg.miss_loss).abs() < 1e-6,
            "{seen} → {after}"
        );
    }

    /// `chair_on_two_legs`'s revolution with its legs' returns dropped out: the rays across
    /// its footprint return nothing, the room's walls elsewhere still return.
    fn legs_dropped_out(mut scan: [f32; BINS]) -> [f32; BINS] {
        scan[350..BINS].fill(0.0);
        scan[..=10].fill(0.0);
        scan
    }

    #[test]
    fn a_dark_piece_seen_empty_only_by_rays_with_no_return_counts_in_a_row() {
        let cfg = TrackConfig {
            empty_revs: 2,
            ..quick()
        };
        let (mut t, scan) = chair_on_two_legs(&cfg);
        let dark = legs_dropped_out(scan);
        let seen = t.all()[0].existence;
        // One revolution in which the legs' returns dropped out says nothing yet...
        step(&mut t, 4, &[], &Pose2::IDENTITY, &dark, &cfg);
        assert_eq!(t.all()[0].existence, seen);
        // ...nor does it after a detection broke the row...
        let chair = [obs(CHAIR, 2.0, 0.0, 0.9, Evidence::A)];
        step(&mut t, 5, &chair, &Pose2::IDENTITY, &scan, &cfg);
        let seen = t.all()[0].existence;
        step(&mut t, 6, &[], &Pose2::IDENTITY, &dark, &cfg);
        assert_eq!(t.all()[0].existence, seen);
        // ...the second in a row does, and each one after it.
        step(&mut t, 7, &[], &Pose2::IDENTITY, &dark, &cfg);
        assert!((seen - t.all()[0].existence - cfg.free_loss).abs() < 1e-6);
        step(&mut t, 8, &[], &Pose2::IDENTITY, &dark, &cfg);
        assert!((seen - t.all()[0].existence - 2.0 * cfg.free_loss).abs() < 1e-6);
        // Rays that return from beyond the whole footprint show it empty at once.
        let (mut t, _) = chair_on_two_legs(&cfg);
        let seen = t.all()[0].existence;
        step(&mut t, 4, &[], &Pose2::IDENTITY, &ranges(3.4), &cfg);
        assert!((seen - t.all()[0].existence - cfg.free_loss).abs() < 1e-6);
        // Nor does a row matter where the footprint returned nothing when it was detected (a
        // phantom in the open, not a dark piece).
        let mut t = Tracks::new();
        let open = legs_dropped_out(ranges(3.4));
        for f in 0..4 {
            let chair = [obs(CHAIR, 2.0, 0.0, 0.9, Evidence::A)];
            step(&mut t, f, &chair, &Pose2::IDENTITY, &open, &cfg);
        }
        assert_eq!(t.all()[0].hit_returns, 0.0);
        let seen = t.all()[0].existence;
        step(&mut t, 4, &[], &Pose2::IDENTITY, &open, &cfg);
        assert!((seen - t.all()[0].existence - cfg.free_loss).abs() < 1e-6);
        // With `empty_revs` 1 (the default) the first dark revolution counts.
        let one = quick();
        let (mut t, scan) = chair_on_two_legs(&one);
        let seen = t.all()[0].existence;
        step(
            &mut t,
            4,
            &[],
            &Pose2::IDENTITY,
            &legs_dropped_out(scan),
            &one,
        );
        assert!((seen - t.all()[0].existence - one.free_loss).abs() < 1e-6);
    }

    #[test]
    fn furniture_of_two_classes_on_one_spot_is_one_piece_where_set() {
        // One piece taken for a chair and for a box, 0.2 m apart, two frames running.
        let seen = |cross_merge_m: f32| {
            let cfg = TrackConfig {
                cross_merge_m,
                ..quick()
            };
            let mut t = Tracks::new();
            let scan = ranges(0.0);
            let both = [
                obs(CHAIR, 2.0, 0.0, 0.9, Evidence::B),
                obs(ObjectClass::Box, 2.2, 0.0, 0.6, Evidence::B),
            ];
            for f in 0..2 {
                step(&mut t, f, &both, &Pose2::IDENTITY, &scan, &cfg);
            }
            t
        };
        assert_eq!(seen(0.0).all().len(), 2, "off: two tracks");
        let one = seen(0.3);
        assert_eq!(one.all().len(), 1);
        assert_eq!(one.all()[0].class(), CHAIR, "the class with more evidence");
        assert_eq!(one.stats().merged, 1);
        // Farther apart than that: two pieces.
        assert_eq!(seen(0.15).all().len(), 2);
    }

    #[test]
    fn bad_input_is_counted_not_tracked() {
        let mut t = Tracks::new();
        let cfg = quick();
        let scan = ranges(0.0);
        let bad = [
            obs(CHAIR, f32::NAN, 0.0, 0.9, Evidence::A),
            obs(CHAIR, 1.0, 0.0, f32::INFINITY, Evidence::A),
            obs(CHAIR, 1e9, 0.0, 0.9, Evidence::A),
        ];
        step(&mut t, 0, &bad, &Pose2::IDENTITY, &scan, &cfg);
        assert!(t.all().is_empty());
        assert_eq!(t.stats().rejected, 3);
        let lost = Pose2::new(f32::NAN, 0.0, 0.0);
        step(
            &mut t,
            1,
            &[obs(CHAIR, 1.0, 0.0, 0.9, Evidence::A)],
            &lost,
            &scan,
            &cfg,
        );
        assert_eq!(t.stats().bad_poses, 1);
        assert!(
            t.all().is_empty(),
            "nothing is placed from a pose that is not known"
        );
    }

    #[test]
    fn a_full_table_evicts_the_weakest_and_counts_it() {
        let mut t = Tracks::new();
        let cfg = quick();
        let scan = ranges(0.0);
        // One strong confirmed track, then more tentative ones than fit.
        for f in 0..4 {
            step(
                &mut t,
                f,
                &[obs(CHAIR, 0.0, 5.0, 1.0, Evidence::AB)],
                &Pose2::IDENTITY,
                &scan,
                &cfg,
            );
        }
        let mut many: Vec<FrameObject, 80> = Vec::new();
        for k in 0..70 {
            let (x, y) = ((k % 10) as f32 - 4.5, -2.0 - (k / 10) as f32);
            let _ = many.push(obs(ObjectClass::Box, x, y, 0.3, Evidence::B));
        }
        step(&mut t, 4, &many, &Pose2::IDENTITY, &scan, &cfg);
        assert_eq!(t.all().len(), MAX_TRACKS);
        assert_eq!(t.stats().evicted, 70 + 1 - MAX_TRACKS as u64);
        assert!(
            t.all().iter().any(|x| x.confirmed && x.id == 0),
            "the strong track stays"
        );
    }

    #[test]
    fn door_frames_and_furniture_never_merge() {
        let mut t = Tracks::new();
        let cfg = quick();
        let scan = ranges(0.0);
        step(
            &mut t,
            0,
            &[obs(ObjectClass::DoorFrame, 1.0, 0.0, 0.9, Evidence::A)],
            &Pose2::IDENTITY,
            &scan,
            &cfg,
        );
        step(
            &mut t,
            1,
            &[obs(CHAIR, 1.1, 0.0, 0.9, Evidence::B)],
            &Pose2::IDENTITY,
            &scan,
            &cfg,
        );
        assert_eq!(t.all().len(), 2);
    }

    #[test]
    fn method_b_door_frames_at_a_corner_of_the_walls_are_not_reported() {
        use crate::walls::test_seg as seg;
        let cfg = TrackConfig {
            single_method_hits: 3,
            ..quick()
        };
        // An L's inner corner at (1, 2), the map's walls seen from the origin.
        let walls = walls_seen(&[seg(-3.0, 2.0, 1.0, 2.0), seg(1.0, 2.0, 1.0, 4.0)]);
        let scan = ranges(0.0);
        // A door frame at (x, y) seen in six frames; the corners marked after each, or not.
        let seen = |x: f32, y: f32, evidence: Evidence, mark: bool| {
            let mut t = Tracks::new();
            let door = obs(ObjectClass::DoorFrame, x, y, 0.9, evidence);
            for f in 0..6 {
                step(&mut t, f, &[door], &Pose2::IDENTITY, &scan, &cfg);
                if mark {
                    t.mark_corner_doors(&walls);
                }
            }
            t
        };
        for (evidence, reported) in [(Evidence::B, 0), (Evidence::A, 1)] {
            let t = seen(0.85, 1.8, evidence, true);
            assert_eq!(t.confirmed().count(), reported, "{evidence:?}");
        }
        // Away from the corner, in the wall's middle, Method B's door frame is reported.
        assert_eq!(seen(-1.5, 1.9, Evidence::B, true).confirmed().count(), 1);
        // One reported before the walls were known stops being reported once they are.
        let mut t = seen(0.85, 1.8, Evidence::B, false);
        assert_eq!(t.confirmed().count(), 1);
        t.mark_corner_doors(&walls);
        assert_eq!(t.confirmed().count(), 0);
    }

    #[test]
    fn method_b_door_frames_beside_a_walls_end_with_no_other_jamb_are_not_reported() {
        use crate::walls::test_seg as seg;
        let cfg = TrackConfig {
            single_method_hits: 3,
            ..quick()
        };
        // A wall along y = 2 that ends at x = 0 (a partition's end), seen from the origin;
        // Method B's door frame 0.45 m past its end, where the other jamb would be at x = 0.9.
        let walls = walls_seen(&[seg(-3.0, 2.0, 0.0, 2.0)]);
        let bin_of = |x: f32, y: f32| (libm::atan2f(y, x).to_degrees().round() as usize) % BINS;
        // Open floor beyond the end: the rays past it return from 3.4 m.
        // The wall y = 2 returns in the bins from `from` to `to`.
        let wall = |scan: &mut [f32; BINS], from: usize, to: usize| {
            for (d, r) in scan.iter_mut().enumerate().take(to + 1).skip(from) {
                *r = 2.0 / libm::sinf((d as f32).to_radians());
            }
        };
        let mut open = ranges(3.4);
        wall(&mut open, bin_of(0.0, 2.0), bin_of(-3.0, 2.0));
        // A doorway: the wall goes on from x = 0.9.
        let mut doorway = open;
        wall(&mut doorway, bin_of(4.0, 2.0), bin_of(0.9, 2.0));
        let seen = |scan: &[f32; BINS], evidence: Evidence| {
            let mut t = Tracks::new();
            let door = obs(ObjectClass::DoorFrame, 0.45, 2.0, 0.9, evidence);
            for f in 0..8 {
                step(&mut t, f, &[door], &Pose2::IDENTITY, scan, &cfg);
                t.mark_corner_doors(&walls);
                t.look_for_far_jambs(&walls, &Pose2::IDENTITY, scan, cfg.max_range_m);
            }
            t
        };
        let t = seen(&open, Evidence::B);
        assert!(t.all()[0].lone_jamb(), "{:?}", t.all()[0].far_jamb_views);
        assert_eq!(t.confirmed().count(), 0);
        // Its other jamb there: a doorway, reported.
        let t = seen(&doorway, Evidence::B);
        assert!(!t.all()[0].lone_jamb(), "{:?}", t.all()[0].far_jamb_views);
        assert_eq!(t.confirmed().count(), 1);
        // Method A's door frames are judged by Method A's own rules.
        assert_eq!(seen(&open, Evidence::A).confirmed().count(), 1);
    }

    #[test]
    fn a_doorway_seen_through_stays_and_one_seen_shut_goes() {
        let cfg = quick();
        let mut t = Tracks::new();
        // A doorway 2 m ahead, 0.9 m wide: its jambs end the rays at ±13°, the rays between
        // them return from the next room.
        let mut open = ranges(4.0);
        for d in [12, 13, 14, 15, 345, 346, 347, 348] {
            open[d] = 2.05;
        }
        let door = obs(ObjectClass::DoorFrame, 2.0, 0.0, 0.9, Evidence::AB);
        for f in 0..5 {
            step(&mut t, f, &[door], &Pose2::IDENTITY, &open, &cfg);
        }
        assert_eq!(t.confirmed().count(), 1);
        // The map's walls show a doorway there.
        let doorway = [Point2::new(2.0, 0.05)];
        t.anchor_doors(&doorway);
        // Not detected for 20 s, in plain view and open: still a door.
        for f in 5..105 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &open, &cfg);
        }
        assert_eq!(
            t.confirmed().count(),
            1,
            "an open doorway is not seen empty"
        );
        // Shut: the rays end on the door's line.
        let shut = ranges(2.0);
        for f in 105..125 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &shut, &cfg);
        }
        assert_eq!(t.all().len(), 0, "a shut door leaves the map");

        // A "door frame" on open floor: the rays pass where its jambs would be too.
        let mut t = Tracks::new();
        for f in 0..5 {
            step(&mut t, f, &[door], &Pose2::IDENTITY, &open, &cfg);
        }
        t.anchor_doors(&doorway);
        let floor = ranges(4.0);
        for f in 5..25 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &floor, &cfg);
        }
        assert_eq!(t.all().len(), 0, "no jambs, no doorway");

        // One method's door seen in every other frame it was in view: below the rate.
        let mut t = Tracks::new();
        let b_door = obs(ObjectClass::DoorFrame, 2.0, 0.0, 0.9, Evidence::B);
        for f in 0..20 {
            let seen: &[FrameObject] = if f % 2 == 0 { &[b_door] } else { &[] };
            step(&mut t, f, seen, &Pose2::IDENTITY, &open, &cfg);
            t.anchor_doors(&doorway);
        }
        assert_eq!(t.confirmed().count(), 0, "a flickering one-method door");

        // A door frame the map's walls never showed as a doorway (a reflex corner, say) is
        // judged like furniture: its place seen empty, it goes.
        let mut t = Tracks::new();
        for f in 0..5 {
            step(&mut t, f, &[door], &Pose2::IDENTITY, &open, &cfg);
        }
        for f in 5..25 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &floor, &cfg);
        }
        assert_eq!(t.all().len(), 0, "not anchored, seen empty");
    }

    #[test]
    fn a_door_seen_often_in_a_wall_line_is_held_through_the_methods_silence() {
        use crate::walls::test_seg as seg;
        let cfg = TrackConfig {
            door_hold_hits: 20,
            ..quick()
        };
        // The jambs' walls of a doorway 2 m ahead, x = 2, |y| ≥ 0.45: the map holds them.
        let walls = walls_seen(&[seg(2.0, -3.0, 2.0, -0.45), seg(2.0, 0.45, 2.0, 3.0)]);
        let mut open = ranges(4.0);
        for d in [12, 13, 14, 15, 345, 346, 347, 348] {
            open[d] = 2.05;
        }
        let door = obs(ObjectClass::DoorFrame, 2.0, 0.0, 0.9, Evidence::B);
        // Seen in `hits` frames, then not detected for 4 s, in plain view and open.
        let run = |hits: u64, cfg: &TrackConfig, walls: &WallMap| {
            let mut t = Tracks::new();
            for f in 0..hits {
                step(&mut t, f, &[door], &Pose2::IDENTITY, &open, cfg);
                t.mark_corner_doors(walls);
            }
            assert_eq!(t.confirmed().count(), 1);
            for f in hits..hits + 20 {
                step(&mut t, f, &[], &Pose2::IDENTITY, &open, cfg);
                t.mark_corner_doors(walls);
            }
            t.confirmed().count()
        };
        assert_eq!(run(25, &cfg, &walls), 1, "held");
        // Seen too few times, or the hold off, or not in a line of the map's walls: the
        // methods' silence in plain view takes it off the map as before.
        assert_eq!(run(12, &cfg, &walls), 0, "too few sightings");
        let off = TrackConfig {
            door_hold_hits: 0,
            ..cfg
        };
        assert_eq!(run(25, &off, &walls), 0, "hold off");
        assert_eq!(run(25, &cfg, &WallMap::new()), 0, "in no wall's line");
        // Held, it still leaves when the doorway is seen shut.
        let mut t = Tracks::new();
        for f in 0..25 {
            step(&mut t, f, &[door], &Pose2::IDENTITY, &open, &cfg);
            t.mark_corner_doors(&walls);
        }
        for f in 25..45 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &ranges(2.0), &cfg);
            t.mark_corner_doors(&walls);
        }
        assert_eq!(t.all().len(), 0, "a shut door leaves the map");
    }

    #[test]
    fn one_object_seen_twice_becomes_one_track_with_the_reported_id() {
        // One method confirms as fast as two here: this test is about something else.
        let cfg = TrackConfig {
            single_method_hits: 3,
            ..quick()
        };
        let mut t = Tracks::new();
        let far = [0.0f32; BINS];
        // A chair confirmed at (2, 0).
        for f in 0..4 {
            step(
                &mut t,
                f,
                &[obs(ObjectClass::Chair, 2.0, 0.0, 0.9, Evidence::A)],
                &Pose2::IDENTITY,
                &far,
                &cfg,
            );
        }
        let id = t.confirmed().next().map(|x| x.id);
        assert!(id.is_some());
        // In one frame both methods see it, 0.3 m apart, and fusion did not join them: the
        // second starts a track; the next frame finds the two one object, under the first id.
        let both = [
            obs(ObjectClass::Chair, 2.0, 0.0, 0.9, Evidence::A),
            obs(ObjectClass::Chair, 2.3, 0.0, 0.9, Evidence::B),
        ];
        step(&mut t, 4, &both, &Pose2::IDENTITY, &far, &cfg);
        assert_eq!(t.all().len(), 2);
        step(&mut t, 5, &[], &Pose2::IDENTITY, &far, &cfg);
        assert_eq!(t.all().len(), 1, "{:?}", t.all());
        assert_eq!(t.all()[0].id, id.unwrap());
        assert_eq!(t.all()[0].evidence(), Evidence::AB);
        assert_eq!(t.stats().merged, 1);
        // Two chairs 0.5 m apart stay two.
        let mut t = Tracks::new();
        for f in 0..4 {
            let o = [
                obs(ObjectClass::Chair, 2.0, 0.0, 0.9, Evidence::A),
                obs(ObjectClass::Chair, 2.0, 0.5, 0.9, Evidence::A),
            ];
            step(&mut t, f, &o, &Pose2::IDENTITY, &far, &cfg);
        }
        assert_eq!(t.confirmed().count(), 2);
    }

    /// A desk Method B sees only now and then (every 8th revolution, 1.6 s: each sighting comes
    /// after a gap, which resets the motion filter's stillness) is reported from a robot that
    /// drives past it, once seen from places [`DESK_VIEW_SPAN_M`] apart; from one that stands
    /// still it is not, and neither is a chair seen so, however the robot drives, nor a desk
    /// seen so within [`DESK_BESIDE_M`] of a reported desk.
    #[test]
    fn a_desk_seen_now_and_then_from_a_driving_robot_is_reported() {
        let cfg = TrackConfig::default();
        let run = |class: ObjectClass, drive: f32| {
            let mut t = Tracks::new();
            for f in (0..160u64).step_by(8) {
                let lidar = Pose2::new(drive * f as f32, 0.0, 0.0);
                let o = obs(class, 3.0, 2.0, 0.9, Evidence::AB);
                step(&mut t, f, &[o], &lidar, &ranges(0.0), &cfg);
            }
            assert_eq!(t.all().len(), 1);
            let d = &t.all()[0];
            (d.confirmed, d.view_span)
        };
        // A tour's 0.15 m/s: 0.03 m a revolution.
        let (shown, span) = run(ObjectClass::Desk, 0.03);
        assert!(shown && span >= DESK_VIEW_SPAN_M, "{span}");
        assert_eq!(run(ObjectClass::Desk, 0.0), (false, 0.0));
        assert!(!run(CHAIR, 0.03).0);
        // Seen in every revolution it settles as anything else does, driving or not.
        let mut t = Tracks::new();
        for f in 0..20 {
            let o = obs(ObjectClass::Desk, 3.0, 2.0, 0.9, Evidence::AB);
            step(&mut t, f, &[o], &Pose2::IDENTITY, &ranges(0.0), &cfg);
        }
        assert!(t.all()[0].confirmed);
        // Beside a desk that is reported (1.6 m: its other end, boxed on its own now and
        // then) it must settle; 3.5 m off it is another desk.
        for (x, shown) in [(4.6f32, false), (6.5, true)] {
            let mut t = Tracks::new();
            for f in 0..160u64 {
                let lidar = Pose2::new(0.03 * f as f32, 0.0, 0.0);
                let desk = obs(ObjectClass::Desk, 3.0, 2.0, 0.9, Evidence::AB);
                let other = obs(ObjectClass::Desk, x, 2.0, 0.9, Evidence::AB);
                let seen: &[FrameObject] = if f % 8 == 0 && f > 0 {
                    &[desk, other]
                } else {
                    &[desk]
                };
                step(&mut t, f, seen, &lidar, &ranges(0.0), &cfg);
            }
            assert_eq!(t.all().len(), 2);
            assert!(t.all()[0].confirmed);
            assert_eq!(t.all()[1].confirmed, shown, "{x}");
        }
    }

    #[test]
    fn a_desk_seen_from_elsewhere_keeps_its_track() {
        let cfg = quick();
        let mut t = Tracks::new();
        let far = [0.0f32; BINS];
        for f in 0..4 {
            step(
                &mut t,
                f,
                &[obs(ObjectClass::Desk, 2.0, 0.0, 0.9, Evidence::B)],
                &Pose2::IDENTITY,
                &far,
                &cfg,
            );
        }
        // Its centre estimate 0.8 m away (other legs in view): the same desk.
        step(
            &mut t,
            4,
            &[obs(ObjectClass::Desk, 2.8, 0.0, 0.9, Evidence::B)],
            &Pose2::IDENTITY,
            &far,
            &cfg,
        );
        assert_eq!(t.all().len(), 1);
        // A chair 0.8 m from a chair is another chair.
        let mut t = Tracks::new();
        for f in 0..4 {
            step(
                &mut t,
                f,
                &[obs(ObjectClass::Chair, 2.0, 0.0, 0.9, Evidence::B)],
                &Pose2::IDENTITY,
                &far,
                &cfg,
            );
        }
        step(
            &mut t,
            4,
            &[obs(ObjectClass::Chair, 2.8, 0.0, 0.9, Evidence::B)],
            &Pose2::IDENTITY,
            &far,
            &cfg,
        );
        assert_eq!(t.all().len(), 2);
    }

    #[test]
    fn one_method_alone_needs_more_hits_and_a_steady_rate() {
        let cfg = quick();
        let scan = ranges(0.0);
        // Both methods: reported at the third hit.
        let mut t = Tracks::new();
        for f in 0..3 {
            step(
                &mut t,
                f,
                &[obs(CHAIR, 2.0, 0.0, 0.9, Evidence::AB)],
                &Pose2::IDENTITY,
                &scan,
                &cfg,
            );
        }
        assert_eq!(t.confirmed().count(), 1);
        // Method B alone: not before the eighth.
        let mut t = Tracks::new();
        for f in 0..8u64 {
            assert_eq!(t.confirmed().count(), 0, "frame {f}");
            step(
                &mut t,
                f,
                &[obs(CHAIR, 2.0, 0.0, 0.9, Evidence::B)],
                &Pose2::IDENTITY,
                &scan,
                &cfg,
            );
        }
        assert_eq!(t.confirmed().count(), 1);
        // Method B alone, seen in one frame of two while in plain view (rays end on it): its
        // rate stays below 0.6 and it is never reported.
        let mut t = Tracks::new();
        let on_it = ranges(2.0);
        for f in 0..40u64 {
            let o = [obs(CHAIR, 2.0, 0.0, 0.9, Evidence::B)];
            let seen: &[FrameObject] = if f % 2 == 0 { &o } else { &[] };
            step(&mut t, f, seen, &Pose2::IDENTITY, &on_it, &cfg);
            assert_eq!(t.confirmed().count(), 0, "frame {f}");
        }
    }

    #[test]
    fn a_method_that_did_not_run_misses_nothing() {
        // Method B on its own thread (a Pi 3): it reports in every other frame. A chair only it
        // sees is in plain view throughout; the frames without Method B are not misses and do
        // not count against its rate, so it is reported as if Method B ran every frame.
        let cfg = TrackConfig::default();
        let on_it = ranges(2.0);
        let mut t = Tracks::new();
        for f in 0..20u64 {
            let o = [obs(CHAIR, 2.0, 0.0, 0.9, Evidence::B)];
            let ran = f % 2 == 0;
            let seen: &[FrameObject] = if ran { &o } else { &[] };
            let looked = Looked { a: true, b: ran };
            t.update(
                f,
                f as f64 * 0.2,
                seen,
                &Pose2::IDENTITY,
                &on_it,
                looked,
                &cfg,
            );
        }
        let chair = t.all()[0];
        assert!(chair.confirmed, "{chair:?}");
        assert_eq!((chair.hits, chair.views), (10, 10));
        // What the rays show needs no method: its place seen empty, it goes, Method B or not.
        let through = ranges(3.0);
        let (mut unreported, mut gone) = (None, None);
        for f in 20..40u64 {
            let looked = Looked { a: true, b: false };
            t.update(
                f,
                f as f64 * 0.2,
                &[],
                &Pose2::IDENTITY,
                &through,
                looked,
                &cfg,
            );
            if t.confirmed().count() == 0 {
                unreported.get_or_insert(f);
            }
            if t.all().is_empty() {
                gone = Some(f);
                break;
            }
        }
        assert!(
            unreported.is_some_and(|f| f < 30),
            "reported until {unreported:?}"
        );
        // Forgotten at the existence floor, as a piece once reported is.
        assert!(gone.is_some_and(|f| f < 40), "deleted at {gone:?}");
    }

    #[test]
    fn furniture_that_appears_on_floor_seen_empty_waits_longer() {
        let cfg = TrackConfig {
            appeared_settle_s: 3.0,
            ..TrackConfig::default()
        };
        let seen_through = ranges(4.0);
        let a_box = [obs(ObjectClass::Box, 2.0, 0.0, 0.8, Evidence::AB)];
        // The frame from which it is reported, seen in every frame from frame `from` on.
        let reported_from = |from: u64, cfg: &TrackConfig| {
            let mut t = Tracks::new();
            for f in 0..from {
                step(&mut t, f, &[], &Pose2::IDENTITY, &seen_through, cfg);
            }
            (from..from + 40).find(|&f| {
                step(&mut t, f, &a_box, &Pose2::IDENTITY, &seen_through, cfg);
                t.confirmed().next().is_some()
            })
        };
        // There from the first look: reported after the usual second (5 revolutions).
        assert_eq!(reported_from(0, &cfg), Some(5));
        // Appearing where the rays had passed: 3 s (15 revolutions) from its first sighting.
        assert_eq!(reported_from(10, &cfg), Some(25));
        // Without the rule it waits the usual second there too.
        let plain = TrackConfig {
            appeared_settle_s: 0.0,
            ..cfg
        };
        assert_eq!(reported_from(10, &plain), Some(15));
        // A door frame stands in a doorway, which rays pass: no extra wait.
        let door = [obs(ObjectClass::DoorFrame, 2.0, 0.0, 0.8, Evidence::AB)];
        let mut t = Tracks::new();
        for f in 0..10 {
            step(&mut t, f, &[], &Pose2::IDENTITY, &seen_through, &cfg);
        }
        for f in 10..16 {
            step(&mut t, f, &door, &Pose2::IDENTITY, &seen_through, &cfg);
        }
        assert!(t.confirmed().next().is_some());
    }

    #[test]
    fn legs_that_stood_and_walked_on_leave_though_detected_beside_their_place() {
        let cfg = TrackConfig {
            appeared_settle_s: 3.0,
            seen_through_revs: 2,
            ..TrackConfig::default()
        };
        let passed = ranges(3.4);
        // Legs standing 2 m ahead: their rays return at 1.9–2.1 m.
        let mut legs = ranges(3.4);
        for d in [357usize, 358, 2, 3] {
            legs[d] = 2.0;
        }
        let here = [obs(ObjectClass::Box, 2.0, 0.0, 0.8, Evidence::AB)];
        // The person walks on in a small loop: detections 0.35 m aside, within the gate,
        // while the rays across the place itself return from the wall behind.
        let beside = [obs(ObjectClass::Box, 2.0, 0.35, 0.8, Evidence::AB)];
        let run = |cfg: &TrackConfig, gone_every: u64| {
            let mut t = Tracks::new();
            for f in 0..10 {
                step(&mut t, f, &[], &Pose2::IDENTITY, &passed, cfg);
            }
            for f in 10..30 {
                step(&mut t, f, &here, &Pose2::IDENTITY, &legs, cfg);
            }
            assert!(t.all()[0].born_on_free, "appeared on floor seen empty");
            let start = t.all()[0].existence;
            for f in 30..50 {
                // Every `gone_every`-th revolution shows the place empty; the others, legs.
                let scan = if f % gone_every == 0 { &passed } else { &legs };
                step(&mut t, f, &beside, &Pose2::IDENTITY, scan, cfg);
            }
            (start, t.all().first().map(|tr| tr.existence))
        };
        // The place seen empty in every revolution: the track dies though still matched.
        let (start, end) = run(&cfg, 1);
        assert!(
            end.is_none_or(|e| e < cfg.confirm_existence),
            "{start} → {end:?}"
        );
        // Seen empty only in every other revolution (legs between): nothing said.
        let (start, end) = run(&cfg, 2);
        assert!(end.is_some_and(|e| e >= start), "{start} → {end:?}");
        // Off: the detections beside keep it.
        let off = TrackConfig {
            seen_through_revs: 0,
            ..cfg
        };
        let (start, end) = run(&off, 1);
        assert!(end.is_some_and(|e| e >= start), "{start} → {end:?}");
    }

    #[test]
    fn walking_legs_are_a_person_never_furniture() {
        let cfg = TrackConfig::default();
        let scan = ranges(0.0);
        // Legs seen by both methods as a chair, walking +x at a slow, a usual and a brisk pace
        // past a real chair at (2, 0.6), the legs' centre swinging ±0.08 m with the stride;
        // five revolutions a second.
        for speed in [0.5f32, 0.8, 1.1] {
            let mut t = Tracks::new();
            let mut listed = 0;
            for f in 0..25u64 {
                let swing = if f % 2 == 0 { 0.08 } else { -0.08 };
                let x = 0.2 + speed * 0.2 * f as f32 + swing;
                let list = [
                    obs(CHAIR, x, 0.0, 0.8, Evidence::AB),
                    obs(CHAIR, 2.0, 0.6, 0.8, Evidence::AB),
                ];
                step(&mut t, f, &list, &Pose2::IDENTITY, &scan, &cfg);
                let people: heapless::Vec<&Track, 4> = t.people(f, &cfg).collect();
                assert!(people.len() <= 1, "{speed} m/s, frame {f}");
                if let Some(p) = people.first() {
                    listed += 1;
                    assert!(
                        (p.centre.x - x).abs() < 0.25,
                        "{speed}: {} vs {x}",
                        p.centre.x
                    );
                    assert!(
                        (p.motion.vel.x - speed).abs() < 0.35,
                        "vx {}",
                        p.motion.vel.x
                    );
                }
                // Only the real chair is ever furniture.
                for c in t.confirmed() {
                    assert!(
                        c.centre.distance(Point2::new(2.0, 0.6)) < 0.1,
                        "{speed} m/s, frame {f}: {c:?}"
                    );
                }
            }
            assert_eq!(t.confirmed().count(), 1);
            // Listed from within 2.5 s of the walk's start to its end.
            assert!(listed >= 12, "{speed} m/s: listed in {listed} frames");
            // The person walks out of sight: listed no more after a few frames.
            for f in 25..29u64 {
                step(&mut t, f, &[], &Pose2::IDENTITY, &scan, &cfg);
            }
            assert_eq!(t.people(28, &cfg).count(), 0);
        }
    }

    #[test]
    fn a_new_piece_is_reported_once_seen_still_for_a_second() {
        let cfg = TrackConfig::default();
        let scan = ranges(0.0);
        let mut t = Tracks::new();
        for f in 0..8u64 {
            let j = if f % 2 == 0 { 0.05 } else { -0.05 };
            let o = [obs(CHAIR, 2.0 + j, 0.0, 0.8, Evidence::AB)];
            step(&mut t, f, &o, &Pose2::IDENTITY, &scan, &cfg);
            // 0.2 s a frame: reported from the sixth frame (1 s after the first).
            assert_eq!(t.confirmed().count(), usize::from(f >= 5), "frame {f}");
        }
    }
}
