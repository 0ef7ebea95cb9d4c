//! People's legs in one revolution: small free-standing blobs of returns, paired into a
//! person. The detector the `people` list is built on (a walking person's legs are seldom
//! furniture to either method, so furniture tracks alone found few of them). It says only
//! "something leg-sized stands here"; bins, thin pillars and table legs pass it too, and only
//! a walk ([`crate::tracks::Walkers`]) makes a person of it. `no_std`, allocation-free.
//!
//! A **leg** is a run of at least [`LegConfig::min_returns`] consecutive returns, each within
//! [`LegConfig::max_step_m`] of the last (a depth jump or a bin without a return ends it),
//! whose width — the chord from first to last return plus one bin's spacing at that range —
//! is that of a human leg, [`LegConfig::min_width_m`] to [`LegConfig::max_width_m`], within
//! [`LegConfig::max_range_m`]. A run that is a piece of something longer (a dark wall broken
//! by dropouts) is not a leg: on one side or the other it goes on, return after return across
//! gaps of up to [`LegConfig::max_dropout_bins`] missing bins, for [`LegConfig::max_chain_m`]
//! or more. Background seen through a gap (a wall between a person's legs) can pass as a
//! leg; it stands still. A **person** is two legs within
//! [`LegConfig::max_pair_m`] (their midpoint), or one leg alone (one hides the other).

use heapless::Vec;

use crate::geometry::{Point2, Pose2};
use crate::sight::BINS;

/// Leg candidates looked at per revolution at most (the first in bin order are kept).
pub const MAX_LEGS: usize = 32;

/// Person candidates reported per revolution at most.
pub const MAX_PERSONS: usize = 16;

/// Tuning of the leg detector: physical sizes of a human leg at a LiDAR's height (shin or
/// calf, trousers included), not fitted to any scene.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LegConfig {
    /// Returns a leg needs at least (one return is any thin thing).
    pub min_returns: usize,
    /// Largest step between consecutive returns of one leg, m.
    pub max_step_m: f32,
    /// Narrowest leg, m (a chair's or table's leg is 0.02–0.04 m).
    pub min_width_m: f32,
    /// Widest leg, m (two legs side by side seen as one run stay under it too).
    pub max_width_m: f32,
    /// Farthest leg looked for, m: at 1° a leg beyond gives two or three returns, and a
    /// range noise of a few per cent of range (the LDS-01's ±5 % band) breaks a wall's
    /// returns into leg-sized runs.
    pub max_range_m: f32,
    /// Two legs of one person are at most this far apart, m (a stride at shin height).
    pub max_pair_m: f32,
    /// Missing bins across which a run is looked at as continued by the next return.
    pub max_dropout_bins: usize,
    /// A run continued (across dropouts) this far on either side is a piece of something
    /// longer, m: more than a person's stance and a leg.
    pub max_chain_m: f32,
}

impl Default for LegConfig {
    fn default() -> Self {
        LegConfig {
            min_returns: 2,
            max_step_m: 0.08,
            min_width_m: 0.06,
            max_width_m: 0.25,
            max_range_m: 2.5,
            max_pair_m: 0.5,
            max_dropout_bins: 4,
            max_chain_m: 0.6,
        }
    }
}

/// One person candidate, in the frame of the pose it was detected with.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Person {
    /// Between the legs (or at the one leg seen), m.
    pub centre: Point2,
    /// Legs seen: 1 or 2.
    pub legs: u8,
}

/// Person candidates of one revolution.
pub type Persons = Vec<Person, MAX_PERSONS>;

/// The range at bin `d` (any integer, wrapped), or `None` without a return.
fn at(ranges: &[f32; BINS], d: i32) -> Option<f32> {
    let r = ranges[d.rem_euclid(BINS as i32) as usize];
    (r > 0.0 && r.is_finite()).then_some(r)
}

/// The return at bin `d` in the LiDAR's frame.
fn point(r: f32, d: i32) -> Point2 {
    Point2::from_polar(r, (d as f32).to_radians())
}

/// Whether bins `a` and `b` (both with returns `ra`, `rb`) are steps of one surface.
fn joined(ra: f32, a: i32, rb: f32, b: i32, cfg: &LegConfig) -> bool {
    point(ra, a).distance(point(rb, b)) <= cfg.max_step_m
}

/// Bins followed at most from a run's edge by [`chain`].
const CHAIN_BINS: i32 = 40;

/// How far from its edge (bin `edge`, range `r_edge`) a run goes on in direction `dir` (±1),
/// return after return, each within the span of the bins missing before it (twice the bins'
/// spacing, and at least two steps, plus twice the range noise), across at most [`LegConfig::max_dropout_bins`] missing
/// bins at a time, m.
fn chain(ranges: &[f32; BINS], edge: i32, r_edge: f32, dir: i32, cfg: &LegConfig) -> f32 {
    let start = point(r_edge, edge);
    let (mut last, mut last_r, mut far, mut missing) = (start, r_edge, 0.0f32, 0usize);
    for k in 1..=CHAIN_BINS {
        let b = edge + dir * k;
        match at(ranges, b) {
            None => {
                missing += 1;
                if missing > cfg.max_dropout_bins {
                    break;
                }
            }
            Some(r) => {
                let p = point(r, b);
                let reach =
                    ((missing + 1) as f32 * last_r * 2f32.to_radians()).max(2.0 * cfg.max_step_m);
                if p.distance(last) > reach {
                    break;
                }
                far = far.max(p.distance(start));
                (last, last_r, missing) = (p, r, 0);
            }
        }
    }
    far
}

/// The leg candidates of a revolution (`ranges`, 1° bins), in the LiDAR's frame: each a run's
/// centre pushed half its width back along its bearing (the leg's axis, not its skin).
pub fn legs(ranges: &[f32; BINS], cfg: &LegConfig) -> Vec<Point2, MAX_LEGS> {
    let mut out: Vec<Point2, MAX_LEGS> = Vec::new();
    let n = BINS as i32;
    // Start where a run breaks, so no run is cut at bin 0.
    let Some(start) = (0..n).find(|&d| match (at(ranges, d - 1), at(ranges, d)) {
        (_, None) => true,
        (Some(p), Some(r)) => !joined(p, d - 1, r, d, cfg),
        (None, Some(_)) => true,
    }) else {
        return out; // one unbroken ring: a wall all round, no legs
    };
    let mut d = start;
    while d < start + n {
        let Some(r0) = at(ranges, d) else {
            d += 1;
            continue;
        };
        // The run from d.
        let (mut end, mut r_end, mut sum, mut count) = (d, r0, point(r0, d), 1usize);
        while end + 1 < start + n {
            match at(ranges, end + 1) {
                Some(r) if joined(r_end, end, r, end + 1, cfg) => {
                    end += 1;
                    r_end = r;
                    sum = sum + point(r, end);
                    count += 1;
                }
                _ => break,
            }
        }
        let next = end + 1;
        if count >= cfg.min_returns {
            let mean_r = sum.norm() / count as f32;
            let spacing = mean_r * 1f32.to_radians();
            let width = point(r0, d).distance(point(r_end, end)) + spacing;
            // A run that goes on past a few missing bins, return after return, for longer
            // than any person's stance is a piece of something longer: a dark wall's dashes
            // between dropouts.
            let piece = chain(ranges, d, r0, -1, cfg) >= cfg.max_chain_m
                || chain(ranges, end, r_end, 1, cfg) >= cfg.max_chain_m;
            if !piece
                && mean_r <= cfg.max_range_m
                && (cfg.min_width_m..=cfg.max_width_m).contains(&width)
            {
                let c = Point2::new(sum.x / count as f32, sum.y / count as f32);
                let back = 1.0 + 0.5 * width / mean_r.max(0.05);
                if out.push(Point2::new(c.x * back, c.y * back)).is_err() {
                    break;
                }
            }
        }
        d = next;
    }
    out
}

/// The leg candidates of a revolution ([`legs`]) placed in the map frame by `lidar`.
pub fn legs_in_map(ranges: &[f32; BINS], lidar: &Pose2, cfg: &LegConfig) -> Vec<Point2, MAX_LEGS> {
    let mut out = legs(ranges, cfg);
    for p in out.iter_mut() {
        *p = lidar.transform(*p);
    }
    out
}

/// The person candidates of a revolution seen from `lidar` (map frame): legs paired nearest
/// first within [`LegConfig::max_pair_m`], a leg left over is a person alone.
pub fn persons(ranges: &[f32; BINS], lidar: &Pose2, cfg: &LegConfig) -> Persons {
    pair(&legs_in_map(ranges, lidar, cfg), cfg)
}

/// Person candidates from leg candidates (any one frame): legs paired nearest first within
/// [`LegConfig::max_pair_m`] (their midpoint), a leg left over is a person alone.
pub fn pair(legs: &[Point2], cfg: &LegConfig) -> Persons {
    let legs = &legs[..legs.len().min(MAX_LEGS)];
    let mut paired = [false; MAX_LEGS];
    let mut out = Persons::new();
    loop {
        let mut best: Option<(f32, usize, usize)> = None;
        for i in 0..legs.len() {
            for j in i + 1..legs.len() {
                if paired[i] || paired[j] {
                    continue;
                }
                let d = legs[i].distance(legs[j]);
                if d <= cfg.max_pair_m && best.is_none_or(|b| d < b.0) {
                    best = Some((d, i, j));
                }
            }
        }
        let Some((_, i, j)) = best else { break };
        paired[i] = true;
        paired[j] = true;
        let mid = Point2::new((legs[i].x + legs[j].x) / 2.0, (legs[i].y + legs[j].y) / 2.0);
        if out
            .push(Person {
                centre: mid,
                legs: 2,
            })
            .is_err()
        {
            return out;
        }
    }
    for (leg, _) in legs.iter().zip(paired).filter(|(_, p)| !p) {
        if out
            .push(Person {
                centre: *leg,
                legs: 1,
            })
            .is_err()
        {
            break;
        }
    }
    out
}

#[cfg(test)]
mod test {
    use super::*;

    /// A revolution from the origin, bin d at d°, of circles (centre, radius) and segments;
    /// every `drop`-th bin without a return (0: none dropped).
    fn scan(circles: &[(Point2, f32)], segments: &[(Point2, Point2)], drop: usize) -> [f32; BINS] {
        let mut out = [0.0; BINS];
        for (d, r) in out.iter_mut().enumerate() {
            if drop > 0 && d % drop == 0 {
                continue;
            }
            let u = Point2::from_polar(1.0, (d as f32).to_radians());
            let mut best = f32::INFINITY;
            for &(c, rad) in circles {
                let b = u.dot(c);
                let disc = b * b - (c.dot(c) - rad * rad);
                if disc >= 0.0 && b - libm::sqrtf(disc) > 0.0 {
                    best = best.min(b - libm::sqrtf(disc));
                }
            }
            for &(a, e) in segments {
                let v = e - a;
                let den = u.cross(v);
                if den.abs() > 1e-9 {
                    let t = a.cross(v) / den;
                    let s = a.cross(u) / den;
                    if t > 0.0 && (0.0..=1.0).contains(&s) {
                        best = best.min(t);
                    }
                }
            }
            if best < 6.0 {
                *r = best;
            }
        }
        out
    }

    fn room() -> [(Point2, Point2); 4] {
        // Within the 2.5 m the legs are looked for on every side.
        let (x0, x1, y0, y1) = (-1.6, 2.1, -1.8, 1.5);
        [
            (Point2::new(x0, y0), Point2::new(x1, y0)),
            (Point2::new(x1, y0), Point2::new(x1, y1)),
            (Point2::new(x1, y1), Point2::new(x0, y1)),
            (Point2::new(x0, y1), Point2::new(x0, y0)),
        ]
    }

    #[test]
    fn two_legs_make_one_person_between_them() {
        let cfg = LegConfig::default();
        for (dist, bearing) in [(0.8f32, 0.3f32), (1.2, -1.2), (1.3, 2.5)] {
            let c = Point2::from_polar(dist, bearing);
            let side = Point2::from_polar(0.12, bearing + core::f32::consts::FRAC_PI_2);
            let legs = [(c + side, 0.06), (c - side, 0.06)];
            let p = persons(&scan(&legs, &room(), 0), &Pose2::IDENTITY, &cfg);
            // The person; a piece of the wall seen between the legs may come as a lone "leg"
            // (it stands still: the walkers never list it), nothing else.
            let near: heapless::Vec<&Person, 4> =
                p.iter().filter(|q| q.centre.distance(c) < 0.3).collect();
            assert_eq!(near.len(), 1, "{dist} m: {p:?}");
            assert_eq!(near[0].legs, 2);
            assert!(near[0].centre.distance(c) < 0.06, "{dist} m: {:?}", near[0]);
            assert!(p.len() <= 2, "{dist} m: {p:?}");
            assert!(
                p.iter()
                    .all(|q| q.legs == 2 || q.centre.norm() > dist + 0.3)
            );
        }
    }

    #[test]
    fn a_person_seen_from_a_pose_is_placed_in_the_map() {
        let lidar = Pose2::new(1.0, 2.0, 1.0);
        let legs = [
            (Point2::new(1.5, 0.1), 0.06),
            (Point2::new(1.5, -0.1), 0.06),
        ];
        let p = persons(&scan(&legs, &[], 0), &lidar, &LegConfig::default());
        assert_eq!(p.len(), 1);
        assert!(p[0].centre.distance(lidar.transform(Point2::new(1.5, 0.0))) < 0.06);
    }

    #[test]
    fn walls_boxes_and_chair_legs_are_no_legs() {
        let cfg = LegConfig::default();
        // A room; the same with a dark wall that drops every third bin.
        assert!(legs(&scan(&[], &room(), 0), &cfg).is_empty());
        let l = legs(&scan(&[], &room(), 3), &cfg);
        assert!(l.is_empty(), "{l:?}");
        // A darker one: runs of three returns between gaps of one to four bins.
        for gap in 1..=4usize {
            let mut dashes = scan(&[], &room(), 0);
            for (d, r) in dashes.iter_mut().enumerate() {
                if d % (3 + gap) >= 3 {
                    *r = 0.0;
                }
            }
            let l = legs(&dashes, &cfg);
            assert!(l.is_empty(), "gaps of {gap}: {l:?}");
        }
        // A 0.4 m box face-on at 1.5 m.
        let face = [(Point2::new(1.5, -0.2), Point2::new(1.5, 0.2))];
        let mut both = room().to_vec();
        both.extend_from_slice(&face);
        assert!(legs(&scan(&[], &both, 0), &cfg).is_empty());
        // A chair's four 0.015 m legs, 0.4 m apart.
        for at in [0.6f32, 1.4] {
            let chair: [(Point2, f32); 4] = [(0.0, 0.0), (0.4, 0.0), (0.0, 0.4), (0.4, 0.4)]
                .map(|(x, y)| (Point2::new(at + x, y - 0.2), 0.015));
            // (No room behind: a wall seen between them comes out in pieces, which stand still.)
            assert!(legs(&scan(&chair, &[], 0), &cfg).is_empty(), "{at} m");
        }
    }

    #[test]
    fn nothing_breaks_on_an_empty_or_full_ring() {
        let cfg = LegConfig::default();
        assert!(persons(&[0.0; BINS], &Pose2::IDENTITY, &cfg).is_empty());
        assert!(persons(&[2.0; BINS], &Pose2::IDENTITY, &cfg).is_empty());
        assert!(persons(&[f32::NAN; BINS], &Pose2::IDENTITY, &cfg).is_empty());
        // Every other bin a return at 1 m: 180 one-return runs, none a leg.
        let mut comb = [0.0; BINS];
        comb.iter_mut().step_by(2).for_each(|r| *r = 1.0);
        assert!(persons(&comb, &Pose2::IDENTITY, &cfg).is_empty());
    }
}
