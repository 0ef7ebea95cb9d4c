//! A LiDAR that returns by the light it receives: the alternative reading model to
//! [`crate::lds01::Lds01SimConfig`]'s additive dropouts.
//!
//! The additive model loses a return with a base chance, plus a dark term `(1 − reflectivity)`,
//! plus a glancing term that starts only past 72° incidence: a dark face at 45° loses no more
//! than the same face head-on, and range plays no part inside the spec range. A real unit's
//! return depends on the light that comes back, which for a diffuse (Lambertian) surface is
//! the product `reflectivity · cos(incidence) / range²`, and the unit reads a range when that
//! clears its detection threshold through the spot's speckle and the receiver's noise. So here
//! the chance of a return is a logistic in the logarithm of the received power:
//!
//! `p = 1 / (1 + (P₅₀ / P)^(1/spread))`, `P = reflectivity · cos / r²` (r in metres),
//!
//! with `P₅₀` the power at which half the readings return and `spread` the threshold's noise in
//! natural-log units. The unit's numbers are drawn per scenario ([`ReceivedPower::draw`]) so
//! that a white wall head-on at the spec range returns (P = 1 / 3.5² ≈ 0.08) while a dark
//! face at a slant thins out well inside it. General LiDAR physics; the evaluation annex's
//! reading model was not copied (its form is documented in `docs/world.md`; this is not it).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A unit's detection threshold on the received power.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReceivedPower {
    /// Received power (reflectivity · cos / m²) at which half the readings return.
    pub half_power: f32,
    /// Noise of the threshold, natural-log units (smaller: a sharper edge).
    pub spread: f32,
}

impl ReceivedPower {
    /// A unit drawn from `seed`: half its readings return at a received power of 0.008–0.05
    /// (a white wall head-on at 4.5–11 m, one of reflectivity 0.15 at 45° at 1.5–3.6 m),
    /// with a threshold noise of 0.35–0.8 log units.
    pub fn draw(seed: u64) -> ReceivedPower {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let ln = rng.random_range((0.008f32).ln()..(0.05f32).ln());
        ReceivedPower {
            half_power: ln.exp().clamp(0.008, 0.05),
            spread: rng.random_range(0.35..0.8),
        }
    }

    /// The chance that a surface at `r` m, seen at incidence cosine `cos`, of `reflectivity`,
    /// returns a reading; 0 for anything not finite or not positive.
    pub fn return_chance(&self, r: f32, cos: f32, reflectivity: f32) -> f64 {
        let p = f64::from(reflectivity) * f64::from(cos) / f64::from(r * r);
        let (p50, s) = (f64::from(self.half_power), f64::from(self.spread));
        if !(p.is_finite() && p > 0.0 && p50 > 0.0 && s > 0.0) {
            return 0.0;
        }
        1.0 / (1.0 + (p50 / p).powf(1.0 / s))
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn a_dark_face_at_a_slant_thins_well_inside_the_range_a_white_one_reaches() {
        let unit = ReceivedPower {
            half_power: 0.02,
            spread: 0.5,
        };
        // A white wall head-on at the LDS-01's 3.5 m spec range still returns.
        assert!(unit.return_chance(3.5, 1.0, 1.0) > 0.9);
        // Half return exactly at the threshold.
        assert!((unit.return_chance(1.0, 1.0, 0.02) - 0.5).abs() < 1e-9);
        // A dark face (0.15) at 60° (cos 0.5): dense close by, sparse at 2.5 m.
        let near = unit.return_chance(0.8, 0.5, 0.15);
        let mid = unit.return_chance(2.5, 0.5, 0.15);
        assert!(near > 0.8 && mid < 0.3, "{near} {mid}");
        // The same face head-on keeps more of its returns than at a slant.
        assert!(unit.return_chance(2.5, 1.0, 0.15) > mid + 0.2);
        // Nonsense in, no return out.
        for (r, c, q) in [(0.0, 1.0, 1.0), (f32::NAN, 1.0, 1.0), (1.0, -0.5, 1.0)] {
            assert_eq!(unit.return_chance(r, c, q), 0.0);
        }
    }

    #[test]
    fn drawn_units_stay_within_their_ranges_and_repeat_by_seed() {
        for seed in 0..200 {
            let u = ReceivedPower::draw(seed);
            assert!((0.008..=0.05).contains(&u.half_power), "{u:?}");
            assert!((0.35..0.8).contains(&u.spread));
            assert_eq!(u, ReceivedPower::draw(seed));
            // Every drawn unit sees a white wall head-on at 3.5 m more often than not.
            assert!(u.return_chance(3.5, 1.0, 1.0) > 0.6, "{u:?}");
        }
    }
}
