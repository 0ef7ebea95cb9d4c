//! Door frames: a gap between two parallel wall segments, as the paper defines it.
//!
//! A pair of segments is a door frame when
//! - their directions differ by less than `max_angle_deg` (10°),
//! - they lie on one line: each facing end is within `max_offset_m` (0.2 m) of the other
//!   segment's line (the study compares parallel segments only; without this, a corridor's
//!   opposite walls 1 m apart would pass),
//! - they do not overlap along that line, and the facing ends leave a gap of
//!   `min_gap_m`–`max_gap_m` (0.75–1.4 m; the paper's 0.9 m lower bound, its code's 1.3–2.0,
//!   would miss standard interior doors, whose clear opening is 0.76–0.9 m: DIN 18101's
//!   0.885 m leaf leaves ~0.8 m, the ADA asks for at least 0.815 m),
//! - the gap is open: at most `max_occluders` cloud points lie in the triangle between the
//!   sensor and the gap (more than `occluder_margin_m` in front of it). A gap that something in
//!   front of the wall shadows is an occlusion, not a door.
//!
//! The door is the midpoint of the facing ends; its width the gap. Its score falls linearly
//! from 1 with the angle and the offset (each halves it at its limit). Detections whose centres
//! are closer than `merge_m` are one door; the higher score stays.

use heapless::Vec;

use crate::geometry::Point2;
use crate::walls::Segment;

/// Door frames kept per frame at most.
pub const MAX_DOORS: usize = 16;

/// Door settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DoorConfig {
    /// Largest angle between the two segments, degrees.
    pub max_angle_deg: f32,
    /// Narrowest gap, metres.
    pub min_gap_m: f32,
    /// Widest gap, metres.
    pub max_gap_m: f32,
    /// Largest distance of a facing end from the other segment's line, metres.
    pub max_offset_m: f32,
    /// Points in front of the gap that make it an occlusion.
    pub max_occluders: u16,
    /// Points closer to the gap line than this are the frame itself, not occluders, metres.
    pub occluder_margin_m: f32,
    /// Detections closer than this are one door, metres.
    pub merge_m: f32,
}

impl Default for DoorConfig {
    fn default() -> Self {
        DoorConfig {
            max_angle_deg: 10.0,
            min_gap_m: 0.75,
            max_gap_m: 1.4,
            max_offset_m: 0.2,
            max_occluders: 3,
            occluder_margin_m: 0.15,
            merge_m: 0.5,
        }
    }
}

/// A door frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Door {
    /// Centre of the gap, map frame.
    pub centre: Point2,
    /// Gap width, metres.
    pub width: f32,
    /// Facing end of the first segment.
    pub a: Point2,
    /// Facing end of the second segment.
    pub b: Point2,
    /// Confidence in [0, 1].
    pub score: f32,
}

/// Door frames of a frame.
pub type Doors = Vec<Door, MAX_DOORS>;

fn cross(o: Point2, a: Point2, b: Point2) -> f32 {
    (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
}

fn in_triangle(p: Point2, a: Point2, b: Point2, c: Point2) -> bool {
    let (d1, d2, d3) = (cross(a, b, p), cross(b, c, p), cross(c, a, p));
    let neg = d1 < 0.0 || d2 < 0.0 || d3 < 0.0;
    let pos = d1 > 0.0 || d2 > 0.0 || d3 > 0.0;
    !(neg && pos)
}

/// The door candidate between two segments, if they form one (before the occlusion test).
pub fn pair(s: &Segment, t: &Segment, cfg: &DoorConfig) -> Option<Door> {
    let pi = core::f32::consts::PI;
    let da = libm::fmodf((s.angle() - t.angle()).abs(), pi);
    let da = da.min(pi - da);
    if da.to_degrees() >= cfg.max_angle_deg {
        return None;
    }
    // Along s's direction: both intervals, then the gap between them.
    let o = s.a;
    let l = s.length();
    if l < 1e-6 {
        return None;
    }
    let u = Point2::new((s.b.x - o.x) / l, (s.b.y - o.y) / l);
    let along = |p: Point2| (p.x - o.x) * u.x + (p.y - o.y) * u.y;
    let (s0, s1) = (0.0, l);
    let (ta, tb) = (along(t.a), along(t.b));
    let (t0, t1, t_lo, t_hi) = if ta <= tb {
        (ta, tb, t.a, t.b)
    } else {
        (tb, ta, t.b, t.a)
    };
    let (ea, eb) = if t0 >= s1 {
        (s.b, t_lo)
    } else if t1 <= s0 {
        (s.a, t_hi)
    } else {
        return None; // overlapping along the line
    };
    let offset = s.line_distance(eb).max(t.line_distance(ea));
    if offset > cfg.max_offset_m {
        return None;
    }
    let width = ea.distance(eb);
    if !(cfg.min_gap_m..=cfg.max_gap_m).contains(&width) {
        return None;
    }
    let score = (1.0 - 0.5 * da.to_degrees() / cfg.max_angle_deg - 0.5 * offset / cfg.max_offset_m)
        .clamp(0.0, 1.0);
    Some(Door {
        centre: Point2::new((ea.x + eb.x) / 2.0, (ea.y + eb.y) / 2.0),
        width,
        a: ea,
        b: eb,
        score,
    })
}

/// Points of `cloud` that shadow the gap from `sensor`.
pub fn occluders<'a>(
    door: &Door,
    sensor: Point2,
    cloud: impl IntoIterator<Item = &'a Point2>,
    margin: f32,
    stop_at: u16,
) -> u16 {
    let mut n = 0u16;
    for p in cloud {
        if in_triangle(*p, sensor, door.a, door.b) && p.distance_to_segment(door.a, door.b) > margin
        {
            n += 1;
            if n > stop_at {
                break;
            }
        }
    }
    n
}

/// Finds the door frames among `segments`, seen from `sensor`, with `cloud` for the occlusion
/// test. Returns how many candidates did not fit in `out`.
pub fn find<'a, I>(
    segments: &[Segment],
    sensor: Point2,
    cloud: impl Fn() -> I,
    cfg: &DoorConfig,
    out: &mut Doors,
) -> u32
where
    I: Iterator<Item = &'a Point2>,
{
    let mut dropped = 0;
    for (i, s) in segments.iter().enumerate() {
        for t in &segments[i + 1..] {
            let Some(d) = pair(s, t, cfg) else { continue };
            if occluders(
                &d,
                sensor,
                cloud(),
                cfg.occluder_margin_m,
                cfg.max_occluders,
            ) > cfg.max_occluders
            {
                continue;
            }
            match out
                .iter_mut()
                .find(|o| o.centre.distance(d.centre) < cfg.merge_m)
            {
                Some(o) => {
                    if d.score > o.score {
                        *o = d;
                    }
                }
                None => {
                    if out.push(d).is_err() {
                        dropped += 1;
                    }
                }
            }
        }
    }
    dropped
}

#[cfg(test)]
mod test {
    use super::*;

    use crate::walls::test_seg as seg;

    #[test]
    fn collinear_gap_is_a_door() {
        let segs = [seg(0.0, 2.0, 1.0, 2.0), seg(2.0, 2.0, 4.0, 2.0)];
        let mut out = Doors::new();
        let none: [Point2; 0] = [];
        find(
            &segs,
            Point2::new(1.5, 0.0),
            || none.iter(),
            &DoorConfig::default(),
            &mut out,
        );
        assert_eq!(out.len(), 1);
        let d = out[0];
        assert!(d.centre.distance(Point2::new(1.5, 2.0)) < 1e-5);
        assert!((d.width - 1.0).abs() < 1e-5 && (d.score - 1.0).abs() < 1e-5);
    }

    #[test]
    fn rejects_wrong_gaps_angles_offsets_and_occlusions() {
        let cfg = DoorConfig::default();
        let base = seg(0.0, 0.0, 1.0, 0.0);
        assert!(pair(&base, &seg(1.5, 0.0, 3.0, 0.0), &cfg).is_none()); // 0.5 m
        assert!(pair(&base, &seg(2.6, 0.0, 3.0, 0.0), &cfg).is_none()); // 1.6 m
        assert!(pair(&base, &seg(2.0, 0.0, 3.0, 0.5), &cfg).is_none()); // 26°
        assert!(pair(&base, &seg(2.0, 1.0, 3.0, 1.0), &cfg).is_none()); // parallel, offset 1 m
        assert!(pair(&base, &seg(0.5, 0.1, 3.0, 0.1), &cfg).is_none()); // overlapping
        // Reversed direction still pairs.
        assert!(pair(&base, &seg(3.0, 0.0, 2.1, 0.0), &cfg).is_some());
        // A box between the sensor and the gap.
        let segs = [base, seg(2.0, 0.0, 3.0, 0.0)];
        let blocker: std::vec::Vec<Point2> = (0..20)
            .map(|k| Point2::new(1.2 + k as f32 * 0.03, -1.0))
            .collect();
        let mut out = Doors::new();
        find(
            &segs,
            Point2::new(1.5, -2.0),
            || blocker.iter(),
            &cfg,
            &mut out,
        );
        assert!(out.is_empty());
        find(
            &segs,
            Point2::new(1.5, -0.5),
            || blocker.iter(),
            &cfg,
            &mut out,
        );
        assert_eq!(out.len(), 1);
    }
}
