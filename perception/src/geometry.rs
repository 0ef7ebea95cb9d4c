//! 2D geometry in ROS REP 103 conventions: metres, radians, x forward, y left, angles
//! counter-clockwise. [`Point2`] is a position, [`Pose2`] a rigid transform (x, y, θ).

use core::ops::{Add, Sub};

/// A point or vector in the plane, metres.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Point2 {
    /// Forward (m).
    pub x: f32,
    /// Left (m).
    pub y: f32,
}

impl Point2 {
    /// A point.
    pub const fn new(x: f32, y: f32) -> Self {
        Point2 { x, y }
    }

    /// The point at `range` metres along the ray at `angle` radians (counter-clockwise from x).
    pub fn from_polar(range: f32, angle: f32) -> Self {
        Point2::new(range * libm::cosf(angle), range * libm::sinf(angle))
    }

    /// Dot product with `other`.
    pub fn dot(self, other: Point2) -> f32 {
        self.x * other.x + self.y * other.y
    }

    /// The z component of the cross product with `other` (positive: `other` is to the left).
    pub fn cross(self, other: Point2) -> f32 {
        self.x * other.y - self.y * other.x
    }

    /// Euclidean length.
    pub fn norm(self) -> f32 {
        libm::hypotf(self.x, self.y)
    }

    /// Distance to `other`.
    pub fn distance(self, other: Point2) -> f32 {
        (self - other).norm()
    }

    /// Distance to the segment from `a` to `b`.
    pub fn distance_to_segment(self, a: Point2, b: Point2) -> f32 {
        let e = b - a;
        let l2 = e.x * e.x + e.y * e.y;
        let t = if l2 > 0.0 {
            (((self - a).x * e.x + (self - a).y * e.y) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.distance(Point2::new(a.x + t * e.x, a.y + t * e.y))
    }
}

impl Add for Point2 {
    type Output = Point2;
    fn add(self, o: Point2) -> Point2 {
        Point2::new(self.x + o.x, self.y + o.y)
    }
}

impl Sub for Point2 {
    type Output = Point2;
    fn sub(self, o: Point2) -> Point2 {
        Point2::new(self.x - o.x, self.y - o.y)
    }
}

/// Wraps an angle into (−π, π].
pub fn wrap_angle(a: f32) -> f32 {
    let two_pi = 2.0 * core::f32::consts::PI;
    let mut w = libm::fmodf(a, two_pi);
    if w <= -core::f32::consts::PI {
        w += two_pi;
    } else if w > core::f32::consts::PI {
        w -= two_pi;
    }
    w
}

/// A rigid 2D transform: the pose of a child frame in a parent frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pose2 {
    /// Position x in the parent frame (m).
    pub x: f32,
    /// Position y in the parent frame (m).
    pub y: f32,
    /// Heading, counter-clockwise from the parent's x axis (rad), kept in (−π, π].
    pub theta: f32,
}

impl Pose2 {
    /// The identity transform.
    pub const IDENTITY: Pose2 = Pose2 {
        x: 0.0,
        y: 0.0,
        theta: 0.0,
    };

    /// A pose; `theta` is wrapped into (−π, π].
    pub fn new(x: f32, y: f32, theta: f32) -> Self {
        Pose2 {
            x,
            y,
            theta: wrap_angle(theta),
        }
    }

    /// Maps a point from the child frame into the parent frame. SE(2) by hand: three trig
    /// calls and four products; nalgebra's `Isometry2` would compute the same with a
    /// different rounding order (it enters with the scan-matched pose filter, where 3 × 3
    /// covariances and Jacobians make it pay).
    pub fn transform(&self, p: Point2) -> Point2 {
        let (s, c) = (libm::sinf(self.theta), libm::cosf(self.theta));
        Point2::new(self.x + c * p.x - s * p.y, self.y + s * p.x + c * p.y)
    }

    /// `self ∘ other`: the pose of `other`'s child in `self`'s parent frame.
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let p = self.transform(Point2::new(other.x, other.y));
        Pose2::new(p.x, p.y, self.theta + other.theta)
    }

    /// The pose halfway to `other` (heading along the shorter way round).
    pub fn midway(&self, other: &Pose2) -> Pose2 {
        Pose2::new(
            (self.x + other.x) / 2.0,
            (self.y + other.y) / 2.0,
            wrap_angle(self.theta + wrap_angle(other.theta - self.theta) / 2.0),
        )
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Pose2 {
        let (s, c) = (libm::sinf(self.theta), libm::cosf(self.theta));
        Pose2::new(
            -(c * self.x + s * self.y),
            s * self.x - c * self.y,
            -self.theta,
        )
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use core::f32::consts::{FRAC_PI_2, PI};
    use proptest::prelude::*;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-4
    }

    #[test]
    fn midway_turns_the_shorter_way_round() {
        let m = Pose2::new(0.0, 0.0, 3.0).midway(&Pose2::new(2.0, 4.0, -3.0));
        assert!(close(m.x, 1.0) && close(m.y, 2.0), "{m:?}");
        assert!(close(m.theta.abs(), PI), "across ±π, not through 0: {m:?}");
        let m = Pose2::new(0.0, 0.0, -0.5).midway(&Pose2::new(0.0, 0.0, 1.5));
        assert!(close(m.theta, 0.5), "{m:?}");
    }

    #[test]
    fn segment_distance() {
        let (a, b) = (Point2::new(0.0, 0.0), Point2::new(2.0, 0.0));
        assert!(close(Point2::new(1.0, 1.0).distance_to_segment(a, b), 1.0));
        assert!(close(Point2::new(3.0, 0.0).distance_to_segment(a, b), 1.0));
        assert!(close(Point2::new(-1.0, 0.0).distance_to_segment(a, a), 1.0));
    }

    #[test]
    fn polar_follows_rep103() {
        let left = Point2::from_polar(2.0, FRAC_PI_2);
        assert!(close(left.x, 0.0) && close(left.y, 2.0));
    }

    #[test]
    fn transform_quarter_turn() {
        let pose = Pose2::new(1.0, 2.0, FRAC_PI_2);
        let p = pose.transform(Point2::new(1.0, 0.0));
        assert!(close(p.x, 1.0) && close(p.y, 3.0));
    }

    #[test]
    fn wrap() {
        // ±3π land on the ±π boundary; which side depends on rounding.
        assert!(close(wrap_angle(3.0 * PI).abs(), PI));
        assert!(close(wrap_angle(-3.0 * PI).abs(), PI));
        assert!(close(wrap_angle(-2.5 * PI), -0.5 * PI));
        assert!(close(wrap_angle(2.5 * PI), 0.5 * PI));
        assert!(close(wrap_angle(0.5), 0.5));
        assert!(close(wrap_angle(-2.0 * PI + 0.1), 0.1));
    }

    proptest! {
        #[test]
        fn inverse_undoes(x in -10f32..10.0, y in -10f32..10.0, t in -4f32..4.0,
                          px in -5f32..5.0, py in -5f32..5.0) {
            let pose = Pose2::new(x, y, t);
            let p = Point2::new(px, py);
            let back = pose.inverse().transform(pose.transform(p));
            prop_assert!(back.distance(p) < 1e-3);
            let id = pose.compose(&pose.inverse());
            prop_assert!(id.x.abs() < 1e-3 && id.y.abs() < 1e-3 && wrap_angle(id.theta).abs() < 1e-4);
        }
    }
}
