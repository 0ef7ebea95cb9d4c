//! How a world is built: walls with doorways and hallways, furniture and clutter placed with
//! spacing, each surface a primitive with its label and reflectivity.

use perception::class::ObjectClass;
use perception::geometry::Point2;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::{CLEARANCE, ClutterTruth, DoorTruth, ObjectTruth, Prim, Shape, Surface};

pub(super) fn rect_corners(c: Point2, half: (f32, f32), yaw: f32) -> [Point2; 4] {
    let (s, co) = yaw.sin_cos();
    let r = |x: f32, y: f32| Point2::new(c.x + co * x - s * y, c.y + s * x + co * y);
    [
        r(-half.0, -half.1),
        r(half.0, -half.1),
        r(half.0, half.1),
        r(-half.0, half.1),
    ]
}

/// How a piece of furniture is built at LiDAR height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Build {
    /// Four round legs of this radius at the footprint's corners (chairs, desks).
    Legs(f32),
    /// A solid footprint (boxes).
    Solid,
    /// An office chair: a gas column on a five-star base (`variety.rs`).
    OfficeChair,
    /// A round table: three or four legs on a circle under its top (`variety.rs`).
    RoundTable,
}

pub(super) struct Builder {
    pub(super) rng: ChaCha8Rng,
    pub(super) prims: Vec<Prim>,
    pub(super) objects: Vec<ObjectTruth>,
    pub(super) doors: Vec<DoorTruth>,
    pub(super) clutter: Vec<ClutterTruth>,
    pub(super) floor: Vec<(Point2, Point2)>,
    /// Keep-out discs (centre, radius) of everything placed so far, for spacing.
    pub(super) keep_out: Vec<(Point2, f32)>,
    /// Wall thickness, metres ([`super::WALL_T`] unless the world is varied).
    pub(super) wall_t: f32,
    /// Drawn with the wider variety (`variety.rs`).
    pub(super) varied: bool,
    /// Share of chairs that are office chairs (0 unless asked for in a varied world).
    pub(super) office_share: f64,
    /// Share of desks that are round tables (0 unless asked for in a varied world).
    pub(super) round_share: f64,
    /// Share of boxes drawn with sides of their own (0 unless asked for in a varied world).
    pub(super) box_share: f64,
    /// Share of boxes drawn dark (0 unless asked for in a varied world).
    pub(super) dark_box_share: f64,
    /// Share of office chairs whose arms lie in the scan plane (0 unless asked for).
    pub(super) spoke_share: f64,
    /// A second stream for the furniture styles of a varied world (`variety.rs`: office
    /// chairs, round tables, box sizes), drawn from only when they are asked for.
    pub(super) style: ChaCha8Rng,
}

impl Builder {
    pub(super) fn polygon(&mut self, corners: &[Point2], surface: Surface, reflectivity: f32) {
        for i in 0..corners.len() {
            self.prims.push(Prim {
                shape: Shape::Segment {
                    a: corners[i],
                    b: corners[(i + 1) % corners.len()],
                },
                surface,
                reflectivity,
            });
        }
    }

    pub(super) fn aabb(&mut self, min: Point2, max: Point2, surface: Surface, reflectivity: f32) {
        if max.x - min.x <= 1e-4 || max.y - min.y <= 1e-4 {
            return;
        }
        self.polygon(
            &[
                min,
                Point2::new(max.x, min.y),
                max,
                Point2::new(min.x, max.y),
            ],
            surface,
            reflectivity,
        );
    }

    pub(super) fn circle(&mut self, c: Point2, r: f32, surface: Surface, reflectivity: f32) {
        self.prims.push(Prim {
            shape: Shape::Circle { c, r },
            surface,
            reflectivity,
        });
    }

    pub(super) fn wall_reflectivity(&mut self) -> f32 {
        if self.varied {
            // Dark paint, glass-fronted cabinets, wood panelling: anything from 0.12 up.
            self.rng.random_range(0.12..1.0)
        } else {
            self.rng.random_range(0.75..1.0)
        }
    }

    /// A straight wall of thickness `wall_t` from `p` to `q` (axis-aligned), built on the side
    /// `outward` (unit normal), with an optional doorway gap `[g0, g1]` measured from `p`.
    pub(super) fn wall(&mut self, p: Point2, q: Point2, outward: Point2, gap: Option<(f32, f32)>) {
        let refl = self.wall_reflectivity();
        let len = p.distance(q);
        let dir = Point2::new((q.x - p.x) / len, (q.y - p.y) / len);
        let along = |t: f32| Point2::new(p.x + dir.x * t, p.y + dir.y * t);
        let piece = |b: &mut Builder, t0: f32, t1: f32| {
            let a = along(t0);
            let c = along(t1);
            let a2 = Point2::new(c.x + outward.x * b.wall_t, c.y + outward.y * b.wall_t);
            let min = Point2::new(a.x.min(a2.x), a.y.min(a2.y));
            let max = Point2::new(a.x.max(a2.x), a.y.max(a2.y));
            b.aabb(min, max, Surface::Wall, refl);
        };
        match gap {
            None => piece(self, 0.0, len),
            Some((g0, g1)) => {
                piece(self, 0.0, g0);
                piece(self, g1, len);
                self.door(along(g0), along(g1), dir, outward);
            }
        }
    }

    /// Jambs at both ends of a gap from `a` to `b` in a wall running along `dir`.
    pub(super) fn door(&mut self, a: Point2, b: Point2, dir: Point2, outward: Point2) {
        let id = self.doors.len() as u16;
        let refl = self.rng.random_range(0.5..0.95);
        let jamb_w = 0.04;
        let wall_t = self.wall_t;
        let reveal = 0.02; // the frame stands proud of the wall on both sides
        let mk = |at: Point2, sign: f32| -> [Point2; 4] {
            // From the gap edge `at`, the jamb extends `jamb_w` into the wall side (sign).
            let o0 = -reveal;
            let o1 = wall_t + reveal;
            let p = |s: f32, o: f32| {
                Point2::new(
                    at.x + dir.x * s * sign + outward.x * o,
                    at.y + dir.y * s * sign + outward.y * o,
                )
            };
            [p(0.0, o0), p(jamb_w, o0), p(jamb_w, o1), p(0.0, o1)]
        };
        let left = mk(a, -1.0);
        let right = mk(b, 1.0);
        self.polygon(&left, Surface::DoorFrame(id), refl);
        self.polygon(&right, Surface::DoorFrame(id), refl);
        let width = a.distance(b);
        let centre = Point2::new(
            (a.x + b.x) / 2.0 + outward.x * wall_t / 2.0,
            (a.y + b.y) / 2.0 + outward.y * wall_t / 2.0,
        );
        let half_len = width / 2.0 + jamb_w;
        let half_t = wall_t / 2.0 + reveal;
        let wall_angle = dir.y.atan2(dir.x);
        self.doors.push(DoorTruth {
            centre,
            width,
            wall_angle,
            footprint: rect_corners(centre, (half_len, half_t), wall_angle),
        });
        self.keep_out.push((centre, half_len));
        if self.varied && self.rng.random_bool(0.4) {
            self.door_leaf(a, b, dir, outward);
        }
    }

    /// Walls around an axis-aligned rectilinear outline (counter-clockwise), with a doorway in
    /// edge `door_edge` if given.
    pub(super) fn outline(
        &mut self,
        v: &[Point2],
        door: Option<(usize, f32)>,
    ) -> Option<(Point2, Point2, Point2)> {
        let n = v.len();
        let mut door_out = None;
        for i in 0..n {
            let (p, q) = (v[i], v[(i + 1) % n]);
            let len = p.distance(q);
            let dir = Point2::new((q.x - p.x) / len, (q.y - p.y) / len);
            // Counter-clockwise outline: the outside is to the right of the edge.
            let outward = Point2::new(dir.y, -dir.x);
            // Extend across convex corners so that corners are closed.
            let convex = |a: Point2, b: Point2, c: Point2| {
                (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x) > 0.0
            };
            let ext0 = if convex(v[(i + n - 1) % n], p, q) {
                self.wall_t
            } else {
                0.0
            };
            let ext1 = if convex(p, q, v[(i + 2) % n]) {
                self.wall_t
            } else {
                0.0
            };
            let p2 = Point2::new(p.x - dir.x * ext0, p.y - dir.y * ext0);
            let q2 = Point2::new(q.x + dir.x * ext1, q.y + dir.y * ext1);
            let gap = door.filter(|(e, _)| *e == i).map(|(_, w)| {
                // Varied worlds put doorways up to a corner (a 5 cm stub of wall beside it).
                let m = if self.varied { 0.05 } else { 0.3 };
                let g0 = self.rng.random_range(m..(len - w - m).max(m + 0.01)) + ext0;
                door_out = Some((
                    Point2::new(p2.x + dir.x * (g0 + w / 2.0), p2.y + dir.y * (g0 + w / 2.0)),
                    dir,
                    outward,
                ));
                (g0, g0 + w)
            });
            self.wall(p2, q2, outward, gap);
        }
        door_out
    }

    /// A hallway wall beyond a doorway so that rays leaving the room see something.
    pub(super) fn hallway(&mut self, door_centre: Point2, dir: Point2, outward: Point2) {
        let dist = self.rng.random_range(1.2..2.0);
        let half = self.rng.random_range(2.0..3.5);
        let c = Point2::new(
            door_centre.x + outward.x * dist,
            door_centre.y + outward.y * dist,
        );
        // Shortened where it would cut into the room (beyond a doorway in an L's notch).
        let mut half: f32 = half;
        loop {
            let p = Point2::new(c.x - dir.x * half, c.y - dir.y * half);
            let q = Point2::new(c.x + dir.x * half, c.y + dir.y * half);
            let far = Point2::new(q.x + outward.x * self.wall_t, q.y + outward.y * self.wall_t);
            let (min, max) = (
                Point2::new(p.x.min(far.x), p.y.min(far.y)),
                Point2::new(p.x.max(far.x), p.y.max(far.y)),
            );
            let cuts = self
                .floor
                .iter()
                .any(|(lo, hi)| min.x < hi.x && max.x > lo.x && min.y < hi.y && max.y > lo.y);
            if !cuts {
                self.wall(p, q, outward, None);
                return;
            }
            if half < 0.8 {
                return;
            }
            half -= 0.1;
        }
    }

    pub(super) fn fits(&self, c: Point2, r: f32, gap: f32) -> bool {
        let inside = self.floor.iter().any(|(lo, hi)| {
            c.x - r >= lo.x + 0.15
                && c.x + r <= hi.x - 0.15
                && c.y - r >= lo.y + 0.15
                && c.y + r <= hi.y - 0.15
        });
        inside
            && self
                .keep_out
                .iter()
                .all(|(o, or)| c.distance(*o) >= r + or + gap)
    }

    pub(super) fn random_floor_point(&mut self) -> Point2 {
        let total: f32 = self
            .floor
            .iter()
            .map(|(a, b)| (b.x - a.x) * (b.y - a.y))
            .sum();
        let mut pick = self.rng.random_range(0.0..total);
        let mut chosen = self.floor[0];
        for f in &self.floor {
            let area = (f.1.x - f.0.x) * (f.1.y - f.0.y);
            if pick < area {
                chosen = *f;
                break;
            }
            pick -= area;
        }
        Point2::new(
            self.rng.random_range(chosen.0.x..chosen.1.x),
            self.rng.random_range(chosen.0.y..chosen.1.y),
        )
    }

    /// The half-size and build of a new piece of `class`, scaled by U(0.8, 1.2); `None` for
    /// classes that are not furniture. A chair may be an office chair
    /// ([`super::WorldConfig::office_chairs`]), whose half-size is its base's radius, and a
    /// desk a round table ([`super::WorldConfig::round_tables`]), whose half-size is its top's.
    pub(super) fn piece_shape(&mut self, class: ObjectClass) -> Option<((f32, f32), Build)> {
        let scale = self.rng.random_range(0.8..1.2f32);
        match class {
            ObjectClass::Chair => {
                let half = (0.2 * scale, 0.2 * scale);
                if self.office_share > 0.0 && self.style.random_bool(self.office_share) {
                    let r = super::variety::star_radius(half);
                    Some(((r, r), Build::OfficeChair))
                } else {
                    Some((half, Build::Legs(0.015 * scale)))
                }
            }
            ObjectClass::Desk => {
                if self.round_share > 0.0 && self.style.random_bool(self.round_share) {
                    let r = super::variety::round_top_radius(scale);
                    Some(((r, r), Build::RoundTable))
                } else {
                    Some(((0.8 * scale, 0.4 * scale), Build::Legs(0.025 * scale)))
                }
            }
            ObjectClass::Box => {
                if self.box_share > 0.0 && self.style.random_bool(self.box_share) {
                    let (long, deep) = (self.style.random(), self.style.random());
                    Some((super::variety::box_half(long, deep), Build::Solid))
                } else {
                    Some(((0.3 * scale, 0.2 * scale), Build::Solid))
                }
            }
            ObjectClass::DoorFrame => None,
        }
    }

    /// Builds a piece of `class` at `c` turned by `yaw`, records its truth and keep-out disc.
    pub(super) fn put(
        &mut self,
        class: ObjectClass,
        c: Point2,
        yaw: f32,
        half: (f32, f32),
        build: Build,
    ) {
        let id = Surface::Object(self.objects.len() as u16);
        let footprint = rect_corners(c, half, yaw);
        match build {
            Build::OfficeChair => self.office_chair(c, yaw, half.0, id),
            Build::RoundTable => self.round_table(c, yaw, half.0, id),
            Build::Legs(r) => {
                let refl = match class {
                    ObjectClass::Desk => self.rng.random_range(0.25..0.7),
                    _ => self.rng.random_range(0.35..0.9),
                };
                for leg_c in rect_corners(c, (half.0 - r, half.1 - r), yaw) {
                    self.circle(leg_c, r, id, refl);
                }
            }
            Build::Solid => {
                let mut refl = self.rng.random_range(0.55..0.9);
                if self.dark_box_share > 0.0 && self.style.random_bool(self.dark_box_share) {
                    refl = self
                        .style
                        .random_range(super::variety::DARK_BOX_REFLECTIVITY);
                }
                self.polygon(&footprint, id, refl);
            }
        }
        self.objects.push(ObjectTruth {
            class,
            centre: c,
            yaw,
            footprint,
        });
        self.keep_out
            .push((c, (half.0 * half.0 + half.1 * half.1).sqrt()));
    }

    /// A piece of `class` anywhere on the floor, [`CLEARANCE`] from everything else.
    pub(super) fn furniture(&mut self, class: ObjectClass) -> bool {
        let Some((half, build)) = self.piece_shape(class) else {
            return false;
        };
        let radius = (half.0 * half.0 + half.1 * half.1).sqrt();
        for _ in 0..60 {
            let c = self.random_floor_point();
            if !self.fits(c, radius, CLEARANCE) {
                continue;
            }
            let yaw = self
                .rng
                .random_range(-core::f32::consts::PI..core::f32::consts::PI);
            self.put(class, c, yaw, half, build);
            return true;
        }
        false
    }

    pub(super) fn clutter_item(&mut self) {
        let kind = ["bin", "pillar", "legs"][self.rng.random_range(0..3)];
        let r = match kind {
            "bin" => self.rng.random_range(0.12..0.2),
            "pillar" => self.rng.random_range(0.1..0.25),
            _ => 0.2,
        };
        for _ in 0..40 {
            let c = self.random_floor_point();
            if !self.fits(c, r, CLEARANCE) {
                continue;
            }
            let id = Surface::Clutter(self.clutter.len() as u16);
            match kind {
                "legs" => {
                    let yaw: f32 = self.rng.random_range(0.0..core::f32::consts::PI);
                    let refl = self.rng.random_range(0.2..0.7);
                    let lr = self.rng.random_range(0.05..0.07);
                    let (s, co) = yaw.sin_cos();
                    self.circle(Point2::new(c.x + co * 0.1, c.y + s * 0.1), lr, id, refl);
                    self.circle(Point2::new(c.x - co * 0.1, c.y - s * 0.1), lr, id, refl);
                }
                _ => {
                    let refl = self.rng.random_range(0.4..0.95);
                    self.circle(c, r, id, refl);
                }
            }
            self.clutter.push(ClutterTruth { kind, centre: c });
            self.keep_out.push((c, r));
            return;
        }
    }
}

/// `true` if `p` is strictly inside one of the floor rectangles `floor` (min, max).
pub(super) fn on_floor(floor: &[(Point2, Point2)], p: Point2) -> bool {
    floor
        .iter()
        .any(|(lo, hi)| p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y)
}

/// `true` if `p` is inside the convex quadrilateral `q` (counter-clockwise).
pub(super) fn inside(q: &[Point2; 4], p: Point2) -> bool {
    (0..4).all(|i| {
        let (a, b) = (q[i], q[(i + 1) % 4]);
        (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x) >= 0.0
    })
}
