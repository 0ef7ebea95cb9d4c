//! Shape of a point set: centroid, principal-axes box and minimum-area box.
//!
//! Point sets come as a list of slices (an object made of several DBSCAN fragments is several
//! runs of the clustered points), so nothing is copied.

use crate::geometry::Point2;

/// An oriented rectangle.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OrientedBox {
    /// Centre, metres.
    pub centre: Point2,
    /// Direction of the long side, radians in [0, π).
    pub angle: f32,
    /// Long side, metres.
    pub length: f32,
    /// Short side, metres.
    pub width: f32,
}

impl OrientedBox {
    /// Area, m².
    pub fn area(&self) -> f32 {
        self.length * self.width
    }

    /// Long side over short side (a short side under 1 mm counts as 1 mm).
    pub fn aspect(&self) -> f32 {
        self.length / self.width.max(1e-3)
    }

    /// The four corners, counter-clockwise.
    pub fn corners(&self) -> [Point2; 4] {
        let (s, c) = (libm::sinf(self.angle), libm::cosf(self.angle));
        let (l, w) = (self.length / 2.0, self.width / 2.0);
        let at = |a: f32, b: f32| {
            Point2::new(self.centre.x + c * a - s * b, self.centre.y + s * a + c * b)
        };
        [at(-l, -w), at(l, -w), at(l, w), at(-l, w)]
    }
}

/// Number of points in `parts`.
pub fn count(parts: &[&[Point2]]) -> usize {
    parts.iter().map(|p| p.len()).sum()
}

/// Mean of the points (the origin if there are none).
pub fn centroid(parts: &[&[Point2]]) -> Point2 {
    let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0usize);
    for p in parts.iter().flat_map(|s| s.iter()) {
        sx += f64::from(p.x);
        sy += f64::from(p.y);
        n += 1;
    }
    if n == 0 {
        return Point2::default();
    }
    Point2::new((sx / n as f64) as f32, (sy / n as f64) as f32)
}

/// Extent of the points along direction `angle` and its normal: (min u, max u, min v, max v).
fn extent(parts: &[&[Point2]], origin: Point2, angle: f32) -> (f32, f32, f32, f32) {
    let (s, c) = (libm::sinf(angle), libm::cosf(angle));
    let (mut u0, mut u1, mut v0, mut v1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
    for p in parts.iter().flat_map(|s| s.iter()) {
        let d = *p - origin;
        let u = c * d.x + s * d.y;
        let v = -s * d.x + c * d.y;
        u0 = u0.min(u);
        u1 = u1.max(u);
        v0 = v0.min(v);
        v1 = v1.max(v);
    }
    (u0, u1, v0, v1)
}

fn box_at(parts: &[&[Point2]], origin: Point2, angle: f32) -> OrientedBox {
    let (u0, u1, v0, v1) = extent(parts, origin, angle);
    if u0 > u1 {
        return OrientedBox::default();
    }
    let (s, c) = (libm::sinf(angle), libm::cosf(angle));
    let (um, vm) = ((u0 + u1) / 2.0, (v0 + v1) / 2.0);
    let centre = Point2::new(origin.x + c * um - s * vm, origin.y + s * um + c * vm);
    let (a, b) = (u1 - u0, v1 - v0);
    let pi = core::f32::consts::PI;
    if a >= b {
        OrientedBox {
            centre,
            angle: libm::fmodf(angle + pi, pi),
            length: a,
            width: b,
        }
    } else {
        OrientedBox {
            centre,
            angle: libm::fmodf(angle + pi / 2.0 + pi, pi),
            length: b,
            width: a,
        }
    }
}

/// The box along the principal axes of the points' covariance. O(n). The 2 × 2 covariance's
/// axis is the closed form `atan2(2 sxy, sxx − syy) / 2` (no matrix library needed).
pub fn principal_box(parts: &[&[Point2]]) -> OrientedBox {
    let c = centroid(parts);
    let (mut sxx, mut sxy, mut syy) = (0.0f32, 0.0f32, 0.0f32);
    for p in parts.iter().flat_map(|s| s.iter()) {
        let d = *p - c;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    let angle = 0.5 * libm::atan2f(2.0 * sxy, sxx - syy);
    box_at(parts, c, angle)
}

/// The smallest-area enclosing rectangle, searched over orientations: every 2° in [0°, 90°),
/// then every 0.25° within ±2° of the best. O(61 n); within 0.13° of the exact optimum's angle.
pub fn min_area_box(parts: &[&[Point2]]) -> OrientedBox {
    let c = centroid(parts);
    let step = 2.0f32.to_radians();
    let mut best = (f32::MAX, 0.0f32);
    for k in 0..45 {
        let a = k as f32 * step;
        let (u0, u1, v0, v1) = extent(parts, c, a);
        let area = (u1 - u0) * (v1 - v0);
        if area < best.0 {
            best = (area, a);
        }
    }
    let fine = 0.25f32.to_radians();
    let coarse = best.1;
    for k in -8..=8 {
        let a = coarse + k as f32 * fine;
        let (u0, u1, v0, v1) = extent(parts, c, a);
        let area = (u1 - u0) * (v1 - v0);
        if area < best.0 {
            best = (area, a);
        }
    }
    box_at(parts, c, best.1)
}

#[cfg(test)]
mod test {
    use super::*;

    fn rect_outline(c: Point2, l: f32, w: f32, yaw: f32) -> std::vec::Vec<Point2> {
        let b = OrientedBox {
            centre: c,
            angle: yaw,
            length: l,
            width: w,
        };
        let k = b.corners();
        let mut out = std::vec::Vec::new();
        for i in 0..4 {
            for t in 0..50 {
                let t = t as f32 / 50.0;
                let (a, b) = (k[i], k[(i + 1) % 4]);
                out.push(Point2::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t));
            }
        }
        out
    }

    #[test]
    fn recovers_a_rotated_rectangle() {
        for yaw in [0.0f32, 0.3, 1.2, 2.9] {
            let pts = rect_outline(Point2::new(1.0, -2.0), 0.6, 0.4, yaw);
            let b = min_area_box(&[&pts]);
            assert!(b.centre.distance(Point2::new(1.0, -2.0)) < 0.01, "{b:?}");
            assert!(
                (b.length - 0.6).abs() < 0.01 && (b.width - 0.4).abs() < 0.01,
                "{b:?}"
            );
            let d = crate::geometry::wrap_angle(2.0 * (b.angle - yaw)).abs();
            assert!(d < 0.02, "{yaw} {b:?}");
            let p = principal_box(&[&pts]);
            assert!((p.area() - 0.24).abs() < 0.01, "{p:?}");
        }
    }

    #[test]
    fn split_parts_equal_one_slice() {
        let pts = rect_outline(Point2::new(0.0, 0.0), 1.0, 0.2, 0.7);
        let (a, b) = pts.split_at(77);
        assert_eq!(min_area_box(&[a, b]), min_area_box(&[&pts]));
        assert_eq!(count(&[a, b]), pts.len());
    }

    #[test]
    fn empty_and_single() {
        assert_eq!(min_area_box(&[]), OrientedBox::default());
        let one = [Point2::new(3.0, 4.0)];
        let b = min_area_box(&[&one]);
        assert_eq!((b.length, b.width), (0.0, 0.0));
        assert!(b.centre.distance(one[0]) < 1e-6);
        assert_eq!(b.aspect(), 0.0);
    }
}
