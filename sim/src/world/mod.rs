//! A seeded 2D world as seen at LiDAR height (~0.17 m): rooms with 0.1 m walls, doorways with
//! jambs, furniture of the four classes' shapes, and clutter that is none of them.
//!
//! Room kinds ([`RoomKind`]): a rectangle 3–8 m a side, an L-shape (a rectangle with a corner
//! cut out), and two rooms joined by a corridor. Walls are solid 0.1 m rectangles built outside
//! the free outline, so a ray sees the inner face, and through a doorway the jamb faces and
//! whatever lies beyond (a hallway wall for single rooms, the corridor and the other room).
//!
//! Furniture (the study's world geometry, `docs/simulator.md`): a chair is four ~3 cm legs on a ~0.4 m square, a
//! desk four ~5 cm legs on ~0.8 × 1.6 m, a box a solid ~0.4 × 0.6 m rectangle, each scaled by
//! U(0.8, 1.2), placed uniformly with random rotation, no overlaps and ≥ 0.7 m between
//! footprints (a varied world's chairs may be office chairs instead: `variety.rs`). Clutter:
//! round bins, round pillars, and pairs of people's legs.
//!
//! Every surface carries a [`Surface`] label (what a ray that hits it has hit) and a
//! reflectivity that drives the LiDAR's dropouts and intensity.

use perception::class::ObjectClass;
use perception::geometry::Point2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod build;
mod config;
pub mod grid;
mod variety;
use build::{Builder, inside};
pub use config::{RoomKind, WorldConfig};
use grid::Grid;

/// Wall thickness, metres.
pub const WALL_T: f32 = 0.1;
/// Narrowest doorway, metres: the paper's door-frame rule looks for gaps of 0.9–1.4 m (a
/// standard interior door's clear opening is about 0.8–0.9 m; wider ones are common in offices).
pub const DOOR_WIDTH_MIN: f32 = 0.9;
/// Widest doorway, metres.
pub const DOOR_WIDTH_MAX: f32 = 1.3;
/// Clearance kept between furniture footprints (room for the robot), metres.
pub const CLEARANCE: f32 = 0.7;

/// What a surface belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Surface {
    /// A wall.
    Wall,
    /// A door frame (jamb) of door `n` (index into [`World::doors`]).
    DoorFrame(u16),
    /// Furniture `n` (index into [`World::objects`]).
    Object(u16),
    /// Clutter item `n` (index into [`World::clutter`]): none of the classes.
    Clutter(u16),
    /// A leg of walking person `n` (index into the scenario's people; `crate::people`).
    Person(u16),
}

/// A ray-castable primitive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A line segment.
    Segment {
        /// One end.
        a: Point2,
        /// The other end.
        b: Point2,
    },
    /// A circle (legs, bins, pillars).
    Circle {
        /// Centre.
        c: Point2,
        /// Radius.
        r: f32,
    },
}

impl Shape {
    /// Axis-aligned bounds (min, max).
    pub fn bounds(&self) -> (Point2, Point2) {
        match *self {
            Shape::Segment { a, b } => (
                Point2::new(a.x.min(b.x), a.y.min(b.y)),
                Point2::new(a.x.max(b.x), a.y.max(b.y)),
            ),
            Shape::Circle { c, r } => {
                (Point2::new(c.x - r, c.y - r), Point2::new(c.x + r, c.y + r))
            }
        }
    }

    /// Distance along the ray `o + t·d` (unit `d`) to this shape and the cosine of the angle of
    /// incidence, if it is hit at `t > 0`.
    #[inline]
    pub fn intersect(&self, o: Point2, d: Point2) -> Option<(f32, f32)> {
        match *self {
            Shape::Segment { a, b } => {
                let e = b - a;
                let denom = d.x * e.y - d.y * e.x;
                if denom.abs() < 1e-12 {
                    return None;
                }
                let w = a - o;
                let t = (w.x * e.y - w.y * e.x) / denom;
                let u = (w.x * d.y - w.y * d.x) / denom;
                if t > 1e-6 && (0.0..=1.0).contains(&u) {
                    let len = (e.x * e.x + e.y * e.y).sqrt();
                    Some((t, (denom / len).abs()))
                } else {
                    None
                }
            }
            Shape::Circle { c, r } => {
                let m = o - c;
                let b = m.x * d.x + m.y * d.y;
                let cc = m.x * m.x + m.y * m.y - r * r;
                if cc > 0.0 && b > 0.0 {
                    return None;
                }
                let disc = b * b - cc;
                if disc < 0.0 {
                    return None;
                }
                let t = -b - disc.sqrt();
                if t <= 1e-6 {
                    return None; // origin inside the circle
                }
                let p = Point2::new(m.x + t * d.x, m.y + t * d.y);
                let cos = ((p.x * d.x + p.y * d.y) / r).abs();
                Some((t, cos))
            }
        }
    }

    /// Distance from `p` to this shape's outline.
    pub fn distance(&self, p: Point2) -> f32 {
        match *self {
            Shape::Segment { a, b } => p.distance_to_segment(a, b),
            Shape::Circle { c, r } => (p.distance(c) - r).max(0.0),
        }
    }
}

/// A primitive with what it belongs to and how well it reflects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prim {
    /// Geometry.
    pub shape: Shape,
    /// Owner.
    pub surface: Surface,
    /// Reflectivity in (0, 1]: dark or glossy surfaces return less often.
    pub reflectivity: f32,
}

/// A piece of furniture (ground truth).
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectTruth {
    /// Class.
    pub class: ObjectClass,
    /// Centre, world frame.
    pub centre: Point2,
    /// Rotation, radians.
    pub yaw: f32,
    /// Footprint corners, counter-clockwise, world frame.
    pub footprint: [Point2; 4],
}

/// A doorway (ground truth).
#[derive(Debug, Clone, PartialEq)]
pub struct DoorTruth {
    /// Centre of the gap.
    pub centre: Point2,
    /// Clear width of the gap, metres.
    pub width: f32,
    /// Direction along the wall, radians.
    pub wall_angle: f32,
    /// Footprint of the frame (gap plus both jambs), counter-clockwise.
    pub footprint: [Point2; 4],
}

/// A clutter item (ground truth).
#[derive(Debug, Clone, PartialEq)]
pub struct ClutterTruth {
    /// What it is: `bin`, `pillar` or `legs`.
    pub kind: &'static str,
    /// Centre.
    pub centre: Point2,
}

/// A generated world.
#[derive(Debug, Clone)]
pub struct World {
    /// Layout.
    pub kind: RoomKind,
    /// Every primitive.
    pub prims: Vec<Prim>,
    /// Furniture.
    pub objects: Vec<ObjectTruth>,
    /// Doorways.
    pub doors: Vec<DoorTruth>,
    /// Clutter.
    pub clutter: Vec<ClutterTruth>,
    /// Axis-aligned free rectangles (min, max) that make up the floor.
    pub floor: Vec<(Point2, Point2)>,
    /// A spot with clearance for the robot to start.
    pub robot_start: Point2,
    /// Spatial index over `prims`.
    pub grid: Grid,
    /// Drawn with the wider variety of [`WorldConfig::varied`].
    pub varied: bool,
}

impl World {
    /// A random world from `seed`.
    pub fn generate(seed: u64, cfg: &WorldConfig) -> World {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        // Drawn only when asked for, so that `varied: 0` leaves every seed's world unchanged.
        let varied = cfg.varied > 0.0 && rng.random_bool(cfg.varied.min(1.0));
        let wall_t = if varied {
            rng.random_range(0.05..0.25)
        } else {
            WALL_T
        };
        // A style's share applies in a varied world only.
        let share = |p: f64| if varied { p.clamp(0.0, 1.0) } else { 0.0 };
        let mut b = Builder {
            rng,
            prims: Vec::new(),
            objects: Vec::new(),
            doors: Vec::new(),
            clutter: Vec::new(),
            floor: Vec::new(),
            keep_out: Vec::new(),
            wall_t,
            varied,
            office_share: share(cfg.office_chairs),
            round_share: share(cfg.round_tables),
            box_share: share(cfg.box_sizes),
            dark_box_share: share(cfg.dark_boxes),
            spoke_share: share(cfg.office_spokes),
            style: ChaCha8Rng::seed_from_u64(seed ^ 0x000f_f1ce),
        };
        let door_min = if varied {
            variety::DOOR_WIDTH_MIN
        } else {
            DOOR_WIDTH_MIN
        };
        let kinds = if cfg.kinds.is_empty() {
            vec![RoomKind::Rect]
        } else {
            cfg.kinds.clone()
        };
        let kind = kinds[b.rng.random_range(0..kinds.len())];
        let p = Point2::new;
        match kind {
            RoomKind::Rect | RoomKind::LShape | RoomKind::Notch => {
                // Varied worlds: rooms up to 11 m, larger than the LiDAR reaches.
                let side = if varied { 11.0 } else { 8.0 };
                // A notched room needs two arms beside its notch.
                let w_min = if kind == RoomKind::Notch { 4.0 } else { 3.0 };
                let w = b.rng.random_range(w_min..side);
                let h = b.rng.random_range(3.0..side);
                let outline: Vec<Point2> = if kind == RoomKind::Rect {
                    b.floor.push((p(0.0, 0.0), p(w, h)));
                    vec![p(0.0, 0.0), p(w, 0.0), p(w, h), p(0.0, h)]
                } else if kind == RoomKind::Notch {
                    // The notch: 25–45 % of the width, its left side 20 % of the width or more
                    // from the left wall, 30–50 % of the depth deep.
                    let nw = b.rng.random_range(0.25..0.45) * w;
                    let a0 = b.rng.random_range(0.2 * w..(0.8 * w - nw));
                    let a1 = a0 + nw;
                    let c = b.rng.random_range(0.3..0.5) * h;
                    b.floor.push((p(0.0, 0.0), p(w, h - c)));
                    b.floor.push((p(0.0, h - c), p(a0, h)));
                    b.floor.push((p(a1, h - c), p(w, h)));
                    vec![
                        p(0.0, 0.0),
                        p(w, 0.0),
                        p(w, h),
                        p(a1, h),
                        p(a1, h - c),
                        p(a0, h - c),
                        p(a0, h),
                        p(0.0, h),
                    ]
                } else {
                    let a = b.rng.random_range(0.35..0.6) * w;
                    let c = b.rng.random_range(0.35..0.6) * h;
                    b.floor.push((p(0.0, 0.0), p(w, h - c)));
                    b.floor.push((p(0.0, h - c), p(w - a, h)));
                    vec![
                        p(0.0, 0.0),
                        p(w, 0.0),
                        p(w, h - c),
                        p(w - a, h - c),
                        p(w - a, h),
                        p(0.0, h),
                    ]
                };
                let door = b.rng.random_bool(cfg.door_chance).then(|| {
                    let width = b.rng.random_range(door_min..DOOR_WIDTH_MAX);
                    // A doorway on an edge long enough for it.
                    let n = outline.len();
                    let mut e = b.rng.random_range(0..n);
                    for _ in 0..n {
                        if outline[e].distance(outline[(e + 1) % n]) >= width + 0.8 {
                            break;
                        }
                        e = (e + 1) % n;
                    }
                    (e, width)
                });
                if let Some((c, dir, out)) = b.outline(&outline, door) {
                    b.hallway(c, dir, out);
                }
            }
            RoomKind::TwoRooms => {
                let w1 = b.rng.random_range(3.0..6.0f32);
                let h1 = b.rng.random_range(3.0..6.0f32);
                let w2 = b.rng.random_range(3.0..6.0f32);
                let h2 = b.rng.random_range(3.0..6.0f32);
                let len = b.rng.random_range(1.5..4.0f32);
                let cw = b.rng.random_range(1.2..1.7f32);
                let yc = b.rng.random_range(0.3..(h1.min(h2) - cw - 0.3));
                let yb = 0.0;
                let x2 = w1 + len;
                b.floor.push((p(0.0, 0.0), p(w1, h1)));
                b.floor.push((p(x2, yb), p(x2 + w2, yb + h2)));
                let outline = vec![
                    p(0.0, 0.0),
                    p(w1, 0.0),
                    p(w1, yc),
                    p(x2, yc),
                    p(x2, yb),
                    p(x2 + w2, yb),
                    p(x2 + w2, yb + h2),
                    p(x2, yb + h2),
                    p(x2, yc + cw),
                    p(w1, yc + cw),
                    p(w1, h1),
                    p(0.0, h1),
                ];
                b.outline(&outline, None);
                // Doorways: walls across the corridor at both ends, each with a gap.
                for x in [w1, x2 - b.wall_t] {
                    let width = b.rng.random_range(door_min..(cw - 0.2).min(DOOR_WIDTH_MAX));
                    let g0 = b.rng.random_range(0.05..(cw - width - 0.05));
                    b.wall(p(x, yc), p(x, yc + cw), p(1.0, 0.0), Some((g0, g0 + width)));
                }
            }
        }
        if varied {
            b.stubs();
        }
        let area: f32 = b.floor.iter().map(|(a, c)| (c.x - a.x) * (c.y - a.y)).sum();
        let n = ((area * cfg.furniture_density).round() as usize).max(2);
        // The first three tries are one of each class, then random; a piece that does not fit
        // anywhere (a desk in a narrow arm) is replaced by another draw.
        for i in 0..n + 12 {
            if b.objects.len() >= n {
                break;
            }
            let class = match (i, b.rng.random_range(0..3)) {
                (0, _) => ObjectClass::Chair,
                (1, _) => ObjectClass::Box,
                (2, _) => ObjectClass::Desk,
                (_, 0) => ObjectClass::Chair,
                (_, 1) => ObjectClass::Box,
                _ => ObjectClass::Desk,
            };
            if varied {
                b.furniture_varied(class);
            } else {
                b.furniture(class);
            }
        }
        let n_clutter = b.rng.random_range(0..=cfg.max_clutter);
        for _ in 0..n_clutter {
            if varied {
                b.clutter_varied();
            } else {
                b.clutter_item();
            }
        }
        let grid = Grid::build(&b.prims);
        let mut world = World {
            kind,
            prims: b.prims,
            objects: b.objects,
            doors: b.doors,
            clutter: b.clutter,
            floor: b.floor,
            robot_start: Point2::default(),
            grid,
            varied,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x0b07);
        world.robot_start = world.free_point(&mut rng, 0.6).unwrap_or_else(|| {
            let (lo, hi) = world.floor[0];
            Point2::new((lo.x + hi.x) / 2.0, (lo.y + hi.y) / 2.0)
        });
        world
    }

    /// The study-like default: a random room of any kind.
    pub fn random_room(seed: u64) -> World {
        World::generate(seed, &WorldConfig::default())
    }

    /// One line for people: layout, size, what is in it.
    pub fn describe(&self) -> String {
        let (mut lo, mut hi) = (
            Point2::new(f32::MAX, f32::MAX),
            Point2::new(f32::MIN, f32::MIN),
        );
        for (a, b) in &self.floor {
            lo = Point2::new(lo.x.min(a.x), lo.y.min(a.y));
            hi = Point2::new(hi.x.max(b.x), hi.y.max(b.y));
        }
        let name = match self.kind {
            RoomKind::Rect => "rectangular room",
            RoomKind::LShape => "L-shaped room",
            RoomKind::Notch => "notched room",
            RoomKind::TwoRooms => "two rooms and a corridor",
        };
        format!(
            "{name} {:.1} × {:.1} m, {} pieces of furniture, {} doorway(s), {} clutter",
            hi.x - lo.x,
            hi.y - lo.y,
            self.objects.len(),
            self.doors.len(),
            self.clutter.len()
        )
    }

    /// Distance from `p` to the nearest surface or furniture footprint (0 inside one: the
    /// robot does not drive under desks or between a chair's legs).
    pub fn clearance(&self, p: Point2) -> f32 {
        let surfaces = self
            .prims
            .iter()
            .map(|pr| pr.shape.distance(p))
            .fold(f32::INFINITY, f32::min);
        self.objects.iter().fold(surfaces, |best, o| {
            let fp = &o.footprint;
            if inside(fp, p) {
                return 0.0;
            }
            (0..4)
                .map(|i| {
                    Shape::Segment {
                        a: fp[i],
                        b: fp[(i + 1) % 4],
                    }
                    .distance(p)
                })
                .fold(best, f32::min)
        })
    }

    /// `true` if `p` lies on the floor.
    pub fn on_floor(&self, p: Point2) -> bool {
        build::on_floor(&self.floor, p)
    }

    /// A random floor point with at least `clearance` to every surface.
    pub fn free_point(&self, rng: &mut impl Rng, clearance: f32) -> Option<Point2> {
        let total: f32 = self
            .floor
            .iter()
            .map(|(a, b)| (b.x - a.x) * (b.y - a.y))
            .sum();
        for _ in 0..500 {
            let mut pick = rng.random_range(0.0..total);
            for (lo, hi) in &self.floor {
                let area = (hi.x - lo.x) * (hi.y - lo.y);
                if pick < area {
                    let p = Point2::new(rng.random_range(lo.x..hi.x), rng.random_range(lo.y..hi.y));
                    if self.clearance(p) >= clearance {
                        return Some(p);
                    }
                    break;
                }
                pick -= area;
            }
        }
        None
    }

    /// `true` if the straight path from `a` to `b` keeps `clearance` everywhere (sampled every
    /// 5 cm) and stays on the floor or in doorways.
    pub fn path_clear(&self, a: Point2, b: Point2, clearance: f32) -> bool {
        let n = (a.distance(b) / 0.05).ceil().max(1.0) as usize;
        (0..=n).all(|i| {
            let t = i as f32 / n as f32;
            let p = Point2::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t);
            self.clearance(p) >= clearance
        })
    }

    /// Nearest surface along the ray from `origin` at `angle` (world frame, radians), up to
    /// `max_range`: (distance, primitive index, cosine of incidence).
    #[inline]
    pub fn raycast(&self, origin: Point2, angle: f32, max_range: f32) -> Option<(f32, usize, f32)> {
        let (s, c) = angle.sin_cos();
        self.grid
            .raycast(&self.prims, origin, Point2::new(c, s), max_range)
    }

    /// Brute-force ray cast over every primitive (the reference for the grid's tests).
    pub fn raycast_brute(
        &self,
        origin: Point2,
        angle: f32,
        max_range: f32,
    ) -> Option<(f32, usize, f32)> {
        let (s, c) = angle.sin_cos();
        let d = Point2::new(c, s);
        self.prims
            .iter()
            .enumerate()
            .filter_map(|(i, p)| p.shape.intersect(origin, d).map(|(t, cos)| (t, i, cos)))
            .filter(|(t, ..)| *t <= max_range)
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn seeded_and_reproducible() {
        let a = World::random_room(7);
        let b = World::random_room(7);
        assert_eq!(a.prims, b.prims);
        assert_eq!(a.objects, b.objects);
        assert_ne!(a.prims, World::random_room(8).prims);
    }

    #[test]
    fn all_kinds_generate_with_furniture_and_clear_start() {
        for kind in [
            RoomKind::Rect,
            RoomKind::LShape,
            RoomKind::TwoRooms,
            RoomKind::Notch,
        ] {
            let cfg = WorldConfig {
                kinds: vec![kind],
                ..WorldConfig::default()
            };
            for seed in 0..20 {
                let w = World::generate(seed, &cfg);
                assert_eq!(w.kind, kind);
                assert!(
                    w.objects.len() >= 2,
                    "{kind:?} seed {seed}: {} objects",
                    w.objects.len()
                );
                assert!(w.on_floor(w.robot_start));
                assert!(w.clearance(w.robot_start) >= 0.5, "{kind:?} seed {seed}");
                if kind == RoomKind::TwoRooms {
                    assert_eq!(w.doors.len(), 2);
                }
                // No two footprints closer than the clearance (bounding circles).
                for (i, a) in w.objects.iter().enumerate() {
                    for b in &w.objects[i + 1..] {
                        let ra = a.centre.distance(a.footprint[0]);
                        let rb = b.centre.distance(b.footprint[0]);
                        assert!(a.centre.distance(b.centre) >= ra + rb + CLEARANCE - 1e-3);
                    }
                }
            }
        }
    }

    #[test]
    fn grid_raycast_equals_brute_force() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for seed in 0..15 {
            let w = World::random_room(seed);
            for _ in 0..400 {
                let o = w.free_point(&mut rng, 0.2).unwrap();
                let a = rng.random_range(-4.0..4.0f32);
                let g = w.raycast(o, a, 6.0);
                let b = w.raycast_brute(o, a, 6.0);
                match (g, b) {
                    (Some(g), Some(b)) => assert!((g.0 - b.0).abs() < 1e-4, "{g:?} vs {b:?}"),
                    (None, None) => {}
                    other => panic!("seed {seed}: grid and brute force disagree: {other:?}"),
                }
            }
        }
    }

    #[test]
    fn circle_and_segment_hits() {
        let o = Point2::new(0.0, 0.0);
        let d = Point2::new(1.0, 0.0);
        let c = Shape::Circle {
            c: Point2::new(2.0, 0.0),
            r: 0.5,
        };
        let (t, cos) = c.intersect(o, d).unwrap();
        assert!((t - 1.5).abs() < 1e-5 && (cos - 1.0).abs() < 1e-5);
        let s = Shape::Segment {
            a: Point2::new(3.0, -1.0),
            b: Point2::new(3.0, 1.0),
        };
        let (t, cos) = s.intersect(o, d).unwrap();
        assert!((t - 3.0).abs() < 1e-5 && (cos - 1.0).abs() < 1e-5);
        assert!(s.intersect(o, Point2::new(-1.0, 0.0)).is_none());
    }
}
