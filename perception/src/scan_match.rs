//! Scan matching: each revolution's returns aligned with a keyframe's by point-to-line ICP, so
//! that the map-frame pose does not drift with the wheels. `no_std`, fixed buffers.
//!
//! The wheels' odometry is good over a revolution (it de-skews the scan) and poor over a tour:
//! wheel slip turns the map by several degrees in 30 s (`umbra-lab eval-world` measures it
//! against the simulator's truth). The matcher keeps one **keyframe**: a revolution's returns
//! in the map frame, as corrected. Every later revolution is de-skewed with the odometry's pose
//! (the [`Scan`] Method A takes), and the rigid correction `C` that lays its returns on the
//! keyframe's lines is estimated: Gauss–Newton on the point-to-line distances (Censi's PL-ICP),
//! rotation about the robot, each return paired with the nearest keyframe return found among
//! the keyframe bins around its bearing and the line through that return's nearer neighbour.
//! `C ∘ pose` is then the pose; the keyframe is replaced by the corrected revolution once the
//! robot has moved or turned far enough from it, so drift grows only at keyframe changes.
//!
//! A match is refused — the odometry's pose stands — when too few returns pair up, the
//! residual is large (a scene that changed, a person walking by), the correction is larger than
//! the odometry could have drifted in a few revolutions, or the geometry cannot fix a direction
//! (a corridor: the pairs' normals span one direction only).

use nalgebra::{Matrix2, Matrix3, Vector3};

use crate::cloud::Scan;
use crate::geometry::{Point2, Pose2, wrap_angle};

/// Bins of a revolution (one a degree).
pub const BINS: usize = 360;

/// Scan-matching settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanMatchConfig {
    /// Gauss–Newton iterations at most.
    pub max_iterations: u8,
    /// Pairing distance at the first iteration, m; it shrinks to `min_pair_m`.
    pub max_pair_m: f32,
    /// Pairing distance at the last iterations, m.
    pub min_pair_m: f32,
    /// Keyframe bins searched either side of a return's bearing.
    pub window: u8,
    /// Pairs needed for a match.
    pub min_pairs: u16,
    /// Largest root-mean-square point-to-line distance of an accepted match, m.
    pub max_rms_m: f32,
    /// Largest accepted correction: translation, m, and rotation, rad.
    pub max_shift_m: f32,
    /// See `max_shift_m`.
    pub max_turn_rad: f32,
    /// Smallest share of the pairs' normal information in the weaker direction (a corridor
    /// gives ~0): below it the match is refused.
    pub min_spread: f32,
    /// A new keyframe once the robot is this far from the keyframe's pose, m ...
    pub keyframe_m: f32,
    /// ... or has turned this much, rad.
    pub keyframe_rad: f32,
    /// Returns beyond this range are not used, m: the LiDAR's reach (`umbra` gives it
    /// `[lidar] max_range_m`; farther returns helped on real scans, `docs/pose.md`).
    pub max_range_m: f32,
}

impl Default for ScanMatchConfig {
    fn default() -> Self {
        ScanMatchConfig {
            max_iterations: 20,
            max_pair_m: 0.3,
            min_pair_m: 0.08,
            window: 8,
            min_pairs: 60,
            max_rms_m: 0.04,
            max_shift_m: 0.3,
            max_turn_rad: 0.2,
            min_spread: 0.05,
            keyframe_m: 0.25,
            keyframe_rad: 0.35,
            max_range_m: 3.5,
        }
    }
}

/// What became of one revolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MatchOutcome {
    /// It became the first keyframe (nothing to match against yet), or there was none to keep.
    Keyframe,
    /// Matched: the pose is `correction ∘ pose` (a rigid motion of the map frame).
    Matched {
        /// The correction.
        correction: Pose2,
        /// Pairs in the last iteration.
        pairs: u16,
        /// Root-mean-square point-to-line distance, m.
        rms_m: f32,
    },
    /// Refused: the odometry's pose stands.
    Refused(Refusal),
}

/// Why a match was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// Fewer pairs than `min_pairs`.
    FewPairs,
    /// The residual is above `max_rms_m`.
    Residual,
    /// The correction is beyond `max_shift_m` / `max_turn_rad`.
    TooFar,
    /// The pairs' normals fix one direction only.
    Degenerate,
}

/// Counts over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct MatchStats {
    /// Revolutions matched.
    pub matched: u32,
    /// Revolutions refused, by reason: few pairs, residual, too far, degenerate.
    pub refused: [u32; 4],
    /// Keyframes taken.
    pub keyframes: u32,
}

/// A revolution's returns in the map frame, by bin (`None`: no usable return).
#[derive(Clone)]
struct Returns {
    pts: [Option<Point2>; BINS],
}

impl Returns {
    const EMPTY: Returns = Returns { pts: [None; BINS] };

    fn fill(&mut self, scan: &Scan<'_>, max_range_m: f32) -> usize {
        let mut n = 0;
        for (d, slot) in self.pts.iter_mut().enumerate() {
            let r = scan.ranges.get(d).copied().unwrap_or(0.0);
            *slot = if r > 0.0 && r <= max_range_m && r.is_finite() {
                let l = scan.lidar_at(d);
                let a = (d as f32).to_radians();
                n += 1;
                Some(l.transform(Point2::new(r * libm::cosf(a), r * libm::sinf(a))))
            } else {
                None
            };
        }
        n
    }
}

/// The keyframe: its returns, where the LiDAR stood (for the bins' bearings) and the robot's
/// pose, both map frame and corrected.
#[derive(Clone)]
struct Keyframe {
    returns: Returns,
    lidar: Pose2,
    robot: Pose2,
}

/// The scan matcher (8.7 KiB: two revolutions of points, `memory-budget.md`).
#[derive(Clone)]
pub struct ScanMatcher {
    cfg: ScanMatchConfig,
    key: Option<Keyframe>,
    cur: Returns,
    stats: MatchStats,
}

impl ScanMatcher {
    /// A matcher with no keyframe.
    pub const fn new(cfg: ScanMatchConfig) -> Self {
        ScanMatcher {
            cfg,
            key: None,
            cur: Returns::EMPTY,
            stats: MatchStats {
                matched: 0,
                refused: [0; 4],
                keyframes: 0,
            },
        }
    }

    /// Counts so far.
    pub fn stats(&self) -> MatchStats {
        self.stats
    }

    /// Matches `scan` (de-skewed with the odometry's poses) against the keyframe, and keeps
    /// it as the next keyframe when the robot has moved on far enough.
    pub fn update(&mut self, scan: &Scan<'_>) -> MatchOutcome {
        let n = self.cur.fill(scan, self.cfg.max_range_m);
        let Some(key) = self.key.as_ref() else {
            if n >= usize::from(self.cfg.min_pairs) {
                self.take_keyframe(scan, Pose2::IDENTITY);
            }
            return MatchOutcome::Keyframe;
        };
        let pivot = Point2::new(scan.end.x, scan.end.y);
        let key_robot = key.robot;
        match self.icp(key, pivot) {
            Ok((correction, pairs, rms_m)) => {
                self.stats.matched += 1;
                if self.beyond(key_robot, correction.compose(&scan.end), 1.0) {
                    self.take_keyframe(scan, correction);
                }
                MatchOutcome::Matched {
                    correction,
                    pairs,
                    rms_m,
                }
            }
            Err(why) => {
                self.stats.refused[why as usize] += 1;
                // Far from a keyframe it cannot match any more: start again from here
                // (the odometry's pose, which is the best there is).
                if self.beyond(key_robot, scan.end, 2.0) {
                    self.take_keyframe(scan, Pose2::IDENTITY);
                }
                MatchOutcome::Refused(why)
            }
        }
    }

    /// Whether `robot` has moved `scale` × `keyframe_m` or turned `scale` × `keyframe_rad`
    /// from the keyframe's robot pose `key_robot`.
    fn beyond(&self, key_robot: Pose2, robot: Pose2, scale: f32) -> bool {
        libm::hypotf(robot.x - key_robot.x, robot.y - key_robot.y) >= scale * self.cfg.keyframe_m
            || libm::fabsf(wrap_angle(robot.theta - key_robot.theta))
                >= scale * self.cfg.keyframe_rad
    }

    /// The current returns, moved by `correction`, become the keyframe.
    ///
    /// They are binned again by their bearing from where the LiDAR stood at the revolution's
    /// end: a turning robot reads bin `d` up to a revolution's turn earlier, so its own bins
    /// are not bearings from any one place (14° apart at the end of a fast turn).
    fn take_keyframe(&mut self, scan: &Scan<'_>, correction: Pose2) {
        let lidar = correction.compose(&scan.end.compose(&scan.mount));
        let key = self.key.get_or_insert(Keyframe {
            returns: Returns::EMPTY,
            lidar,
            robot: Pose2::IDENTITY,
        });
        key.lidar = lidar;
        key.robot = correction.compose(&scan.end);
        key.returns.pts = [None; BINS];
        for p in self.cur.pts.iter().flatten() {
            let p = correction.transform(*p);
            let (dx, dy) = (p.x - lidar.x, p.y - lidar.y);
            let bearing = wrap_angle(libm::atan2f(dy, dx) - lidar.theta).to_degrees();
            let bin = (libm::roundf(bearing) as i32).rem_euclid(BINS as i32) as usize;
            let slot = &mut key.returns.pts[bin];
            let r = dx * dx + dy * dy;
            let nearer = |q: Point2| {
                let (qx, qy) = (q.x - lidar.x, q.y - lidar.y);
                qx * qx + qy * qy > r
            };
            if slot.is_none_or(nearer) {
                *slot = Some(p);
            }
        }
        self.stats.keyframes += 1;
    }

    /// The keyframe return nearest `q` (within `gate`) among the bins around its bearing, and
    /// the unit normal of the line through it and its nearer neighbour.
    fn pair(&self, key: &Keyframe, q: Point2, gate: f32) -> Option<(Point2, Point2)> {
        let dx = q.x - key.lidar.x;
        let dy = q.y - key.lidar.y;
        let bearing = wrap_angle(libm::atan2f(dy, dx) - key.lidar.theta).to_degrees();
        let centre = libm::roundf(bearing) as i32;
        let w = i32::from(self.cfg.window);
        let at = |d: i32| key.returns.pts[d.rem_euclid(BINS as i32) as usize];
        let mut best: Option<(i32, Point2, f32)> = None;
        for d in centre - w..=centre + w {
            if let Some(p) = at(d) {
                let dist = p.distance(q);
                if dist <= gate && best.is_none_or(|b| dist < b.2) {
                    best = Some((d, p, dist));
                }
            }
        }
        let (d, p, _) = best?;
        // The line through p and its nearer neighbour (within 3 gates: the same surface).
        let mut other: Option<(Point2, f32)> = None;
        for e in [d - 1, d + 1] {
            if let Some(o) = at(e) {
                let dist = o.distance(p);
                if dist <= 3.0 * self.cfg.max_pair_m && other.is_none_or(|b| dist < b.1) {
                    other = Some((o, dist));
                }
            }
        }
        let (o, len) = other?;
        if len < 1e-4 {
            return None;
        }
        let n = Point2::new(-(o.y - p.y) / len, (o.x - p.x) / len);
        Some((p, n))
    }

    /// Point-to-line ICP of the current returns against `key`, rotating about `pivot`.
    fn icp(&self, key: &Keyframe, pivot: Point2) -> Result<(Pose2, u16, f32), Refusal> {
        let cfg = &self.cfg;
        // The correction: rotate by `th` about the pivot, then shift by (tx, ty).
        let (mut tx, mut ty, mut th) = (0.0f32, 0.0f32, 0.0f32);
        let mut last = (0u16, f32::INFINITY, Matrix2::<f32>::zeros());
        for it in 0..cfg.max_iterations {
            let shrink = f32::from(it) / f32::from(cfg.max_iterations.max(2) / 2).max(1.0);
            let gate = (cfg.max_pair_m - (cfg.max_pair_m - cfg.min_pair_m) * shrink.min(1.0))
                .max(cfg.min_pair_m);
            let (s, c) = (libm::sinf(th), libm::cosf(th));
            let mut h = Matrix3::<f32>::zeros();
            let mut g = Vector3::<f32>::zeros();
            let mut pairs = 0u16;
            let mut sq = 0.0f32;
            for q0 in self.cur.pts.iter().flatten() {
                let v = Point2::new(q0.x - pivot.x, q0.y - pivot.y);
                let rv = Point2::new(c * v.x - s * v.y, s * v.x + c * v.y);
                let q = Point2::new(pivot.x + rv.x + tx, pivot.y + rv.y + ty);
                let Some((p, n)) = self.pair(key, q, gate) else {
                    continue;
                };
                let r = n.x * (q.x - p.x) + n.y * (q.y - p.y);
                // d(q)/d(th) = perp(rv); the residual's gradient is n · that.
                let j = Vector3::new(n.x, n.y, rv.cross(n));
                h += j * j.transpose();
                g += j * r;
                pairs += 1;
                sq += r * r;
            }
            if pairs < cfg.min_pairs {
                return Err(Refusal::FewPairs);
            }
            let rms = libm::sqrtf(sq / f32::from(pairs));
            last = (pairs, rms, h.fixed_view::<2, 2>(0, 0).into_owned());
            let Some(chol) = h.cholesky() else {
                return Err(Refusal::Degenerate);
            };
            let step = chol.solve(&(-g));
            tx += step[0];
            ty += step[1];
            th += step[2];
            if libm::fabsf(step[0]) + libm::fabsf(step[1]) < 1e-4 && libm::fabsf(step[2]) < 1e-4 {
                break;
            }
        }
        let (pairs, rms, ht) = last;
        // The weaker direction's share of the translation information.
        let eig = ht.symmetric_eigenvalues();
        let (lo, hi) = (eig[0].min(eig[1]), eig[0].max(eig[1]));
        if hi <= 0.0 || lo / (lo + hi) < cfg.min_spread {
            return Err(Refusal::Degenerate);
        }
        if rms > cfg.max_rms_m {
            return Err(Refusal::Residual);
        }
        if libm::hypotf(tx, ty) > cfg.max_shift_m || libm::fabsf(th) > cfg.max_turn_rad {
            return Err(Refusal::TooFar);
        }
        // As a pose: q' = R(q − pivot) + pivot + t = R q + (pivot + t − R pivot).
        let (s, c) = (libm::sinf(th), libm::cosf(th));
        let correction = Pose2::new(
            pivot.x + tx - (c * pivot.x - s * pivot.y),
            pivot.y + ty - (s * pivot.x + c * pivot.y),
            th,
        );
        Ok((correction, pairs, rms))
    }
}

#[cfg(test)]
mod test {
    use super::*;

    /// Ranges of a rectangular room `[-2, 3] × [-1.5, 2]` with a box at (1, 1), seen by a
    /// LiDAR at `lidar` (map frame), one ray a degree.
    fn room_ranges(lidar: Pose2) -> [f32; BINS] {
        let walls = [
            (Point2::new(-2.0, -1.5), Point2::new(3.0, -1.5)),
            (Point2::new(3.0, -1.5), Point2::new(3.0, 2.0)),
            (Point2::new(3.0, 2.0), Point2::new(-2.0, 2.0)),
            (Point2::new(-2.0, 2.0), Point2::new(-2.0, -1.5)),
            (Point2::new(0.8, 0.8), Point2::new(1.2, 0.8)),
            (Point2::new(1.2, 0.8), Point2::new(1.2, 1.2)),
            (Point2::new(1.2, 1.2), Point2::new(0.8, 1.2)),
            (Point2::new(0.8, 1.2), Point2::new(0.8, 0.8)),
        ];
        let mut out = [0.0; BINS];
        for (d, r) in out.iter_mut().enumerate() {
            let a = lidar.theta + (d as f32).to_radians();
            let (dx, dy) = (libm::cosf(a), libm::sinf(a));
            let mut best = f32::INFINITY;
            for (p, q) in walls {
                // Ray o + t·d against segment p + u·(q − p).
                let (ex, ey) = (q.x - p.x, q.y - p.y);
                let den = dx * ey - dy * ex;
                if den.abs() < 1e-9 {
                    continue;
                }
                let (wx, wy) = (p.x - lidar.x, p.y - lidar.y);
                let t = (wx * ey - wy * ex) / den;
                let u = (wx * dy - wy * dx) / den;
                if t > 0.0 && (0.0..=1.0).contains(&u) && t < best {
                    best = t;
                }
            }
            *r = if best <= 3.4 { best } else { 0.0 };
        }
        out
    }

    fn scan(ranges: &[f32], robot: Pose2) -> Scan<'_> {
        Scan {
            ranges,
            start: robot,
            end: robot,
            mount: Pose2::IDENTITY,
        }
    }

    #[test]
    fn a_drifted_pose_is_pulled_back_onto_the_keyframe() {
        let mut m = ScanMatcher::new(ScanMatchConfig::default());
        let first = Pose2::new(0.0, 0.0, 0.3);
        let r0 = room_ranges(first);
        assert_eq!(m.update(&scan(&r0, first)), MatchOutcome::Keyframe);
        // The robot really moved to `truth`; odometry says `drifted` (4° and 8 cm off).
        let truth = Pose2::new(0.15, 0.1, 0.4);
        let drifted = Pose2::new(0.22, 0.07, 0.4 + 4f32.to_radians());
        let r1 = room_ranges(truth);
        let MatchOutcome::Matched { correction, .. } = m.update(&scan(&r1, drifted)) else {
            panic!("no match");
        };
        let fixed = correction.compose(&drifted);
        assert!(
            libm::hypotf(fixed.x - truth.x, fixed.y - truth.y) < 0.01,
            "{fixed:?} vs {truth:?}"
        );
        assert!(wrap_angle(fixed.theta - truth.theta).abs() < 0.3f32.to_radians());
        assert_eq!(m.stats().matched, 1);
    }

    #[test]
    fn drift_does_not_build_up_over_a_walk_through_the_room() {
        let mut m = ScanMatcher::new(ScanMatchConfig::default());
        let (mut odo, mut truth) = (Pose2::IDENTITY, Pose2::IDENTITY);
        // Forty revolutions: 2 cm and 1.5° a revolution, odometry over-turning by 5 %.
        for _ in 0..40 {
            let r = room_ranges(truth);
            let sc = scan(&r, odo);
            if let MatchOutcome::Matched { correction, .. } = m.update(&sc) {
                odo = correction.compose(&odo);
            }
            truth = truth.compose(&Pose2::new(0.02, 0.0, 1.5f32.to_radians()));
            odo = odo.compose(&Pose2::new(0.02, 0.0, 1.05 * 1.5f32.to_radians()));
        }
        let r = room_ranges(truth);
        if let MatchOutcome::Matched { correction, .. } = m.update(&scan(&r, odo)) {
            odo = correction.compose(&odo);
        }
        // Unmatched, the heading would be 3° off.
        let err = wrap_angle(odo.theta - truth.theta).abs().to_degrees();
        assert!(err < 0.5, "heading {err}° off");
        assert!(
            libm::hypotf(odo.x - truth.x, odo.y - truth.y) < 0.03,
            "{odo:?} vs {truth:?}"
        );
        assert!(m.stats().matched >= 35, "{:?}", m.stats());
    }

    #[test]
    fn a_corridor_cannot_fix_its_length_and_says_so() {
        // Two long parallel walls and nothing else.
        let mut r = [0.0f32; BINS];
        for (d, x) in r.iter_mut().enumerate() {
            let a = (d as f32).to_radians();
            let s = libm::sinf(a);
            if s.abs() > 0.35 {
                let t = 0.8 / s.abs();
                if t < 3.4 {
                    *x = t;
                }
            }
        }
        let mut m = ScanMatcher::new(ScanMatchConfig::default());
        assert_eq!(m.update(&scan(&r, Pose2::IDENTITY)), MatchOutcome::Keyframe);
        let out = m.update(&scan(&r, Pose2::new(0.1, 0.0, 0.0)));
        assert_eq!(out, MatchOutcome::Refused(Refusal::Degenerate));
    }

    #[test]
    fn an_empty_or_changed_view_is_refused() {
        let mut m = ScanMatcher::new(ScanMatchConfig::default());
        let p = Pose2::IDENTITY;
        let r0 = room_ranges(p);
        m.update(&scan(&r0, p));
        let none = [0.0f32; BINS];
        assert_eq!(
            m.update(&scan(&none, p)),
            MatchOutcome::Refused(Refusal::FewPairs)
        );
        // Another room altogether: everything 3.1 m away.
        let far = [3.1f32; BINS];
        assert!(matches!(m.update(&scan(&far, p)), MatchOutcome::Refused(_)));
    }
}
