//! One revolution's sweep: where the LiDAR stood when it read each bearing, and the bearing at
//! which it read a given point. Method B's labels (`sim::labels`, with `--deskew`) and its
//! decoded boxes (`[method_b] deskew`) use it, so a box sits on its readings, not where the
//! object lies from one pose of the revolution.
//!
//! The LDS-01 sweeps clockwise: raw reading `i` is bin `359 − i`, read at fraction `i / 360` of
//! the revolution, so bearing `b` (degrees counter-clockwise, continuous) is read at fraction
//! `(359 − b) / 360`, wrapped into `[0, 1)`, with the robot's pose interpolated between the
//! first ray's and the last ray's ([`crate::cloud::Scan::lidar_at`], the same rule for one
//! bin). On a robot turning at 1 rad/s a revolution's two ends are 11° apart: a label drawn
//! from the middle's pose sits up to 6° off its readings. `no_std`, allocation-free.

use crate::geometry::{Point2, Pose2, wrap_angle};

/// Fixed-point passes of [`Sweep::bearing_of`] (each shrinks the error by the share of a
/// revolution the robot turns in a degree's sweep, < 1 %).
const PASSES: usize = 3;

/// A revolution's sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sweep {
    /// Robot pose (map frame) at the first ray.
    pub start: Pose2,
    /// Robot pose (map frame) at the last ray.
    pub end: Pose2,
    /// The LiDAR's pose on the robot.
    pub mount: Pose2,
}

impl Sweep {
    /// The LiDAR's pose (map frame) when it read bearing `deg` (any real number of degrees).
    pub fn lidar_at(&self, deg: f32) -> Pose2 {
        let f = (359.0 - deg) / 360.0;
        self.lidar_at_fraction(f - libm::floorf(f))
    }

    /// The LiDAR's pose (map frame) at fraction `u` of the way from the first ray to the last:
    /// the robot's pose interpolated, then the mount. The one interpolation of a revolution's
    /// poses ([`crate::cloud::Scan::lidar_at`] reads its bins through it too).
    pub fn lidar_at_fraction(&self, u: f32) -> Pose2 {
        let dtheta = wrap_angle(self.end.theta - self.start.theta);
        Pose2::new(
            self.start.x + (self.end.x - self.start.x) * u,
            self.start.y + (self.end.y - self.start.y) * u,
            self.start.theta + dtheta * u,
        )
        .compose(&self.mount)
    }

    /// The point read at bearing `deg` and range `range_m`, in the map frame.
    pub fn point(&self, deg: f32, range_m: f32) -> Point2 {
        self.lidar_at(deg)
            .transform(Point2::from_polar(range_m, deg.to_radians()))
    }

    /// The bearing (degrees, `[0, 360)`) at which the sweep reads map point `p`, and `p` in the
    /// LiDAR's frame at that instant. Starts from the middle of the revolution and follows
    /// the bearing's own read instant for a few passes. A point the LiDAR stands on has
    /// bearing 0.
    pub fn bearing_of(&self, p: Point2) -> (f32, Point2) {
        let mut deg = 179.5;
        let mut local = self.lidar_at(deg).inverse().transform(p);
        for _ in 0..PASSES {
            deg = degrees(local);
            local = self.lidar_at(deg).inverse().transform(p);
        }
        (degrees(local), local)
    }
}

/// The bearing of a point in the LiDAR's frame, degrees in `[0, 360)`.
fn degrees(local: Point2) -> f32 {
    let d = libm::atan2f(local.y, local.x).to_degrees();
    if d < 0.0 { d + 360.0 } else { d }
}

#[cfg(test)]
mod test {
    use super::*;

    fn turning() -> Sweep {
        // Turning in place at 1 rad/s for one 0.2 s revolution, LiDAR 3 cm behind the axle.
        Sweep {
            start: Pose2::new(1.0, 1.0, 0.0),
            end: Pose2::new(1.0, 1.0, 0.2),
            mount: Pose2::new(-0.03, 0.0, 0.0),
        }
    }

    #[test]
    fn bins_read_first_and_last() {
        let s = turning();
        // Bin 359 is read first (the start's pose), bin 0 last (almost the end's).
        assert!((s.lidar_at(359.0).theta - 0.0).abs() < 1e-6);
        assert!((s.lidar_at(0.0).theta - 0.2 * 359.0 / 360.0).abs() < 1e-5);
        assert!((s.lidar_at(179.0).theta - 0.1).abs() < 1e-5);
        // The same rule as Method A's cloud, bin for bin.
        let ranges = [1.0f32; 360];
        let scan = crate::cloud::Scan {
            ranges: &ranges,
            start: s.start,
            end: s.end,
            mount: s.mount,
        };
        for d in [0usize, 90, 200, 359] {
            let (a, b) = (scan.lidar_at(d), s.lidar_at(d as f32));
            assert!((a.x - b.x).abs() < 1e-6 && (a.theta - b.theta).abs() < 1e-6);
        }
    }

    #[test]
    fn a_point_read_is_found_at_its_bearing() {
        let s = turning();
        for deg in [5.0f32, 90.0, 181.0, 270.5, 350.0] {
            let p = s.point(deg, 2.0);
            let (b, local) = s.bearing_of(p);
            assert!((b - deg).abs() < 0.01, "{deg} → {b}");
            assert!((local.norm() - 2.0).abs() < 1e-4);
        }
    }

    #[test]
    fn the_middle_pose_is_off_by_the_turn() {
        // From the middle's pose a point read early (bearing 300°, fraction 0.16, the LiDAR
        // then 0.067 rad short of the middle's heading) lies at ≈ 296.2°: the offset a label
        // drawn from the middle carries.
        let s = turning();
        let p = s.point(300.0, 2.0);
        let mid = s.lidar_at(179.5).inverse().transform(p);
        let from_mid = mid.y.atan2(mid.x).to_degrees().rem_euclid(360.0);
        assert!((from_mid - 300.0).abs() > 3.0, "{from_mid}");
        assert!((s.bearing_of(p).0 - 300.0).abs() < 0.01);
    }

    #[test]
    fn a_still_robot_reads_from_one_pose() {
        let still = Sweep {
            start: Pose2::new(0.5, -1.0, 2.0),
            end: Pose2::new(0.5, -1.0, 2.0),
            mount: Pose2::IDENTITY,
        };
        let p = Point2::new(0.5, 1.0);
        let local = still.start.inverse().transform(p);
        let want = local.y.atan2(local.x).to_degrees().rem_euclid(360.0);
        assert!((still.bearing_of(p).0 - want).abs() < 1e-4);
    }
}
