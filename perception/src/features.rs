//! The 9-D feature vector of Method A, as the study's code computes it, in a chosen frame.
//!
//! Order: `[width, height, area, density, aspect, n, std_x, std_y, std_ratio]`, where, with
//! the points rotated into the frame, width = peak-to-peak x, height = peak-to-peak y, area =
//! width · height, density = n / area, aspect = width / height, n = point count, std_x and
//! std_y the population standard deviations, std_ratio = std_x / std_y.
//!
//! **Zero guards** (a single point, a perfectly straight face): area uses at least 1e-4 m²,
//! aspect divides by at least 1 mm, the ratio by at least 0.1 mm, so every feature is finite.
//!
//! **Frame.** [`FeatureFrame::Object`] rotates into the object's minimum-area box (x along its
//! long side): the features do not change when the object turns. [`FeatureFrame::Axis`] keeps
//! the map axes, as the study's code did. Which one classifies better was measured on held-out
//! scenes (see `docs/method-a.md`); [`FeatureFrame::Object`] is the default.

use crate::geometry::Point2;

/// Features per object.
pub const N_FEATURES: usize = 9;

/// Feature names, in order.
pub const FEATURE_NAMES: [&str; N_FEATURES] = [
    "width",
    "height",
    "area",
    "density",
    "aspect",
    "n",
    "std_x",
    "std_y",
    "std_ratio",
];

/// The frame the features are computed in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FeatureFrame {
    /// The object's own (minimum-area box) frame: rotation-invariant.
    #[default]
    Object,
    /// The map's axes.
    Axis,
}

/// Features of the points in `parts`, in the frame turned by `angle` (radians) from the map.
pub fn features(parts: &[&[Point2]], angle: f32) -> [f32; N_FEATURES] {
    let (s, c) = (libm::sinf(angle), libm::cosf(angle));
    let (mut x0, mut x1, mut y0, mut y1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
    let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0usize);
    for p in parts.iter().flat_map(|s| s.iter()) {
        let (u, v) = (c * p.x + s * p.y, -s * p.x + c * p.y);
        x0 = x0.min(u);
        x1 = x1.max(u);
        y0 = y0.min(v);
        y1 = y1.max(v);
        sx += f64::from(u);
        sy += f64::from(v);
        n += 1;
    }
    if n == 0 {
        return [0.0; N_FEATURES];
    }
    let (mx, my) = (sx / n as f64, sy / n as f64);
    let (mut vx, mut vy) = (0.0f64, 0.0f64);
    for p in parts.iter().flat_map(|s| s.iter()) {
        let (u, v) = (c * p.x + s * p.y, -s * p.x + c * p.y);
        vx += (f64::from(u) - mx) * (f64::from(u) - mx);
        vy += (f64::from(v) - my) * (f64::from(v) - my);
    }
    let (w, h) = (x1 - x0, y1 - y0);
    let area = (w * h).max(1e-4);
    let nf = n as f32;
    let (stx, sty) = (
        libm::sqrt(vx / n as f64) as f32,
        libm::sqrt(vy / n as f64) as f32,
    );
    [
        w,
        h,
        area,
        nf / area,
        w / h.max(1e-3),
        nf,
        stx,
        sty,
        stx / sty.max(1e-4),
    ]
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn rectangle_features_and_rotation_invariance() {
        let pts: std::vec::Vec<Point2> = (0..100)
            .map(|k| Point2::new((k % 10) as f32 * 0.06, (k / 10) as f32 * 0.04))
            .collect();
        let f = features(&[&pts], 0.0);
        assert!((f[0] - 0.54).abs() < 1e-5 && (f[1] - 0.36).abs() < 1e-5);
        assert!((f[2] - 0.54 * 0.36).abs() < 1e-5);
        assert!((f[4] - 1.5).abs() < 1e-4 && f[5] == 100.0);
        // Turn the points; features in the turned frame match.
        let a = 0.7f32;
        let turned: std::vec::Vec<Point2> = pts
            .iter()
            .map(|p| Point2::new(a.cos() * p.x - a.sin() * p.y, a.sin() * p.x + a.cos() * p.y))
            .collect();
        let g = features(&[&turned], a);
        for (x, y) in f.iter().zip(g.iter()) {
            assert!((x - y).abs() < 1e-3 * x.abs().max(1.0), "{f:?} {g:?}");
        }
    }

    #[test]
    fn guards_keep_everything_finite() {
        for pts in [
            std::vec![],
            std::vec![Point2::new(1.0, 1.0)],
            std::vec![Point2::new(1.0, 1.0); 30],
            (0..30).map(|k| Point2::new(k as f32 * 0.01, 0.0)).collect(),
        ] {
            let f = features(&[&pts], 0.3);
            assert!(f.iter().all(|x| x.is_finite()), "{f:?}");
        }
    }
}
