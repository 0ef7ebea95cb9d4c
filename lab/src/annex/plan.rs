//! The annex's floor plans (what stands in them: [`super::furnish`]).
//!
//! Rooms are orthogonal polygons (a rectangle 4–11 m a side, an L, or a rectangle split by a
//! partition into two rooms with a doorway), with walls 0.05–0.25 m thick, each wall its own
//! reflectivity (0.12–0.95: dark paint to white). 1–3 doorways of 0.80–1.20 m clear width,
//! anywhere along a wall (corners included); some have their door leaf standing open. Around
//! the plan a hallway boundary 1–2.5 m out. Furniture is placed against walls (a box touching
//! one, a desk backed to one with its chair tucked in) or in the open, in variants the study's
//! world does not have: office chairs on a five-star base, round tables on a pedestal or three
//! legs, panel-end desks. Clutter: shelves along walls, round and square pillars, bins, and
//! people walking back and forth.

use perception::class::ObjectClass;
use perception::geometry::Point2;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use sim::world::Shape;

/// What a primitive belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Owner {
    /// A wall face (or the hallway boundary).
    Wall,
    /// A jamb of door `n`.
    Jamb(usize),
    /// An open door leaf (a wall-like thin board).
    Leaf,
    /// Furniture piece `n` (index into [`Plan::pieces`]).
    Piece(usize),
    /// Clutter item `n`.
    Clutter(usize),
    /// Walking person `n`.
    Person(usize),
}

/// A primitive with its owner and reflectivity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prim {
    /// Geometry.
    pub shape: Shape,
    /// Owner.
    pub owner: Owner,
    /// Reflectivity in (0, 1].
    pub refl: f32,
}

/// A piece of furniture.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Its class.
    pub class: ObjectClass,
    /// Footprint (convex, world frame).
    pub footprint: Vec<Point2>,
    /// What the LiDAR can hit.
    pub shapes: Vec<Shape>,
    /// Reflectivity.
    pub refl: f32,
    /// In words.
    pub what: String,
    /// Backed to or touching a wall.
    pub against_wall: bool,
}

impl Piece {
    pub(super) fn centre(&self) -> Point2 {
        perception::shape::centroid(&[&self.footprint])
    }

    pub(super) fn radius(&self) -> f32 {
        let c = self.centre();
        self.footprint
            .iter()
            .map(|p| p.distance(c))
            .fold(0.0, f32::max)
    }
}

/// A doorway.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Doorway {
    /// Centre of the gap (on the wall's inner face line).
    pub centre: Point2,
    /// Clear width.
    pub width: f32,
}

/// A person walking back and forth between two points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Walker {
    /// One end.
    pub a: Point2,
    /// The other end.
    pub b: Point2,
    /// Speed, m/s.
    pub speed: f32,
    /// Leg radius, m.
    pub leg_r: f32,
    /// Phase offset, s.
    pub phase: f32,
}

impl Walker {
    /// Where the person is at `t` (midpoint of the legs) and the two legs.
    pub fn at(&self, t: f32) -> (Point2, [Point2; 2]) {
        let len = self.a.distance(self.b).max(0.1);
        let s = (t + self.phase) * self.speed;
        let lap = (s / len).rem_euclid(2.0);
        let (u, dir) = if lap < 1.0 {
            (lap, 1.0)
        } else {
            (2.0 - lap, -1.0)
        };
        let d = Point2::new((self.b.x - self.a.x) / len, (self.b.y - self.a.y) / len);
        let c = Point2::new(self.a.x + d.x * u * len, self.a.y + d.y * u * len);
        // Stride: the legs swing ±0.2 m along the walk, 0.1 m either side of it.
        let swing = 0.2 * (core::f32::consts::TAU * s / 1.4).sin() * dir;
        let n = Point2::new(-d.y, d.x);
        let leg = |side: f32, fwd: f32| {
            Point2::new(
                c.x + n.x * 0.1 * side + d.x * fwd,
                c.y + n.y * 0.1 * side + d.y * fwd,
            )
        };
        (c, [leg(1.0, swing), leg(-1.0, -swing)])
    }
}

/// A whole plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Room kind: `rect`, `l`, `two-rooms`.
    pub kind: &'static str,
    /// Walls, jambs, leaves and clutter (everything that never moves).
    pub fixed: Vec<Prim>,
    /// Furniture.
    pub pieces: Vec<Piece>,
    /// Doorways.
    pub doors: Vec<Doorway>,
    /// Clutter: centre and what.
    pub clutter: Vec<(Point2, String)>,
    /// Walking people.
    pub walkers: Vec<Walker>,
    /// Floor rectangles (min, max): the free outline and the doorways between rooms.
    pub floor: Vec<(Point2, Point2)>,
}

/// A wall's inner face from `a` to `b` with the room on its left.
#[derive(Debug, Clone, Copy)]
pub(super) struct Face {
    pub(super) a: Point2,
    pub(super) b: Point2,
}

impl Face {
    pub(super) fn len(&self) -> f32 {
        self.a.distance(self.b)
    }
    pub(super) fn dir(&self) -> Point2 {
        let l = self.len().max(1e-6);
        Point2::new((self.b.x - self.a.x) / l, (self.b.y - self.a.y) / l)
    }
    /// Unit normal into the room.
    pub(super) fn inward(&self) -> Point2 {
        let d = self.dir();
        Point2::new(-d.y, d.x)
    }
    pub(super) fn at(&self, s: f32) -> Point2 {
        let d = self.dir();
        Point2::new(self.a.x + d.x * s, self.a.y + d.y * s)
    }
}

pub(super) fn seg(a: Point2, b: Point2) -> Shape {
    Shape::Segment { a, b }
}

pub(super) fn offset(p: Point2, n: Point2, k: f32) -> Point2 {
    Point2::new(p.x + n.x * k, p.y + n.y * k)
}

/// Corners of a rectangle centred at `c`, half sizes `hx` (along `yaw`) and `hy`.
pub fn rect(c: Point2, hx: f32, hy: f32, yaw: f32) -> Vec<Point2> {
    let (s, co) = yaw.sin_cos();
    [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)]
        .iter()
        .map(|&(x, y)| Point2::new(c.x + co * x - s * y, c.y + s * x + co * y))
        .collect()
}

pub(super) fn outline(poly: &[Point2]) -> Vec<Shape> {
    (0..poly.len())
        .map(|i| seg(poly[i], poly[(i + 1) % poly.len()]))
        .collect()
}

/// Builds plan `seed`.
pub fn generate(rng: &mut ChaCha8Rng) -> Plan {
    let w = rng.random_range(4.0..11.0f32);
    let h = rng.random_range(4.0..9.0f32);
    let t = rng.random_range(0.05..0.25f32);
    let kind = match rng.random_range(0..3) {
        0 => "rect",
        1 => "l",
        _ => "two-rooms",
    };
    let p = |x: f32, y: f32| Point2::new(x, y);
    // Inner outline, counter-clockwise (room on the left of every face).
    let (poly, mut floor) = match kind {
        "l" => {
            let (cw, ch) = (
                w * rng.random_range(0.35..0.55),
                h * rng.random_range(0.35..0.55),
            );
            (
                vec![
                    p(0.0, 0.0),
                    p(w, 0.0),
                    p(w, h - ch),
                    p(w - cw, h - ch),
                    p(w - cw, h),
                    p(0.0, h),
                ],
                vec![(p(0.0, 0.0), p(w, h - ch)), (p(0.0, h - ch), p(w - cw, h))],
            )
        }
        _ => (
            vec![p(0.0, 0.0), p(w, 0.0), p(w, h), p(0.0, h)],
            vec![(p(0.0, 0.0), p(w, h))],
        ),
    };
    let mut faces: Vec<Face> = (0..poly.len())
        .map(|i| Face {
            a: poly[i],
            b: poly[(i + 1) % poly.len()],
        })
        .collect();
    let mut fixed = Vec::new();
    let mut doors = Vec::new();
    let wall_refl: Vec<f32> = (0..faces.len() + 2)
        .map(|_| rng.random_range(0.12..0.95f32))
        .collect();
    // The partition of two rooms: two faces with a doorway through both.
    let mut partition_gap = None;
    if kind == "two-rooms" {
        let s = w * rng.random_range(0.35..0.65);
        let dw = rng.random_range(0.8..1.2f32);
        let y0 = rng.random_range(0.05..(h - dw - 0.05));
        let (xl, xr) = (s - t / 2.0, s + t / 2.0);
        floor = vec![
            (p(0.0, 0.0), p(xl, h)),
            (p(xr, 0.0), p(w, h)),
            (p(xl, y0), p(xr, y0 + dw)),
        ];
        let r = wall_refl[faces.len()];
        for (a, b) in [
            (p(xl, 0.0), p(xl, y0)),
            (p(xl, y0 + dw), p(xl, h)),
            (p(xr, 0.0), p(xr, y0)),
            (p(xr, y0 + dw), p(xr, h)),
            (p(xl, y0), p(xr, y0)),
            (p(xl, y0 + dw), p(xr, y0 + dw)),
        ] {
            let owner = if a.y == b.y {
                Owner::Jamb(0)
            } else {
                Owner::Wall
            };
            fixed.push(Prim {
                shape: seg(a, b),
                owner,
                refl: r,
            });
        }
        doors.push(Doorway {
            centre: p(s, y0 + dw / 2.0),
            width: dw,
        });
        partition_gap = Some((s, y0, dw));
    }
    // Doorways in the outer walls: 1–3 in all (the partition's counts).
    let n_outer = rng
        .random_range(1..=3usize)
        .saturating_sub(doors.len())
        .max(if doors.is_empty() { 1 } else { 0 });
    let mut gaps: Vec<Vec<(f32, f32)>> = vec![Vec::new(); faces.len()];
    for _ in 0..n_outer {
        for _try in 0..20 {
            let fi = rng.random_range(0..faces.len());
            let f = faces[fi];
            let dw = rng.random_range(0.8..1.2f32);
            if f.len() < dw + 0.2 {
                continue;
            }
            let s0 = rng.random_range(0.05..(f.len() - dw - 0.05));
            if gaps[fi]
                .iter()
                .any(|&(a, b)| s0 < b + 0.5 && s0 + dw > a - 0.5)
            {
                continue;
            }
            // Not where the partition meets this wall.
            if let Some((s, _, _)) = partition_gap {
                let m = f.at(s0 + dw / 2.0);
                if (f.a.y == f.b.y) && (m.x - s).abs() < dw / 2.0 + t + 0.2 {
                    continue;
                }
            }
            gaps[fi].push((s0, s0 + dw));
            break;
        }
    }
    let hall = rng.random_range(1.0..2.5f32);
    for (fi, f) in faces.iter_mut().enumerate() {
        let n_in = f.inward();
        let r = wall_refl[fi];
        let mut cuts = gaps[fi].clone();
        cuts.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut s = 0.0;
        for &(g0, g1) in cuts.iter().chain(core::iter::once(&(f.len(), f.len()))) {
            if g0 > s + 1e-4 {
                let (a, b) = (f.at(s), f.at(g0));
                fixed.push(Prim {
                    shape: seg(a, b),
                    owner: Owner::Wall,
                    refl: r,
                });
                fixed.push(Prim {
                    shape: seg(offset(a, n_in, -t), offset(b, n_in, -t)),
                    owner: Owner::Wall,
                    refl: r,
                });
            }
            if g1 > g0 {
                let di = doors.len();
                for e in [g0, g1] {
                    let q = f.at(e);
                    fixed.push(Prim {
                        shape: seg(q, offset(q, n_in, -t)),
                        owner: Owner::Jamb(di),
                        refl: r,
                    });
                }
                let c = f.at((g0 + g1) / 2.0);
                doors.push(Doorway {
                    centre: c,
                    width: g1 - g0,
                });
                // An open leaf, swung into the room or out, on the hinge side.
                if rng.random_bool(0.4) {
                    let hinge = f.at(g0);
                    let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                    let leaf_end = offset(hinge, n_in, sign * (g1 - g0 - 0.05));
                    fixed.push(Prim {
                        shape: seg(
                            offset(hinge, f.dir(), 0.02),
                            offset(leaf_end, f.dir(), 0.02),
                        ),
                        owner: Owner::Leaf,
                        refl: rng.random_range(0.3..0.9),
                    });
                }
            }
            s = g1;
        }
    }
    // Hallway boundary.
    let (lo, hi) = (p(-t - hall, -t - hall), p(w + t + hall, h + t + hall));
    for s in outline(&[lo, p(hi.x, lo.y), hi, p(lo.x, hi.y)]) {
        fixed.push(Prim {
            shape: s,
            owner: Owner::Wall,
            refl: wall_refl[faces.len() + 1],
        });
    }
    let mut plan = Plan {
        kind,
        fixed,
        pieces: Vec::new(),
        doors,
        clutter: Vec::new(),
        walkers: Vec::new(),
        floor,
    };
    super::furnish::furnish(&mut plan, &faces, rng);
    plan
}

fn on_floor(floor: &[(Point2, Point2)], q: Point2, margin: f32) -> bool {
    floor.iter().any(|(a, b)| {
        q.x >= a.x + margin && q.x <= b.x - margin && q.y >= a.y + margin && q.y <= b.y - margin
    })
}

impl Plan {
    /// Distance from `q` to the nearest wall, jamb or leaf.
    pub fn wall_clearance(&self, q: Point2) -> f32 {
        self.fixed
            .iter()
            .filter(|p| matches!(p.owner, Owner::Wall | Owner::Jamb(_) | Owner::Leaf))
            .map(|p| p.shape.distance(q))
            .fold(f32::INFINITY, f32::min)
    }

    /// Whether `q` is on the floor with `c` metres to every wall, piece and clutter item.
    pub fn free(&self, q: Point2, c: f32) -> bool {
        on_floor(&self.floor, q, 0.0)
            && self.fixed.iter().all(|p| p.shape.distance(q) >= c)
            && self
                .pieces
                .iter()
                .all(|pc| crate::run_truth::polygon_distance(&pc.footprint, q) >= c)
    }

    /// Whether the straight path `a → b` keeps `c` metres from everything.
    pub fn path_free(&self, a: Point2, b: Point2, c: f32) -> bool {
        let n = (a.distance(b) / 0.05).ceil().max(1.0) as usize;
        (0..=n).all(|i| {
            let u = i as f32 / n as f32;
            self.free(Point2::new(a.x + (b.x - a.x) * u, a.y + (b.y - a.y) * u), c)
        })
    }

    /// A random free point with clearance `c`.
    pub fn free_point(&self, rng: &mut ChaCha8Rng, c: f32) -> Option<Point2> {
        for _ in 0..400 {
            let (a, b) = self.floor[rng.random_range(0..self.floor.len())];
            if b.x - a.x < 2.0 * c || b.y - a.y < 2.0 * c {
                continue;
            }
            let q = Point2::new(rng.random_range(a.x..b.x), rng.random_range(a.y..b.y));
            if self.free(q, c) {
                return Some(q);
            }
        }
        None
    }

    pub(super) fn fits(&self, fp: &[Point2], gap: f32) -> bool {
        let c = perception::shape::centroid(&[fp]);
        let r = fp.iter().map(|p| p.distance(c)).fold(0.0, f32::max);
        let mut probes: Vec<Point2> = fp.to_vec();
        for i in 0..fp.len() {
            let (a, b) = (fp[i], fp[(i + 1) % fp.len()]);
            probes.push(Point2::new((a.x + b.x) / 2.0, (a.y + b.y) / 2.0));
        }
        probes.iter().all(|&q| on_floor(&self.floor, q, -0.001))
            && self.doors.iter().all(|d| d.centre.distance(c) > r + 0.8)
            && self
                .pieces
                .iter()
                .all(|pc| pc.centre().distance(c) > pc.radius() + r + gap)
            && self
                .clutter
                .iter()
                .all(|(q, _)| q.distance(c) > r + gap + 0.3)
    }
}
