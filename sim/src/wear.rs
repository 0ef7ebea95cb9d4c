//! A real unit's wear: what a bench-fresh reading model leaves out and scanners in service show.
//! Two effects, both general to time-of-flight and triangulation scanners (and in the real
//! CARMEN logs: `docs/world.md`, 37th session):
//!
//! - **Returns that fade with range.** The returned light falls with the square of the range,
//!   so a unit with a dirty window or a tired diode loses more returns the farther the surface
//!   is, not only past its spec range: an extra dropout chance of `fade · (r / spec)²`.
//! - **Mixed pixels.** The beam is a spot, not a line. Where the spot straddles a depth edge
//!   (a chair leg before a wall, a wall's end before the room beyond), part of the light comes
//!   back from each surface and the unit reads a range between the two: a return that lies on
//!   neither surface.
//!
//! Both are off in [`Wear::default`], so a reading model without wear draws exactly the random
//! numbers it always drew and every seed's scans stay as they were.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A depth step smaller than this within the spot is one surface, not an edge, m.
pub const EDGE_STEP_M: f32 = 0.10;

/// How worn a unit is.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wear {
    /// Extra dropout chance at the spec range, falling with the square of the range below it.
    pub fade: f64,
    /// Chance that a reading whose spot straddles a depth edge returns a range between the two
    /// surfaces.
    pub mixed_pixel: f64,
    /// Half the spot's width, degrees: a second ray this far to one side finds the edge.
    pub half_spot_deg: f32,
}

impl Wear {
    /// A worn unit drawn from `seed`: fading 0.05–0.4 at the spec range, mixed pixels at
    /// 20–70 % of the depth edges within a spot 0.3–1.0° wide.
    pub fn draw(seed: u64) -> Wear {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        Wear {
            fade: rng.random_range(0.05..0.4),
            mixed_pixel: rng.random_range(0.2..0.7),
            half_spot_deg: rng.random_range(0.15..0.5f32),
        }
    }

    /// Whether readings need a second ray (mixed pixels are on).
    pub fn has_spot(&self) -> bool {
        self.mixed_pixel > 0.0 && self.half_spot_deg > 0.0
    }

    /// The extra dropout chance of a surface at `r` m for a unit whose spec range is `spec` m.
    pub fn fade_at(&self, r: f32, spec: f32) -> f64 {
        if self.fade <= 0.0 || spec <= 0.0 {
            return 0.0;
        }
        let x = f64::from((r / spec).min(1.0));
        self.fade * x * x
    }

    /// The range read where the spot's centre hits at `r` and its other side at `other` (if
    /// that side hits anything): between the two with chance [`Wear::mixed_pixel`] when they
    /// differ by more than [`EDGE_STEP_M`], else `r`.
    pub fn mix(&self, r: f32, other: Option<f32>, rng: &mut impl Rng) -> f32 {
        match other {
            Some(o) if (o - r).abs() > EDGE_STEP_M && rng.random_bool(self.mixed_pixel) => {
                r + rng.random_range(0.0..1.0f32) * (o - r)
            }
            _ => r,
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn a_worn_unit_is_reproducible_and_in_its_ranges() {
        for seed in 0..50 {
            let w = Wear::draw(seed);
            assert_eq!(w, Wear::draw(seed));
            assert!((0.05..0.4).contains(&w.fade) && (0.2..0.7).contains(&w.mixed_pixel));
            assert!(w.has_spot());
        }
        assert!(!Wear::default().has_spot());
        assert_eq!(Wear::default().fade_at(3.0, 3.5), 0.0);
    }

    #[test]
    fn returns_fade_with_the_square_of_range() {
        let w = Wear {
            fade: 0.4,
            ..Wear::default()
        };
        assert!((w.fade_at(3.5, 3.5) - 0.4).abs() < 1e-9);
        assert!((w.fade_at(1.75, 3.5) - 0.1).abs() < 1e-6);
        assert!((w.fade_at(9.0, 3.5) - 0.4).abs() < 1e-9);
    }

    #[test]
    fn mixed_pixels_lie_between_the_two_surfaces_and_only_at_edges() {
        let w = Wear {
            mixed_pixel: 1.0,
            half_spot_deg: 0.5,
            ..Wear::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut between = 0;
        for _ in 0..200 {
            let r = w.mix(1.0, Some(2.5), &mut rng);
            assert!((1.0..=2.5).contains(&r), "{r}");
            between += usize::from(r > 1.05 && r < 2.45);
            assert_eq!(w.mix(1.0, Some(1.05), &mut rng), 1.0);
            assert_eq!(w.mix(1.0, None, &mut rng), 1.0);
        }
        assert!(between > 150, "{between}");
    }
}
