//! The annex's LiDAR: which surface a beam meets and whether, and how, it comes back.
//!
//! Deliberately not the simulator's reading model. A return is drawn with probability
//! `reflectivity^0.7 · cos(incidence)^0.6 · falloff(range)` (nothing below a 5° grazing angle),
//! where the falloff is 1 up to 2.6 m and fades to 0.08 at 3.5 m and to nothing by 5 m, so
//! walls seen obliquely or far away break into sparse dashes. The beam is 0.9° wide: where its
//! edges fall on surfaces more than 0.15 m apart in range, a third of the returns are mixed
//! pixels somewhere between the two. Range noise grows with range (σ = 5 mm + 0.6 %), and one
//! reading in 500 is a spurious return at a random range (dust, sunlight).

use perception::geometry::Point2;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::plan::{Owner, Prim};

/// What one beam did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// Range sent, metres (0 = no return).
    pub range_m: f32,
    /// Intensity sent.
    pub intensity: u16,
    /// What the beam's centre hit and at what true range (returned or not).
    pub hit: Option<(Owner, f32)>,
    /// Whether the range sent is a real return of `hit` (not mixed, not spurious).
    pub clean: bool,
}

/// Nearest hit of the ray `o + t·d` among `prims`: (range, cos incidence, owner, reflectivity).
pub fn cast(prims: &[Prim], o: Point2, d: Point2) -> Option<(f32, f32, Owner, f32)> {
    let mut best: Option<(f32, f32, Owner, f32)> = None;
    for p in prims {
        if let Some((t, cos)) = p.shape.intersect(o, d)
            && best.is_none_or(|b| t < b.0)
        {
            best = Some((t, cos, p.owner, p.refl));
        }
    }
    best
}

fn falloff(r: f32) -> f32 {
    if r <= 2.6 {
        1.0
    } else if r <= 3.5 {
        1.0 - (r - 2.6) / 0.9 * 0.92
    } else if r <= 5.0 {
        0.08 * (5.0 - r) / 1.5
    } else {
        0.0
    }
}

/// One beam from `o` at `angle` (radians) through `prims`.
pub fn beam(rng: &mut ChaCha8Rng, prims: &[Prim], o: Point2, angle: f32) -> Beam {
    let dir = |a: f32| Point2::new(a.cos(), a.sin());
    let centre = cast(prims, o, dir(angle));
    let hit = centre.map(|(t, _, owner, _)| (owner, t));
    if rng.random_bool(0.002) {
        return Beam {
            range_m: rng.random_range(0.15..3.0),
            intensity: rng.random_range(50..400),
            hit,
            clean: false,
        };
    }
    let Some((t, cos, _, refl)) = centre else {
        return Beam {
            range_m: 0.0,
            intensity: 0,
            hit,
            clean: false,
        };
    };
    let p = if cos < 0.087 {
        0.0
    } else {
        refl.powf(0.7) * cos.powf(0.6) * falloff(t)
    };
    if !rng.random_bool(f64::from(p.clamp(0.0, 1.0))) {
        return Beam {
            range_m: 0.0,
            intensity: 0,
            hit,
            clean: false,
        };
    }
    let noisy = |rng: &mut ChaCha8Rng, r: f32| {
        let sigma = 0.005 + 0.006 * r;
        // Box–Muller from two uniforms.
        let (u1, u2): (f32, f32) = (rng.random_range(1e-6..1.0), rng.random_range(0.0..1.0));
        r + sigma * (-2.0 * u1.ln()).sqrt() * (core::f32::consts::TAU * u2).cos()
    };
    let intensity = (150.0 + 2500.0 * refl * cos / (0.4 + t)) as u16;
    // Mixed pixel: the beam's other edge on a surface far from this one.
    let half = 0.45f32.to_radians();
    let edge = if rng.random_bool(0.5) { half } else { -half };
    if let Some((t2, ..)) = cast(prims, o, dir(angle + edge))
        && (t2 - t).abs() > 0.15
        && rng.random_bool(0.33)
    {
        let u = rng.random_range(0.15..0.85f32);
        return Beam {
            range_m: noisy(rng, t + u * (t2 - t)),
            intensity: intensity / 2,
            hit,
            clean: false,
        };
    }
    Beam {
        range_m: noisy(rng, t),
        intensity,
        hit,
        clean: true,
    }
}

/// Whether the segment `o → q` crosses the convex `poly` (sampled every 3 cm, stopping 5 cm
/// short of `q`).
pub fn passes_through(poly: &[Point2], o: Point2, q: Point2) -> bool {
    let len = o.distance(q) - 0.05;
    if len <= 0.0 {
        return false;
    }
    let n = (len / 0.03).ceil() as usize;
    let d = Point2::new((q.x - o.x) / o.distance(q), (q.y - o.y) / o.distance(q));
    (0..=n).any(|i| {
        let s = len * i as f32 / n as f32;
        crate::run_truth::polygon_distance(poly, Point2::new(o.x + d.x * s, o.y + d.y * s)) == 0.0
    })
}
