//! What a *varied* world ([`super::WorldConfig::varied`]) adds to the study's world: the wall
//! geometry and the clutter that a detector trained on the study's rooms alone mistakes for
//! furniture, and furniture where rooms really keep it.
//!
//! * doorways from [`DOOR_WIDTH_MIN`] (door standards: a DIN 18101 0.885 m leaf leaves about
//!   0.8 m clear) and up to a corner; open door leaves (a thin panel hinged on a jamb);
//! * partition stubs: short walls standing into the room, whose ends a scan sees as a blob;
//! * furniture against walls (desks long side to the wall; chairs and boxes either way), and
//!   chairs tucked at desks (part under the desk's edge, or just pulled out);
//! * clutter that hugs walls (shelves, radiators) and square pillars (free or as a pilaster),
//!   besides the study's bins, round pillars and standing legs;
//! * office chairs on request ([`super::WorldConfig::office_chairs`] of the chairs; none by
//!   default) on a five-star base 0.5–0.7 m across:
//!   at LiDAR height a scan cuts the gas column (5–8 cm) and the base's five arms at one
//!   radius, where they rise through the scan plane from the casters to the hub; on request
//!   ([`super::WorldConfig::office_spokes`]) a share of them with the arms in the scan plane,
//!   each seen whole, as a LiDAR at the hub's height sees them. Drawn from the world's own
//!   `style` stream;
//! * round tables on request ([`super::WorldConfig::round_tables`] of the desks; none by
//!   default), 0.7–1.1 m across on three or four legs (2–5 cm) set 5–12 cm in from the top's
//!   edge. A pedestal table would show its column alone at LiDAR height, a post like any
//!   other (the office chair's lesson): not drawn. From the `style` stream too;
//! * boxes of other sizes on request ([`super::WorldConfig::box_sizes`] of the boxes; none by
//!   default): sides of their own, square ones too ([`box_half`]); and dark boxes
//!   ([`super::WorldConfig::dark_boxes`], [`DARK_BOX_REFLECTIVITY`]). From the `style` stream.
//!
//! Wall thickness (0.05–0.25 m) and reflectivity (0.12–1.0) are drawn in `build.rs`; the
//! LiDAR's reach and dropouts in `Lds01SimConfig::varied`. Everything here draws from the
//! world's own random stream, so a varied world is as reproducible as any other.

use core::f32::consts::{FRAC_PI_2, PI};

use perception::class::ObjectClass;
use perception::geometry::Point2;
use rand::Rng;

use super::build::{Builder, rect_corners};
use super::{CLEARANCE, ClutterTruth, Surface};

/// Narrowest doorway of a varied world, metres.
pub const DOOR_WIDTH_MIN: f32 = 0.75;

/// Space kept between a wall-side piece and everything else, metres.
const WALL_SIDE_GAP: f32 = 0.35;

/// The radius of a five-star base for a chair drawn with half-sizes `half` (0.16–0.24 m): 0.25–0.35
/// m, the 0.5–0.7 m bases office chairs stand on.
pub(super) fn star_radius(half: (f32, f32)) -> f32 {
    (half.0.max(half.1) * 1.45).clamp(0.25, 0.35)
}

/// Half-sides of a box with sides of its own, from two uniform draws `long_u`, `deep_u` in
/// [0, 1): 0.3–0.9 m along, and across from 0.25 m up to the lesser of its length and 0.6 m.
/// The study's boxes are one shape (0.48–0.72 × 0.32–0.48, always 3 : 2); boxes in rooms are
/// storage and moving boxes (0.3–0.6 m, many square), crates and low cabinets up to 0.9 m
/// long. General sizes; nobody read the evaluation annex's generator for them.
pub(super) fn box_half(long_u: f32, deep_u: f32) -> (f32, f32) {
    let long = 0.3 + 0.6 * long_u.clamp(0.0, 1.0);
    let deep_max = long.min(0.6);
    let deep = 0.25 + (deep_max - 0.25) * deep_u.clamp(0.0, 1.0);
    (long / 2.0, deep / 2.0)
}

/// Reflectivity of a dark box ([`super::WorldConfig::dark_boxes`]): black plastic crates
/// reflect a few per cent of the light, brown cardboard about a third to a half.
pub(super) const DARK_BOX_REFLECTIVITY: core::ops::Range<f32> = 0.05..0.5;

/// The top's radius of a round table drawn at `scale` (0.8–1.2): 0.35–0.55 m.
pub(super) fn round_top_radius(scale: f32) -> f32 {
    (0.45 * scale).clamp(0.35, 0.55)
}

/// A spot against a wall: the centre and yaw of a rectangle with half-sizes `half` whose
/// `half.0` side runs along the wall (or across it when `across`), `0..gap_max` m off the
/// wall's face.
struct WallSpot {
    centre: Point2,
    yaw: f32,
    /// The wall's inward normal (into the room).
    inward: Point2,
}

impl Builder {
    /// `true` if `p` is strictly inside a floor rectangle.
    fn on_floor(&self, p: Point2) -> bool {
        super::build::on_floor(&self.floor, p)
    }

    /// Finds a place against a real wall (not the open side between two floor rectangles)
    /// for a rectangle of half-sizes `half`, clear of everything placed by `spacing`.
    fn wall_spot(
        &mut self,
        half: (f32, f32),
        across: bool,
        gap_max: f32,
        spacing: f32,
    ) -> Option<WallSpot> {
        let (hw, hn) = if across { (half.1, half.0) } else { half };
        let radius = (half.0 * half.0 + half.1 * half.1).sqrt();
        for _ in 0..30 {
            let (lo, hi) = self.floor[self.rng.random_range(0..self.floor.len())];
            let side = self.rng.random_range(0..4u8);
            // The wall's face point at `t`, its inward normal, and the run of `t`.
            let (origin, along, inward, run) = match side {
                0 => (
                    lo,
                    Point2::new(1.0, 0.0),
                    Point2::new(0.0, 1.0),
                    hi.x - lo.x,
                ),
                1 => (
                    Point2::new(hi.x, lo.y),
                    Point2::new(0.0, 1.0),
                    Point2::new(-1.0, 0.0),
                    hi.y - lo.y,
                ),
                2 => (
                    Point2::new(lo.x, hi.y),
                    Point2::new(1.0, 0.0),
                    Point2::new(0.0, -1.0),
                    hi.x - lo.x,
                ),
                _ => (
                    lo,
                    Point2::new(0.0, 1.0),
                    Point2::new(1.0, 0.0),
                    hi.y - lo.y,
                ),
            };
            if run < 2.0 * hw + 0.2 {
                continue;
            }
            let t = self.rng.random_range(hw + 0.1..run - hw - 0.1);
            let jitter = self.rng.random_range(-0.04..0.04f32);
            let off = hn + self.rng.random_range(0.01..gap_max.max(0.011)) + jitter.abs() * hw;
            let at = |s: f32, n: f32| {
                Point2::new(
                    origin.x + along.x * s + inward.x * n,
                    origin.y + along.y * s + inward.y * n,
                )
            };
            // A wall behind the whole piece: just beyond the face is off the floor.
            if [t - hw, t, t + hw]
                .iter()
                .any(|&s| self.on_floor(at(s, -0.05)))
            {
                continue;
            }
            let centre = at(t, off);
            if !self
                .keep_out
                .iter()
                .all(|(o, or)| centre.distance(*o) >= radius + or + spacing)
            {
                continue;
            }
            let wall_dir =
                along.y.atan2(along.x) + if self.rng.random_bool(0.5) { PI } else { 0.0 };
            let yaw = wall_dir + if across { FRAC_PI_2 } else { 0.0 } + jitter;
            return Some(WallSpot {
                centre,
                yaw,
                inward,
            });
        }
        None
    }

    /// A piece of `class` in a varied world: against a wall 45 % of the time (else, or if no
    /// wall has room, anywhere), and a desk gets a chair tucked at it half the time.
    pub(super) fn furniture_varied(&mut self, class: ObjectClass) -> bool {
        let placed =
            (self.rng.random_bool(0.45) && self.against_wall(class)) || self.furniture(class);
        if placed && class == ObjectClass::Desk && self.rng.random_bool(0.5) {
            self.tucked_chair();
        }
        placed
    }

    /// A piece of `class` 1–8 cm off a wall.
    fn against_wall(&mut self, class: ObjectClass) -> bool {
        let Some((half, build)) = self.piece_shape(class) else {
            return false;
        };
        let across = class != ObjectClass::Desk && self.rng.random_bool(0.4);
        match self.wall_spot(half, across, 0.08, WALL_SIDE_GAP) {
            Some(s) => {
                self.put(class, s.centre, s.yaw, half, build);
                true
            }
            None => false,
        }
    }

    /// An office chair at `c` whose base, of radius `radius`, has an arm at `yaw`: the gas
    /// column, and the five arms where the scan plane cuts them (an arm climbs from its caster
    /// to the hub, so the plane cuts each at one radius). A base that stays wholly below the
    /// plane would show the column alone, a post nothing tells from any other: not drawn,
    /// because a forest trained on such chairs took posts and people's legs for chairs
    /// (`docs/world.md`, 18th session).
    ///
    /// A share of them ([`super::WorldConfig::office_spokes`]) lie in the scan plane instead:
    /// five flat arms 4–6 cm wide from the hub to 0–4 cm short of the base's radius, each seen
    /// whole.
    pub(super) fn office_chair(&mut self, c: Point2, yaw: f32, radius: f32, id: Surface) {
        let column = self.style.random_range(0.025..0.04f32);
        let refl = self.style.random_range(0.3..0.9f32);
        self.circle(c, column, id, refl);
        if self.spoke_share > 0.0 && self.style.random_bool(self.spoke_share) {
            self.flat_arms(c, yaw, radius, column, id);
        } else {
            self.cut_arms(c, yaw, radius, id);
        }
    }

    /// The five arms of an office chair's base where the scan plane cuts them, at one radius.
    fn cut_arms(&mut self, c: Point2, yaw: f32, radius: f32, id: Surface) {
        let cut = self.style.random_range(0.1..radius - 0.04);
        let arm = self.style.random_range(0.018..0.028f32);
        let refl = self.style.random_range(0.15..0.9f32);
        for k in 0..5 {
            let a = yaw + k as f32 * (2.0 * PI / 5.0);
            let p = Point2::new(c.x + cut * a.cos(), c.y + cut * a.sin());
            self.circle(p, arm, id, refl);
        }
    }

    /// The five arms of an office chair's base lying in the scan plane, each seen whole: 4–6
    /// cm wide, from the column (`column` m) to 0–4 cm short of the base's `radius`.
    fn flat_arms(&mut self, c: Point2, yaw: f32, radius: f32, column: f32, id: Surface) {
        let half_w = self.style.random_range(0.02..0.03f32);
        let reach = radius - self.style.random_range(0.0..0.04f32);
        let refl = self.style.random_range(0.15..0.9f32);
        for k in 0..5 {
            let a = yaw + k as f32 * (2.0 * PI / 5.0);
            let (s, co) = a.sin_cos();
            let at = |r: f32, w: f32| Point2::new(c.x + r * co - w * s, c.y + r * s + w * co);
            let arm = [
                at(column, -half_w),
                at(reach, -half_w),
                at(reach, half_w),
                at(column, half_w),
            ];
            self.polygon(&arm, id, refl);
        }
    }

    /// A round table at `c` whose top has radius `radius`: three or four legs evenly round a
    /// circle 5–12 cm inside the top's edge, the first at `yaw`.
    pub(super) fn round_table(&mut self, c: Point2, yaw: f32, radius: f32, id: Surface) {
        let legs = if self.style.random_bool(0.5) { 3 } else { 4 };
        let leg = self.style.random_range(0.012..0.025f32);
        let at = radius - self.style.random_range(0.05..0.12f32);
        let refl = self.style.random_range(0.25..0.8f32);
        for k in 0..legs {
            let a = yaw + k as f32 * (2.0 * PI / legs as f32);
            let p = Point2::new(c.x + at * a.cos(), c.y + at * a.sin());
            self.circle(p, leg, id, refl);
        }
    }

    /// A chair at the last desk placed: from a third under its edge to a little pulled out,
    /// on a side with floor, clear of the desk's legs.
    fn tucked_chair(&mut self) {
        let Some(desk) = self.objects.last().cloned() else {
            return;
        };
        let Some((ch, build)) = self.piece_shape(ObjectClass::Chair) else {
            return;
        };
        let fp = desk.footprint;
        let (hx, hy) = (fp[0].distance(fp[1]) / 2.0, fp[1].distance(fp[2]) / 2.0);
        let (s, c) = desk.yaw.sin_cos();
        let reach = hx - ch.0 - 0.15;
        if reach <= 0.0 {
            return;
        }
        let u = self.rng.random_range(-reach..reach);
        let f = self.rng.random_range(-0.3..1.4f32);
        let yaw = desk.yaw + self.rng.random_range(-0.25..0.25f32);
        let first = if self.rng.random_bool(0.5) { 1.0 } else { -1.0 };
        for side in [first, -first] {
            let d = side * (hy + ch.1 * f);
            let centre = Point2::new(desk.centre.x + c * u - s * d, desk.centre.y + s * u + c * d);
            let corners = rect_corners(centre, (ch.0 + 0.05, ch.1 + 0.05), yaw);
            let radius = (ch.0 * ch.0 + ch.1 * ch.1).sqrt();
            let others = &self.keep_out[..self.keep_out.len().saturating_sub(1)];
            if corners.iter().all(|&p| self.on_floor(p))
                && others
                    .iter()
                    .all(|(o, or)| centre.distance(*o) >= radius + or + 0.3)
            {
                self.put(ObjectClass::Chair, centre, yaw, ch, build);
                return;
            }
        }
    }

    /// One clutter item of a varied world: the study's three kinds, or a shelf or radiator
    /// against a wall, or a square pillar (free, or as a pilaster on a wall).
    pub(super) fn clutter_varied(&mut self) {
        match self.rng.random_range(0..6u8) {
            0..=2 => self.clutter_item(),
            3 => {
                let half = (
                    self.rng.random_range(0.35..1.0f32),
                    self.rng.random_range(0.12..0.22f32),
                );
                self.wall_clutter("shelf", half, 0.03);
            }
            4 => {
                let half = (
                    self.rng.random_range(0.25..0.75f32),
                    self.rng.random_range(0.03..0.06f32),
                );
                self.wall_clutter("radiator", half, 0.06);
            }
            _ => {
                let h = self.rng.random_range(0.07..0.17f32);
                if self.rng.random_bool(0.5) {
                    self.wall_clutter("square pillar", (h, h), 0.0);
                } else {
                    self.free_square_pillar(h);
                }
            }
        }
    }

    /// A solid rectangle of clutter `kind` against a wall.
    fn wall_clutter(&mut self, kind: &'static str, half: (f32, f32), gap_max: f32) {
        if let Some(s) = self.wall_spot(half, false, gap_max, 0.2) {
            let id = Surface::Clutter(self.clutter.len() as u16);
            let refl = self.rng.random_range(0.2..0.95);
            self.polygon(&rect_corners(s.centre, half, s.yaw), id, refl);
            self.clutter.push(ClutterTruth {
                kind,
                centre: s.centre,
            });
            self.keep_out
                .push((s.centre, (half.0 * half.0 + half.1 * half.1).sqrt()));
        }
    }

    /// A free-standing square pillar of half-side `h`.
    fn free_square_pillar(&mut self, h: f32) {
        let r = h * core::f32::consts::SQRT_2;
        for _ in 0..40 {
            let c = self.random_floor_point();
            if !self.fits(c, r, CLEARANCE) {
                continue;
            }
            let yaw = self.rng.random_range(0.0..FRAC_PI_2);
            let id = Surface::Clutter(self.clutter.len() as u16);
            let refl = self.rng.random_range(0.3..0.95);
            self.polygon(&rect_corners(c, (h, h), yaw), id, refl);
            self.clutter.push(ClutterTruth {
                kind: "square pillar",
                centre: c,
            });
            self.keep_out.push((c, r));
            return;
        }
    }

    /// 0–2 partition stubs: walls 0.4–2 m long standing into the room from a wall, clear of
    /// doorways.
    pub(super) fn stubs(&mut self) {
        for _ in 0..self.rng.random_range(0..=2u8) {
            let len = self.rng.random_range(0.4..2.0f32);
            let t = self.wall_t;
            // A stub is a thin rectangle across the wall: long side `len` into the room.
            let half = (t / 2.0, len / 2.0);
            let Some(s) = self.wall_spot((len / 2.0, t / 2.0), true, 0.011, 0.5) else {
                continue;
            };
            // `wall_spot` put it 1 cm off the face; a stub is built into the wall.
            let (sn, cn) = s.yaw.sin_cos();
            let centre = Point2::new(
                s.centre.x - s.inward.x * 0.02,
                s.centre.y - s.inward.y * 0.02,
            );
            let refl = self.wall_reflectivity();
            self.polygon(
                &rect_corners(centre, (half.1 + 0.02, half.0), s.yaw),
                Surface::Wall,
                refl,
            );
            // Keep furniture off it: discs along its length.
            let n = (len / 0.4).ceil() as usize;
            for i in 0..=n {
                let k = i as f32 / n as f32 - 0.5;
                let p = Point2::new(centre.x + cn * len * k, centre.y + sn * len * k);
                self.keep_out.push((p, 0.2 + t));
            }
        }
    }

    /// An open door leaf in the gap from `a` to `b` (a wall along `dir`, outside `outward`):
    /// hinged on one jamb, swung 60–110° into the room or out of it.
    pub(super) fn door_leaf(&mut self, a: Point2, b: Point2, dir: Point2, outward: Point2) {
        let width = a.distance(b) * 0.95;
        let (hinge, toward) = if self.rng.random_bool(0.5) {
            (a, dir)
        } else {
            (b, Point2::new(-dir.x, -dir.y))
        };
        let (hinge, side) = if self.rng.random_bool(0.5) {
            (hinge, Point2::new(-outward.x, -outward.y))
        } else {
            (
                Point2::new(
                    hinge.x + outward.x * self.wall_t,
                    hinge.y + outward.y * self.wall_t,
                ),
                outward,
            )
        };
        let angle = self.rng.random_range(60.0f32..110.0).to_radians();
        let (sa, ca) = angle.sin_cos();
        let u = Point2::new(toward.x * ca + side.x * sa, toward.y * ca + side.y * sa);
        let mid = Point2::new(hinge.x + u.x * width / 2.0, hinge.y + u.y * width / 2.0);
        let refl = self.rng.random_range(0.3..0.9);
        self.polygon(
            &rect_corners(mid, (width / 2.0, 0.02), u.y.atan2(u.x)),
            Surface::Wall,
            refl,
        );
        self.keep_out.push((mid, width / 2.0));
    }
}

#[cfg(test)]
mod test {
    use super::super::build::inside;
    use super::super::{Shape, Surface, World, WorldConfig};
    use super::*;

    fn varied() -> WorldConfig {
        WorldConfig {
            varied: 1.0,
            max_clutter: 6,
            ..WorldConfig::default()
        }
    }

    /// Whether segments `a–b` and `c–d` cross.
    fn crosses(a: Point2, b: Point2, c: Point2, d: Point2) -> bool {
        let side =
            |p: Point2, q: Point2, r: Point2| (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
        side(a, b, c) * side(a, b, d) < 0.0 && side(c, d, a) * side(c, d, b) < 0.0
    }

    #[test]
    fn drawn_only_when_asked_and_reproducible() {
        for seed in 0..30 {
            let a = World::generate(seed, &varied());
            assert!(a.varied);
            assert_eq!(a.prims, World::generate(seed, &varied()).prims);
            assert!(!World::generate(seed, &WorldConfig::default()).varied);
        }
    }

    #[test]
    fn furniture_against_walls_and_at_desks_touches_nothing_else() {
        let (mut pieces, mut against, mut tucked) = (0, 0, 0);
        for seed in 0..80 {
            let w = World::generate(seed, &varied());
            assert!(w.on_floor(w.robot_start));
            assert!(w.clearance(w.robot_start) >= 0.5, "seed {seed}");
            for d in &w.doors {
                assert!(d.width >= DOOR_WIDTH_MIN - 1e-4, "seed {seed}: {}", d.width);
            }
            // No two round things (legs, bins, pillars) of different owners intersect.
            for (k, p) in w.prims.iter().enumerate() {
                for q in &w.prims[k + 1..] {
                    if let (Shape::Circle { c: a, r: ra }, Shape::Circle { c: b, r: rb }) =
                        (p.shape, q.shape)
                    {
                        assert!(
                            p.surface == q.surface || a.distance(b) > ra + rb,
                            "seed {seed}: {:?} and {:?} intersect",
                            p.surface,
                            q.surface
                        );
                    }
                }
            }
            for (i, o) in w.objects.iter().enumerate() {
                pieces += 1;
                let fp = o.footprint;
                assert!(
                    fp.iter().all(|&c| w.on_floor(c)),
                    "seed {seed} piece {i} off the floor"
                );
                for p in &w.prims {
                    if p.surface == Surface::Object(i as u16) {
                        continue;
                    }
                    // A tucked chair's legs may stand under its desk (checked leg by leg below).
                    if let Surface::Object(j) = p.surface {
                        let other = w.objects[usize::from(j)].class;
                        if [o.class, other].contains(&ObjectClass::Desk)
                            && [o.class, other].contains(&ObjectClass::Chair)
                        {
                            continue;
                        }
                    }
                    let hit = match p.shape {
                        Shape::Circle { c, .. } => inside(&fp, c),
                        Shape::Segment { a, b } => {
                            inside(&fp, a)
                                || inside(&fp, b)
                                || (0..4).any(|k| crosses(a, b, fp[k], fp[(k + 1) % 4]))
                        }
                    };
                    assert!(
                        !hit,
                        "seed {seed}: piece {i} overlaps {:?} {:?}",
                        p.surface, p.shape
                    );
                }
                let to_wall = w
                    .prims
                    .iter()
                    .filter(|p| p.surface == Surface::Wall)
                    .flat_map(|p| fp.iter().map(|&c| p.shape.distance(c)))
                    .fold(f32::INFINITY, f32::min);
                if to_wall < 0.12 {
                    against += 1;
                }
                if o.class == ObjectClass::Chair
                    && w.objects.iter().any(|d| {
                        d.class == ObjectClass::Desk
                            && (0..4).any(|k| {
                                Shape::Segment {
                                    a: d.footprint[k],
                                    b: d.footprint[(k + 1) % 4],
                                }
                                .distance(o.centre)
                                    < 0.35
                            })
                    })
                {
                    tucked += 1;
                }
            }
        }
        // 45 % of tries go to a wall when one has room; half the desks get a chair.
        assert!(
            against * 5 >= pieces,
            "{against} of {pieces} against a wall"
        );
        assert!(tucked >= 20, "{tucked} chairs at desks in {pieces} pieces");
    }

    /// The primitives piece `i` of `w` is built of.
    fn shapes(w: &World, i: usize) -> impl Iterator<Item = Shape> + '_ {
        w.prims
            .iter()
            .filter(move |p| p.surface == Surface::Object(i as u16))
            .map(|p| p.shape)
    }

    /// The round things a piece is built of.
    fn circles(w: &World, i: usize) -> Vec<(Point2, f32)> {
        shapes(w, i)
            .filter_map(|s| match s {
                Shape::Circle { c, r } => Some((c, r)),
                Shape::Segment { .. } => None,
            })
            .collect()
    }

    /// The straight sides of piece `i` of `w`, as (a, b) pairs.
    fn segments(w: &World, i: usize) -> Vec<(Point2, Point2)> {
        shapes(w, i)
            .filter_map(|s| match s {
                Shape::Segment { a, b } => Some((a, b)),
                Shape::Circle { .. } => None,
            })
            .collect()
    }

    #[test]
    fn office_chairs_stand_on_five_arms_in_varied_worlds_when_asked() {
        let office = WorldConfig {
            office_chairs: 0.4,
            ..varied()
        };
        let (mut chairs, mut office_chairs) = (0, 0);
        for seed in 0..80 {
            let w = World::generate(seed, &office);
            for (i, o) in w.objects.iter().enumerate() {
                if o.class != ObjectClass::Chair {
                    continue;
                }
                chairs += 1;
                let parts = circles(&w, i);
                let column = parts
                    .iter()
                    .any(|&(c, r)| c.distance(o.centre) < 1e-4 && r >= 0.025);
                match parts.len() {
                    4 => assert!(!column, "seed {seed}: a legged chair has no column"),
                    6 => {
                        assert!(column, "seed {seed} piece {i}: {parts:?}");
                        // Five arms at one radius inside the base, 72° apart.
                        let arms: Vec<_> = parts.iter().filter(|p| p.0 != o.centre).collect();
                        let r0 = arms[0].0.distance(o.centre);
                        let half = o.footprint[0].distance(o.footprint[1]) / 2.0;
                        assert!((0.1..half).contains(&r0), "seed {seed}: arms at {r0} m");
                        for (k, a) in arms.iter().enumerate() {
                            let b = arms[(k + 1) % 5];
                            assert!((a.0.distance(o.centre) - r0).abs() < 1e-3);
                            let chord = 2.0 * r0 * (PI / 5.0).sin();
                            assert!((a.0.distance(b.0) - chord).abs() < 1e-3);
                        }
                        office_chairs += 1;
                    }
                    n => panic!("seed {seed} piece {i}: a chair of {n} round parts"),
                }
            }
            // Unless asked for, and in worlds drawn without variety, there are none, and
            // the world is the one it always was.
            let plain = World::generate(seed, &varied());
            let study = World::generate(
                seed,
                &WorldConfig {
                    office_chairs: 0.4,
                    ..WorldConfig::default()
                },
            );
            assert_eq!(
                study.prims,
                World::generate(seed, &WorldConfig::default()).prims
            );
            for w in [&plain, &study] {
                for (i, o) in w.objects.iter().enumerate() {
                    if o.class == ObjectClass::Chair {
                        assert_eq!(circles(w, i).len(), 4, "seed {seed}");
                    }
                }
            }
        }
        // 40 % of the chairs.
        assert!(
            office_chairs * 5 >= chairs && office_chairs * 5 <= chairs * 3,
            "{office_chairs} office chairs of {chairs}"
        );
    }

    #[test]
    fn office_chairs_arms_lie_in_the_scan_plane_when_asked() {
        let spokes = WorldConfig {
            office_chairs: 1.0,
            office_spokes: 0.5,
            ..varied()
        };
        let (mut chairs, mut flat) = (0, 0);
        for seed in 0..60 {
            let w = World::generate(seed, &spokes);
            for (i, o) in w.objects.iter().enumerate() {
                if o.class != ObjectClass::Chair {
                    continue;
                }
                chairs += 1;
                let segs = segments(&w, i);
                match (circles(&w, i).len(), segs.len()) {
                    (6, 0) => {}
                    (1, 20) => {
                        // Five arms 4–6 cm wide from the column out to the base's radius.
                        let half = o.footprint[0].distance(o.footprint[1]) / 2.0;
                        let far = segs
                            .iter()
                            .map(|&(a, _)| a.distance(o.centre))
                            .fold(0.0f32, f32::max);
                        assert!(far <= half + 0.031 && far >= half - 0.05, "{far} of {half}");
                        for arm in segs.chunks(4) {
                            let width = arm[1].0.distance(arm[1].1);
                            assert!((0.039..0.061).contains(&width), "arm {width} m wide");
                        }
                        flat += 1;
                    }
                    parts => panic!("seed {seed} piece {i}: {parts:?}"),
                }
            }
            // Without office chairs nothing changes.
            let none = WorldConfig {
                office_spokes: 0.5,
                ..varied()
            };
            assert_eq!(
                World::generate(seed, &none).prims,
                World::generate(seed, &varied()).prims
            );
        }
        assert!(
            flat * 4 >= chairs && flat * 4 <= chairs * 3,
            "{flat} of {chairs}"
        );
    }

    #[test]
    fn round_tables_stand_on_three_or_four_legs_in_varied_worlds_when_asked() {
        let round = WorldConfig {
            round_tables: 0.5,
            ..varied()
        };
        let (mut desks, mut tables) = (0, 0);
        for seed in 0..80 {
            let w = World::generate(seed, &round);
            for (i, o) in w.objects.iter().enumerate() {
                if o.class != ObjectClass::Desk {
                    continue;
                }
                desks += 1;
                let legs = circles(&w, i);
                let d: Vec<f32> = legs.iter().map(|l| l.0.distance(o.centre)).collect();
                let (w0, w1) = (
                    o.footprint[0].distance(o.footprint[1]),
                    o.footprint[1].distance(o.footprint[2]),
                );
                if (w0 - w1).abs() < 1e-3 {
                    // A round table: its legs on one circle inside the top, evenly spaced.
                    assert!(matches!(legs.len(), 3 | 4), "seed {seed}: {legs:?}");
                    let top = w0 / 2.0;
                    assert!((0.35..=0.55).contains(&top), "seed {seed}: top {top}");
                    for (k, l) in legs.iter().enumerate() {
                        assert!((d[k] - d[0]).abs() < 1e-3 && d[0] < top - 0.04);
                        assert!((0.012..0.025).contains(&l.1));
                        let next = legs[(k + 1) % legs.len()].0;
                        let chord = 2.0 * d[0] * (PI / legs.len() as f32).sin();
                        assert!((l.0.distance(next) - chord).abs() < 1e-3);
                    }
                    tables += 1;
                } else {
                    assert_eq!(legs.len(), 4, "seed {seed}: a desk's four legs");
                }
            }
            // Asked for in a world drawn without variety: the world is the one it always was.
            let study = WorldConfig {
                round_tables: 0.5,
                ..WorldConfig::default()
            };
            assert_eq!(
                World::generate(seed, &study).prims,
                World::generate(seed, &WorldConfig::default()).prims
            );
        }
        assert!(
            tables * 4 >= desks && tables * 4 <= desks * 3,
            "{tables} round tables of {desks} desks"
        );
    }

    #[test]
    fn boxes_take_sides_of_their_own_in_varied_worlds_when_asked() {
        let sized = WorldConfig {
            box_sizes: 0.5,
            ..varied()
        };
        let (mut boxes, mut own, mut squarish) = (0, 0, 0);
        for seed in 0..80 {
            let w = World::generate(seed, &sized);
            for o in w.objects.iter().filter(|o| o.class == ObjectClass::Box) {
                boxes += 1;
                let a = o.footprint[0].distance(o.footprint[1]);
                let b = o.footprint[1].distance(o.footprint[2]);
                let (long, deep) = (a.max(b), a.min(b));
                // The study's box: 0.48–0.72 × 0.32–0.48, always 3 : 2.
                let study = (long / deep - 1.5).abs() < 1e-3 && (0.479..0.721).contains(&long);
                if !study {
                    assert!((0.299..0.901).contains(&long), "seed {seed}: {long} m long");
                    assert!(
                        (0.249..=long.min(0.6) + 1e-3).contains(&deep),
                        "seed {seed}: {long} × {deep} m"
                    );
                    own += 1;
                    squarish += usize::from(long / deep < 1.2);
                }
            }
            // Asked for in a world drawn without variety: the world is the one it always was.
            let study = WorldConfig {
                box_sizes: 0.5,
                ..WorldConfig::default()
            };
            assert_eq!(
                World::generate(seed, &study).prims,
                World::generate(seed, &WorldConfig::default()).prims
            );
        }
        // Half the boxes, a fair share of them near square.
        assert!(own * 4 >= boxes && own * 4 <= boxes * 3, "{own} of {boxes}");
        assert!(squarish * 5 >= own, "{squarish} near square of {own}");
    }

    #[test]
    fn box_half_spans_its_sizes() {
        assert_eq!(box_half(0.0, 0.0), (0.15, 0.125));
        let (l, d) = box_half(1.0, 1.0);
        assert!((l - 0.45).abs() < 1e-6 && (d - 0.3).abs() < 1e-6);
        // Never deeper than long.
        let (l, d) = box_half(0.0, 1.0);
        assert!((l - d).abs() < 1e-6);
    }

    #[test]
    fn dark_boxes_are_drawn_dark_in_varied_worlds_when_asked() {
        let dark = WorldConfig {
            dark_boxes: 0.5,
            ..varied()
        };
        let (mut boxes, mut darker) = (0, 0);
        for seed in 0..80 {
            let w = World::generate(seed, &dark);
            let plain = World::generate(seed, &varied());
            // The same world but for the boxes' reflectivity.
            assert_eq!(w.prims.len(), plain.prims.len());
            for (p, q) in w.prims.iter().zip(&plain.prims) {
                assert_eq!((p.shape, p.surface), (q.shape, q.surface));
                let is_box = matches!(p.surface, Surface::Object(k)
                    if w.objects[usize::from(k)].class == ObjectClass::Box);
                if !is_box {
                    assert_eq!(p.reflectivity, q.reflectivity);
                } else if p.reflectivity != q.reflectivity {
                    assert!(DARK_BOX_REFLECTIVITY.contains(&p.reflectivity));
                    darker += 1;
                }
                boxes += usize::from(is_box);
            }
            let study = WorldConfig {
                dark_boxes: 0.5,
                ..WorldConfig::default()
            };
            assert_eq!(
                World::generate(seed, &study).prims,
                World::generate(seed, &WorldConfig::default()).prims
            );
        }
        // Half the boxes' faces (each box is four segments).
        assert!(
            darker * 4 >= boxes && darker * 4 <= boxes * 3,
            "{darker} of {boxes}"
        );
    }
}
