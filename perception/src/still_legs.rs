//! Places where leg-sized things stand: the legs of chairs and tables, bins, thin posts, the
//! two legs of a coat stand. A background model for the leg detector ([`crate::legs`]), as
//! people trackers keep one: a leg candidate at a place where leg candidates have been seen in
//! most recent revolutions is a still thing, not a leg of someone walking, and is left out
//! before legs are paired into people. Without it a walker track can hop from one chair leg
//! to the next as the view turns, and that reads as a walk. `no_std`, fixed capacity.
//!
//! Each place is a [`Spot`], fixed where first seen, with a score that gains one for each
//! revolution with a leg candidate within [`SPOT_M`] and decays by [`DECAY`] every revolution:
//! something seen in a share `p` of the revolutions settles at `p / (1 − DECAY)`. A spot is
//! still at [`STILL_SCORE`]: seen in five revolutions running (a second at 5 Hz), or in 40 % of
//! them for longer. A walking person's leg candidates move on from a spot within two or three
//! revolutions, a planted foot's within four; a person who stands a second makes the spot
//! still and is left out while standing (a standing person is never listed anyway; the walker
//! table, [`crate::tracks::Walkers`], keeps its track through five unseen frames).
//!
//! Set on the tuning seed 4242's sim and varied worlds (people walking, the true pose, leg
//! candidates within 0.15 m of a wall dropped; `docs/world.md`).

use heapless::Vec;

use crate::geometry::Point2;

/// Places remembered at most; when full, the lowest-scoring spot gives way.
pub const MAX_SPOTS: usize = 64;

/// A leg candidate this close to a spot is seen at that spot, m (a thin leg's position
/// wanders by a few centimetres with the view and the range noise).
pub const SPOT_M: f32 = 0.15;

/// Share of a spot's score kept from one revolution to the next.
pub const DECAY: f32 = 0.9;

/// Score at which a spot holds a still thing.
pub const STILL_SCORE: f32 = 4.0;

/// One remembered place.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Spot {
    /// Where, map frame (fixed where first seen).
    pub at: Point2,
    /// Decayed count of the revolutions it was seen in, as of [`StillLegs`]' last revolution.
    pub score: f32,
}

/// The still places.
#[derive(Debug, Clone, Default)]
pub struct StillLegs {
    spots: Vec<Spot, MAX_SPOTS>,
    /// The revolution every spot's score was last brought up to date to.
    frame: u64,
}

impl StillLegs {
    /// No place known.
    pub const fn new() -> Self {
        StillLegs {
            spots: Vec::new(),
            frame: 0,
        }
    }

    /// Every spot.
    pub fn spots(&self) -> &[Spot] {
        &self.spots
    }

    /// Takes revolution `frame`'s leg candidates (map frame) into the spots, then drops from
    /// `legs` those standing at a still spot. Non-finite candidates are dropped too.
    pub fn filter<const N: usize>(&mut self, frame: u64, legs: &mut Vec<Point2, N>) {
        legs.retain(|p| p.x.is_finite() && p.y.is_finite());
        // Bring the scores up to date; a spot seen this revolution gains one, once.
        let gap = frame.saturating_sub(self.frame).min(64) as f32;
        let kept = libm::powf(DECAY, gap);
        for s in self.spots.iter_mut() {
            s.score *= kept;
        }
        self.frame = frame;
        let mut seen = [false; MAX_SPOTS];
        for p in legs.iter() {
            let near = (0..self.spots.len())
                .filter(|&i| self.spots[i].at.distance(*p) <= SPOT_M)
                .min_by(|&a, &b| {
                    self.spots[a]
                        .at
                        .distance(*p)
                        .total_cmp(&self.spots[b].at.distance(*p))
                });
            match near {
                Some(i) => seen[i] = true,
                None => {
                    let spot = Spot { at: *p, score: 0.0 };
                    if self.spots.is_full() {
                        // The weakest gives way (not one seen this revolution).
                        if let Some(w) = (0..self.spots.len())
                            .filter(|&i| !seen[i])
                            .min_by(|&a, &b| self.spots[a].score.total_cmp(&self.spots[b].score))
                        {
                            self.spots[w] = spot;
                            seen[w] = true;
                        }
                    } else if self.spots.push(spot).is_ok() {
                        seen[self.spots.len() - 1] = true;
                    }
                }
            }
        }
        for (s, _) in self.spots.iter_mut().zip(seen).filter(|(_, seen)| *seen) {
            s.score += 1.0;
        }
        // Forget what faded.
        self.spots.retain(|s| s.score >= 0.05);
        let spots = &self.spots;
        legs.retain(|p| {
            !spots
                .iter()
                .any(|s| s.score >= STILL_SCORE && s.at.distance(*p) <= SPOT_M)
        });
    }
}

#[cfg(test)]
mod test {
    use super::*;

    fn legs(pts: &[(f32, f32)]) -> Vec<Point2, 32> {
        pts.iter().map(|&(x, y)| Point2::new(x, y)).collect()
    }

    #[test]
    fn a_chair_leg_seen_most_revolutions_becomes_still_a_walker_never_does() {
        let mut s = StillLegs::new();
        let mut kept_chair = 0;
        let mut kept_walker = 0;
        for f in 0..100u64 {
            // A chair's leg seen in two revolutions of three, jittering 3 cm; a person
            // walking at 0.4 m/s (0.08 m a revolution at 5 Hz) along x.
            let j = [0.0, 0.03, -0.02][f as usize % 3];
            let walker = (-4.0 + 0.08 * f as f32, 1.0);
            let mut l = if f % 3 == 2 {
                legs(&[walker])
            } else {
                legs(&[(1.0 + j, -1.0), walker])
            };
            s.filter(f, &mut l);
            kept_chair += l.iter().filter(|p| p.y < 0.0).count();
            kept_walker += l.iter().filter(|p| p.y > 0.0).count();
        }
        assert!(
            kept_chair <= 5,
            "the chair leg is still after a few revolutions: {kept_chair}"
        );
        assert_eq!(kept_walker, 100, "a walk never stands still");
    }

    #[test]
    fn a_person_who_stands_is_left_out_and_comes_back_when_walking_on() {
        let mut s = StillLegs::new();
        let mut kept = [0usize; 3];
        for f in 0..40u64 {
            // Walks 10 revolutions at 1 m/s, stands 20, walks on.
            let x = match f {
                0..10 => 0.2 * f as f32,
                10..30 => 2.0,
                _ => 2.0 + 0.2 * (f - 29) as f32,
            };
            let mut l = legs(&[(x, 0.0)]);
            s.filter(f, &mut l);
            kept[if f < 10 {
                0
            } else if f < 30 {
                1
            } else {
                2
            }] += l.len();
        }
        assert_eq!(kept[0], 10);
        assert!(kept[1] <= 5, "standing: {}", kept[1]);
        assert_eq!(kept[2], 10);
    }

    #[test]
    fn the_table_never_overflows_and_refuses_nan() {
        let mut s = StillLegs::new();
        for f in 0..10u64 {
            let mut l: Vec<Point2, 32> = (0..32)
                .map(|k| Point2::new(k as f32 + 10.0 * f as f32, 0.0))
                .collect();
            s.filter(f, &mut l);
            assert!(s.spots().len() <= MAX_SPOTS);
        }
        let mut l = legs(&[(f32::NAN, 0.0), (0.0, f32::INFINITY)]);
        s.filter(10, &mut l);
        assert!(l.is_empty());
    }
}
