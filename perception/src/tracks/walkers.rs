//! Walkers: tracks of the leg detector's person candidates ([`crate::legs`]), each with the
//! motion filter; one that walks is a person, listed in `people` with the id the furniture
//! tracks draw from (never reused). Candidates that stand still — bins, thin pillars, table
//! legs, a person standing — are tracked too but never listed: a leg-sized blob is only a
//! person once it walks. Fixed capacity, allocation-free, `no_std`.
//!
//! Association is greedy on the global minimum distance within [`WALKER_GATE_M`] of where a
//! walker stands or its walk has taken it; a walker unseen for [`WALKER_LOST_FRAMES`] is
//! dropped (a person who comes back into view starts a new one, listed again once it walks).

use heapless::Vec;

use super::{PEOPLE_FRAMES, TrackConfig, Tracks};
use crate::geometry::Point2;
use crate::legs::{LegConfig, MAX_LEGS, Person};
use crate::motion::{Motion, MotionConfig};
use crate::still_legs::StillLegs;

/// Walkers held at most (people and the leg-sized things that stand still).
pub const MAX_WALKERS: usize = 24;

/// Farthest a candidate may be from a walker (or its predicted place) to continue it, m: a
/// brisk walk's 0.3 m in a 5 Hz revolution, plus the jump between one leg and two.
pub const WALKER_GATE_M: f32 = 0.6;

/// Frames a walker may go unseen before it is dropped.
pub const WALKER_LOST_FRAMES: u64 = 5;

/// One walker.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Walker {
    /// The person's id once it walks (drawn from the tracks' ids).
    pub id: Option<u32>,
    /// Position and velocity, map frame.
    pub motion: Motion,
    /// Frames it was seen.
    pub hits: u32,
    /// First frame it was seen.
    pub first_seen: u64,
    /// Last frame it was seen.
    pub last_seen: u64,
}

impl Walker {
    /// Share of the frames since it was first seen in which it was seen (0–1).
    pub fn score(&self) -> f32 {
        let span = self.last_seen.saturating_sub(self.first_seen) + 1;
        (self.hits as f32 / span as f32).min(1.0)
    }
}

/// The walker table.
#[derive(Debug, Clone, Default)]
pub struct Walkers {
    list: Vec<Walker, MAX_WALKERS>,
    /// Where leg-sized things stand still ([`Tracks::update_legs`] leaves them out).
    still: StillLegs,
}

impl Walkers {
    /// An empty table.
    pub const fn new() -> Self {
        Walkers {
            list: Vec::new(),
            still: StillLegs::new(),
        }
    }

    /// Every walker, listed or not.
    pub fn all(&self) -> &[Walker] {
        &self.list
    }

    /// One frame's person candidates (map frame) at `stamp_s`; a walker found to walk takes
    /// its id from `next_id`.
    pub fn update(
        &mut self,
        frame: u64,
        stamp_s: f64,
        persons: &[Person],
        next_id: &mut u32,
        cfg: &MotionConfig,
    ) {
        let mut matched = [false; MAX_WALKERS];
        let mut used = [false; crate::legs::MAX_PERSONS];
        let persons = &persons[..persons.len().min(used.len())];
        for (k, p) in persons.iter().enumerate() {
            used[k] = !(p.centre.x.is_finite() && p.centre.y.is_finite());
        }
        let mut ahead = [Point2::new(0.0, 0.0); MAX_WALKERS];
        for (a, w) in ahead.iter_mut().zip(self.list.iter()) {
            *a = w.motion.predict(stamp_s, cfg);
        }
        let taken = super::association::greedy(
            &mut matched,
            &mut used,
            self.list.len(),
            persons.len(),
            |i, k| {
                let (w, p) = (&self.list[i], &persons[k]);
                let d = w
                    .motion
                    .pos
                    .distance(p.centre)
                    .min(ahead[i].distance(p.centre));
                (d <= WALKER_GATE_M).then_some(d)
            },
        );
        for (i, k) in taken
            .into_iter()
            .map(|(i, k)| (usize::from(i), usize::from(k)))
        {
            let w = &mut self.list[i];
            w.motion.observe(persons[k].centre, stamp_s, cfg, true);
            w.hits = w.hits.saturating_add(1);
            w.last_seen = frame;
            if w.motion.moving && w.id.is_none() {
                w.id = Some(*next_id);
                *next_id = next_id.wrapping_add(1);
            }
        }
        self.list
            .retain(|w| frame.saturating_sub(w.last_seen) <= WALKER_LOST_FRAMES);
        for (k, p) in persons.iter().enumerate() {
            if used[k] {
                continue;
            }
            if self.list.is_full() {
                // The one seen longest ago goes (a person in view is seen every frame).
                if let Some(stale) = (0..self.list.len())
                    .min_by_key(|&i| (self.list[i].last_seen, self.list[i].hits))
                {
                    self.list.swap_remove(stale);
                }
            }
            let _ = self.list.push(Walker {
                id: None,
                motion: Motion::new(p.centre, stamp_s),
                hits: 1,
                first_seen: frame,
                last_seen: frame,
            });
        }
    }

    /// The people: walkers that walk, with their ids, seen in one of the last `recent` frames
    /// up to `frame`.
    pub fn people(&self, frame: u64, recent: u64) -> impl Iterator<Item = (u32, &Walker)> + '_ {
        self.list
            .iter()
            .filter(move |w| frame.saturating_sub(w.last_seen) < recent)
            .filter_map(|w| Some((w.id?, w)))
    }
}

/// A furniture track that walked and a listed walker this close are one person, m.
pub const SAME_PERSON_M: f32 = 0.5;

impl Tracks {
    /// One frame's person candidates from the leg detector (map frame, `stamp_s` as for
    /// [`Tracks::update`]).
    pub fn update_walkers(
        &mut self,
        frame: u64,
        stamp_s: f64,
        persons: &[Person],
        cfg: &TrackConfig,
    ) {
        self.walkers
            .update(frame, stamp_s, persons, &mut self.next_id, &cfg.motion);
    }

    /// One frame's leg candidates (map frame; [`crate::legs::legs_in_map`]): those standing
    /// where leg-sized things stand still are left out ([`StillLegs`]; `legs` keeps the
    /// rest), the rest paired into person candidates ([`crate::legs::pair`]) and tracked
    /// ([`Tracks::update_walkers`]).
    pub fn update_legs(
        &mut self,
        frame: u64,
        stamp_s: f64,
        legs: &mut Vec<Point2, MAX_LEGS>,
        leg_cfg: &LegConfig,
        cfg: &TrackConfig,
    ) {
        self.walkers.still.filter(frame, legs);
        let persons = crate::legs::pair(legs, leg_cfg);
        self.update_walkers(frame, stamp_s, &persons, cfg);
    }

    /// The walker table.
    pub fn walkers(&self) -> &Walkers {
        &self.walkers
    }

    /// Whether a walker listed at `frame` is within [`SAME_PERSON_M`] of `p` (a furniture
    /// track that walked there is that person, listed once).
    pub fn walker_near(&self, frame: u64, p: Point2) -> bool {
        self.walkers
            .people(frame, PEOPLE_FRAMES)
            .any(|(_, w)| w.motion.pos.distance(p) <= SAME_PERSON_M)
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::fusion::{Evidence, FrameObject};
    use crate::sight::BINS;
    use crate::tracks::Looked;
    use crate::{class::ObjectClass, geometry::Pose2};

    fn person(x: f32, y: f32) -> Person {
        Person {
            centre: Point2::new(x, y),
            legs: 2,
        }
    }

    #[test]
    fn a_walk_is_listed_with_its_velocity_and_a_fresh_id() {
        let cfg = TrackConfig::default();
        let mut t = Tracks::new();
        // A chair first, so ids are seen to be shared.
        let chair = FrameObject {
            class: ObjectClass::Chair,
            centre: Point2::new(3.0, 3.0),
            score: 0.9,
            evidence: Evidence::AB,
            bbox: None,
            width_m: 0.4,
        };
        t.update(
            0,
            0.0,
            &[chair],
            &Pose2::IDENTITY,
            &[0.0; BINS],
            Looked::BOTH,
            &cfg,
        );
        let mut listed = None;
        for f in 0..30u64 {
            let s = f as f64 * 0.2;
            // 1 m/s along x, the legs' midpoint jittering ±0.05 m.
            let jitter = if f % 2 == 0 { 0.05 } else { -0.05 };
            t.update_walkers(f, s, &[person(-1.0 + s as f32, 1.0 + jitter)], &cfg);
            let people: heapless::Vec<(u32, &Walker), 4> =
                t.walkers().people(f, PEOPLE_FRAMES).collect();
            assert!(people.len() <= 1);
            assert_eq!(t.people(f, &cfg).count(), 0);
            if let Some(&(id, p)) = people.first() {
                listed.get_or_insert((f, id));
                assert_eq!(id, listed.unwrap().1, "the id stays");
                let v = p.motion.vel;
                assert!((v.x - 1.0).abs() < 0.3 && v.y.abs() < 0.3, "{p:?}");
            }
        }
        let (f, id) = listed.expect("the walk is listed");
        assert!(f <= 14, "listed after {f} frames");
        assert_ne!(id, t.all()[0].id, "its own id");
    }

    #[test]
    fn a_person_both_tables_follow_is_listed_once() {
        let cfg = TrackConfig::default();
        let (mut both, mut tracks_only) = (Tracks::new(), Tracks::new());
        let (mut from_walkers, mut from_tracks, mut alone) = (0, 0, 0);
        for f in 0..30u64 {
            let s = f as f64 * 0.2;
            let at = Point2::new(-1.0 + s as f32, 1.0);
            // The legs taken for a chair by both methods, and found by the leg detector.
            let legs = FrameObject {
                class: ObjectClass::Chair,
                centre: at,
                score: 0.9,
                evidence: Evidence::AB,
                bbox: None,
                width_m: 0.3,
            };
            for t in [&mut both, &mut tracks_only] {
                t.update(
                    f,
                    s,
                    &[legs],
                    &Pose2::IDENTITY,
                    &[0.0; BINS],
                    Looked::BOTH,
                    &cfg,
                );
            }
            both.update_walkers(f, s, &[person(at.x, at.y)], &cfg);
            let w = both.walkers().people(f, PEOPLE_FRAMES).count();
            let t = both.people(f, &cfg).count();
            assert!(w + t <= 1, "frame {f}: listed twice");
            from_walkers += w;
            from_tracks += t;
            alone += tracks_only.people(f, &cfg).count();
        }
        assert!(alone > 0, "the furniture track walks on its own");
        assert!(from_walkers > 0);
        assert!(from_tracks < alone, "a walker there takes its place");
    }

    #[test]
    fn things_that_stand_are_never_listed() {
        let cfg = TrackConfig::default();
        let mut t = Tracks::new();
        for f in 0..150u64 {
            let j = [0.0, 0.04, -0.03, 0.02][f as usize % 4];
            // A bin with jitter; a pair of blobs 0.45 m apart seen one at a time; a person
            // standing still.
            let flicker = if f % 3 == 0 { 0.0 } else { 0.45 };
            let seen = [
                person(1.0 + j, 0.0),
                person(-2.0 + flicker, 1.0),
                person(0.0, -1.5 - j),
            ];
            t.update_walkers(f, f as f64 * 0.2, &seen, &cfg);
            assert_eq!(t.walkers().people(f, PEOPLE_FRAMES).count(), 0, "frame {f}");
            assert_eq!(t.people(f, &cfg).count(), 0, "frame {f}");
        }
        assert_eq!(t.walkers().all().len(), 3);
    }

    #[test]
    fn a_walker_out_of_sight_is_dropped_and_the_table_never_overflows() {
        let cfg = TrackConfig::default();
        let mut w = Walkers::new();
        let mut id = 0;
        let many: heapless::Vec<Person, 16> = (0..16).map(|k| person(k as f32, 0.0)).collect();
        for f in 0..3u64 {
            w.update(f, f as f64 * 0.2, &many, &mut id, &cfg.motion);
        }
        assert_eq!(w.all().len(), 16);
        // Sixteen others elsewhere: the table keeps its 24 at most.
        let others: heapless::Vec<Person, 16> = (0..16).map(|k| person(k as f32, 5.0)).collect();
        w.update(3, 0.6, &others, &mut id, &cfg.motion);
        assert_eq!(w.all().len(), MAX_WALKERS);
        for f in 4..4 + WALKER_LOST_FRAMES + 2 {
            w.update(f, f as f64 * 0.2, &[], &mut id, &cfg.motion);
        }
        assert!(w.all().is_empty());
        // Non-finite candidates are refused.
        w.update(20, 4.0, &[person(f32::NAN, 0.0)], &mut id, &cfg.motion);
        assert!(w.all().is_empty());
    }
}
