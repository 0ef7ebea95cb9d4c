//! Doorways in the map's walls: two confirmed wall lines ([`crate::wall_map`]) on one line and
//! facing one room, with a door-wide gap between their facing ends that this revolution's rays
//! pass through (they return from beyond the line and none ends on it).
//!
//! The map holds walls gathered over many revolutions and viewpoints, so a doorway is found
//! where one scan shows only a short or broken piece of wall beside it: a door near a corner,
//! in a long wall thinned into dashes at a grazing angle, or in a wall the robot saw from the
//! other end of the room a minute ago. A gap that furniture in front of the wall shadows is
//! never seen through, and one with wall behind it is seen closed: neither is a door.
//!
//! Each doorway seen through is a door-frame observation for the world model (Method A's
//! evidence: it comes from the walls), unless a door frame of the frame's own is already there.

use heapless::Vec;

use crate::class::ObjectClass;
use crate::fusion::{Evidence, FrameObject, FrameObjects};
use crate::geometry::{Point2, Pose2};
use crate::sight::BINS;
use crate::wall_map::{MapWall, WallMap};

/// Map doorway settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MapDoorConfig {
    /// Narrowest gap, m (interior doors open 0.76–0.9 m clear; see [`crate::doors`]).
    pub min_gap_m: f32,
    /// Widest gap, m.
    pub max_gap_m: f32,
    /// Largest angle between the two lines, rad.
    pub max_angle_rad: f32,
    /// Largest distance of the second line's ends from the first's, m.
    pub max_offset_m: f32,
    /// Share of the gap next to each jamb the rays are not looked at in (a jamb's mixed
    /// pixels, the lines' ends a little short of the true corners).
    pub jamb_share: f32,
    /// A ray that returns this far beyond the doorway's line passed through it, m.
    pub beyond_m: f32,
    /// A ray that returns this close to the line (plus 2 % of its range) ended on it, m.
    pub on_line_m: f32,
    /// Rays through the gap before it is a doorway this revolution.
    pub min_through: u32,
    /// The LiDAR's useful range, m: gaps farther away are not looked at.
    pub max_range_m: f32,
    /// A door frame of the frame's own this close is the same door, m.
    pub same_door_m: f32,
    /// The observation's score: a gap in confirmed walls that rays pass through.
    pub score: f32,
}

impl Default for MapDoorConfig {
    fn default() -> Self {
        MapDoorConfig {
            min_gap_m: 0.75,
            max_gap_m: 1.4,
            max_angle_rad: 0.087,
            max_offset_m: 0.12,
            jamb_share: 0.15,
            beyond_m: 0.3,
            on_line_m: 0.1,
            min_through: 2,
            max_range_m: 3.5,
            same_door_m: 0.5,
            score: 0.8,
        }
    }
}

/// A door-wide gap between two confirmed lines: its jambs (the lines' facing ends, `a` on the
/// first line) and the first line's room normal.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Gap {
    /// The first line's facing end.
    pub a: Point2,
    /// The second line's facing end.
    pub b: Point2,
    /// Unit normal of the lines, on the room's side.
    pub room: Point2,
}

impl Gap {
    /// Its middle.
    pub fn centre(&self) -> Point2 {
        Point2::new(0.5 * (self.a.x + self.b.x), 0.5 * (self.a.y + self.b.y))
    }

    /// Its width, m.
    pub fn width(&self) -> f32 {
        self.a.distance(self.b)
    }
}

/// The gap between `w` and `v` when the two are one wall with a door-wide gap in it.
fn gap(w: &MapWall, v: &MapWall, cfg: &MapDoorConfig) -> Option<Gap> {
    if !(w.confirmed() && v.confirmed()) {
        return None;
    }
    let room = w.room_normal();
    if room.dot(v.room_normal()) < libm::cosf(cfg.max_angle_rad) {
        return None;
    }
    let (v0, v1) = v.ends();
    if libm::fabsf(w.in_front(v0)) > cfg.max_offset_m
        || libm::fabsf(w.in_front(v1)) > cfg.max_offset_m
    {
        return None;
    }
    let (lo, hi) = w.extent();
    let (u0, u1) = (w.along(v0), w.along(v1));
    let (a, b, width) = if u0.max(u1) < lo {
        // `v` lies before `w`'s start: its end nearer that start faces it.
        (w.at(lo), if u0 > u1 { v0 } else { v1 }, lo - u0.max(u1))
    } else if u0.min(u1) > hi {
        (w.at(hi), if u0 < u1 { v0 } else { v1 }, u0.min(u1) - hi)
    } else {
        return None; // they overlap along the line
    };
    if !(cfg.min_gap_m..=cfg.max_gap_m).contains(&width) {
        return None;
    }
    Some(Gap { a, b, room })
}

/// The door-wide gaps between the map's confirmed lines.
pub fn gaps<'a>(map: &'a WallMap, cfg: &'a MapDoorConfig) -> impl Iterator<Item = Gap> + 'a {
    let walls = map.walls();
    walls
        .iter()
        .enumerate()
        .flat_map(move |(i, w)| walls[i + 1..].iter().filter_map(move |v| gap(w, v, cfg)))
}

/// What this revolution (`ranges`, from `lidar`) showed of the gap's middle: rays that passed
/// through it, and rays that ended on its line.
pub fn look_through(
    g: &Gap,
    lidar: &Pose2,
    ranges: &[f32; BINS],
    cfg: &MapDoorConfig,
) -> (u32, u32) {
    let sensor = Point2::new(lidar.x, lidar.y);
    // Signed distance along the room normal from the sensor to the line: negative on the
    // room's side, which is the only side looked from.
    let to_line = (g.a - sensor).dot(g.room);
    if to_line >= -0.1 {
        return (0, 0);
    }
    let e = g.b - g.a;
    let t = cfg.jamb_share.clamp(0.0, 0.45);
    let p = Point2::new(g.a.x + t * e.x, g.a.y + t * e.y);
    let q = Point2::new(g.b.x - t * e.x, g.b.y - t * e.y);
    if p.distance(sensor) > cfg.max_range_m || q.distance(sensor) > cfg.max_range_m {
        return (0, 0);
    }
    let to = lidar.inverse();
    let bearing = |x: Point2| {
        let l = to.transform(x);
        libm::atan2f(l.y, l.x).to_degrees()
    };
    let (mut lo, mut hi) = (bearing(p), bearing(q));
    if lo > hi {
        core::mem::swap(&mut lo, &mut hi);
    }
    if hi - lo > 180.0 {
        // The gap straddles the bins' wrap: walk from `hi` round to `lo`.
        (lo, hi) = (hi, lo + 360.0);
    }
    let (mut through, mut closed) = (0, 0);
    for d in libm::ceilf(lo) as i32..=libm::floorf(hi) as i32 {
        let phi = lidar.theta + (d as f32).to_radians();
        let ray = Point2::new(libm::cosf(phi), libm::sinf(phi));
        let denom = ray.dot(g.room);
        if denom > -0.1 {
            continue; // grazing, or not towards the line
        }
        let s = to_line / denom;
        let range = ranges[d.rem_euclid(BINS as i32) as usize];
        if !(range > 0.0 && range.is_finite()) {
            continue; // no return: says nothing
        }
        if range > s + cfg.beyond_m {
            through += 1;
        } else if libm::fabsf(range - s) <= cfg.on_line_m + 0.02 * s {
            closed += 1;
        }
    }
    (through, closed)
}

/// Doorways seen through in one revolution, at most.
pub const MAX_DOORWAYS: usize = 8;

/// The centres of the doorways this revolution saw through.
pub type Doorways = Vec<Point2, MAX_DOORWAYS>;

/// Adds a door frame to `out` for each doorway in the map's walls this revolution sees
/// through, unless a door frame is already within [`MapDoorConfig::same_door_m`]; returns
/// the centres of all the doorways it saw through (for [`crate::tracks::Tracks::anchor_doors`]).
pub fn observe(
    map: &WallMap,
    lidar: &Pose2,
    ranges: &[f32; BINS],
    cfg: &MapDoorConfig,
    out: &mut FrameObjects,
) -> Doorways {
    let mut seen = Doorways::new();
    if !(lidar.x.is_finite() && lidar.y.is_finite() && lidar.theta.is_finite()) {
        return seen;
    }
    for g in gaps(map, cfg) {
        let (through, closed) = look_through(&g, lidar, ranges, cfg);
        if through < cfg.min_through || closed * 4 > through {
            continue;
        }
        let c = g.centre();
        let _ = seen.push(c);
        let known = out
            .iter()
            .any(|o| o.class == ObjectClass::DoorFrame && o.centre.distance(c) < cfg.same_door_m);
        if known || out.is_full() {
            continue;
        }
        let _ = out.push(FrameObject {
            class: ObjectClass::DoorFrame,
            centre: c,
            score: cfg.score,
            evidence: Evidence::A,
            bbox: None,
            width_m: g.width(),
        });
    }
    seen
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::walls::test_seg as seg;

    /// A map of the wall y = 2 with a gap from x = 0.5 to x = 1.4, seen from the origin.
    fn wall_with_gap() -> WallMap {
        let mut m = WallMap::new();
        for f in 0..4 {
            m.update(
                f,
                &[seg(-3.0, 2.0, 0.5, 2.0), seg(1.4, 2.0, 3.5, 2.0)],
                Point2::new(0.0, 0.0),
            );
        }
        m
    }

    /// The revolution from the origin facing +x: the wall at y = `wall` everywhere except,
    /// when `beyond` is set, through the gap, where the rays reach the next room's wall.
    fn scan(wall: f32, beyond: Option<f32>) -> [f32; BINS] {
        let mut r = [0.0f32; BINS];
        for (d, slot) in r.iter_mut().enumerate() {
            let phi = (d as f32).to_radians();
            let s = libm::sinf(phi);
            if s <= 0.1 {
                continue;
            }
            let x = wall / s * libm::cosf(phi);
            let in_gap = (0.5..1.4).contains(&x);
            *slot = match (in_gap, beyond) {
                (true, Some(far)) => far / s,
                _ => wall / s,
            };
        }
        r
    }

    #[test]
    fn a_gap_seen_through_is_a_door_and_a_shut_or_shadowed_one_is_not() {
        let map = wall_with_gap();
        let cfg = MapDoorConfig::default();
        let g: heapless::Vec<Gap, 4> = gaps(&map, &cfg).collect();
        assert_eq!(g.len(), 1);
        assert!((g[0].width() - 0.9).abs() < 0.02, "{}", g[0].width());
        assert!(g[0].centre().distance(Point2::new(0.95, 2.0)) < 0.02);

        // Open: the rays through it return from 4 m.
        let mut out = FrameObjects::new();
        let open = scan(2.0, Some(4.0));
        assert_eq!(
            observe(&map, &Pose2::IDENTITY, &open, &cfg, &mut out).len(),
            1
        );
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].class, ObjectClass::DoorFrame);
        assert!((out[0].width_m - 0.9).abs() < 0.02);
        // A door frame of the frame's own there already: seen, not added twice.
        assert_eq!(
            observe(&map, &Pose2::IDENTITY, &open, &cfg, &mut out).len(),
            1
        );
        assert_eq!(out.len(), 1);

        // Shut (a door leaf in the gap): the rays end on the line.
        let mut out = FrameObjects::new();
        let shut = scan(2.0, None);
        assert!(observe(&map, &Pose2::IDENTITY, &shut, &cfg, &mut out).is_empty());
        // Shadowed: a box at y = 1.2 in front of the gap ends the rays before the line.
        let mut out = FrameObjects::new();
        let shadow = scan(2.0, Some(1.2));
        assert!(observe(&map, &Pose2::IDENTITY, &shadow, &cfg, &mut out).is_empty());
        // Seen from behind the wall (the other room): not this room's doorway.
        let mut out = FrameObjects::new();
        let behind = Pose2::new(1.0, 4.0, 0.0);
        assert!(observe(&map, &behind, &open, &cfg, &mut out).is_empty());
    }

    #[test]
    fn gaps_that_are_not_doorways() {
        let cfg = MapDoorConfig::default();
        let origin = Point2::new(0.0, 0.0);
        let mut m = WallMap::new();
        for f in 0..4 {
            m.update(
                f,
                &[
                    // Too narrow (0.5 m): a gap behind a shelf, not a door.
                    seg(-3.0, 2.0, -1.0, 2.0),
                    seg(-0.5, 2.0, 1.5, 2.0),
                    // Too wide (2 m): a passage, not a door.
                    seg(3.5, 2.0, 5.5, 2.0),
                    // Parallel but 0.5 m further back: an alcove's side, not the same wall.
                    seg(-3.0, -2.0, -1.0, -2.0),
                    seg(-0.1, -2.5, 2.0, -2.5),
                ],
                origin,
            );
        }
        assert_eq!(gaps(&m, &cfg).count(), 0);
        // Bad poses say nothing.
        let mut out = FrameObjects::new();
        let nan = Pose2::new(f32::NAN, 0.0, 0.0);
        assert!(observe(&m, &nan, &[3.0; BINS], &cfg, &mut out).is_empty());
    }
}
