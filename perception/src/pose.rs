//! Pose from wheel encoders and a compass: differential-drive odometry, hard-iron calibration,
//! and a heading filter that trusts odometry in the short term and the compass in the long term.
//!
//! ## Odometry
//!
//! Ticks are cumulative counters that may wrap (the OpenCR reports i32); each update takes the
//! wrapping difference, so a wrap between two samples costs nothing. Left/right wheel travel
//! `dl, dr` give `d = (dl + dr)/2` and `Δθ = (dr − dl)/b`; the position advances along the
//! mid-step heading.
//!
//! ## Heading filter
//!
//! A one-state Kalman filter on θ. Prediction adds the odometry's Δθ and grows the variance by
//! `(slip · |Δθ_wheels|)² + drift² · dt`, where `|Δθ_wheels| = (|dl| + |dr|)/b` is how much the
//! wheels moved (slip scales with it, also when turning in place). A compass reading is used only
//! if its horizontal field strength is within [`HeadingConfig::field_tolerance`] of the reference
//! (a disturbance near steel changes the strength) and its innovation is within
//! [`HeadingConfig::gate_sigmas`] standard deviations of the innovation (unless the filter has been without a compass for longer than
//! [`HeadingConfig::regain_after_s`]); then `θ += K·(θ_compass − θ)` with
//! `K = P / (P + σ_c²)`. So the gain is not a tuned constant: it follows from the documented
//! noise figures — large after a long drive without a compass, small when odometry has just
//! been corrected. The compass's zero (north in the map frame) is the mean of its first
//! readings, taken as the robot's start heading (the map frame's x axis).
//!
//! The study overwrote odometry's heading with the raw compass (`CompassOverwrite` in the
//! evaluation); odometry alone drifts without bound; the filter is measured against both in
//! `lab::pose_eval` (the `umbra-lab` crate).

use crate::geometry::{Pose2, wrap_angle};

/// Robot geometry and encoder resolution.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OdometryConfig {
    /// Wheel radius, m.
    pub wheel_radius_m: f32,
    /// Distance between the wheels, m.
    pub wheel_separation_m: f32,
    /// Encoder ticks per wheel turn.
    pub ticks_per_rev: f32,
}

impl OdometryConfig {
    /// TurtleBot3 Burger: r 0.033 m, b 0.160 m, 4096 ticks.
    pub const BURGER: OdometryConfig = OdometryConfig {
        wheel_radius_m: 0.033,
        wheel_separation_m: 0.160,
        ticks_per_rev: 4096.0,
    };

    /// Metres of travel per tick.
    pub fn m_per_tick(&self) -> f32 {
        2.0 * core::f32::consts::PI * self.wheel_radius_m / self.ticks_per_rev
    }
}

impl Default for OdometryConfig {
    fn default() -> Self {
        Self::BURGER
    }
}

/// One odometry step: wheel travel in metres.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WheelStep {
    /// Left wheel travel, m.
    pub left_m: f32,
    /// Right wheel travel, m.
    pub right_m: f32,
}

impl WheelStep {
    /// Heading change, rad (counter-clockwise positive).
    pub fn dtheta(&self, cfg: &OdometryConfig) -> f32 {
        (self.right_m - self.left_m) / cfg.wheel_separation_m
    }

    /// Forward travel of the centre, m.
    pub fn distance(&self) -> f32 {
        (self.left_m + self.right_m) / 2.0
    }
}

/// Turns cumulative tick counters into wheel steps (wrap-safe).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TickCounter {
    last: Option<(i32, i32)>,
}

impl TickCounter {
    /// `true` before the first sample.
    pub fn is_empty(&self) -> bool {
        self.last.is_none()
    }

    /// The step since the previous sample (zero for the first one).
    pub fn step(&mut self, left: i32, right: i32, cfg: &OdometryConfig) -> WheelStep {
        let step = match self.last {
            Some((l0, r0)) => WheelStep {
                left_m: left.wrapping_sub(l0) as f32 * cfg.m_per_tick(),
                right_m: right.wrapping_sub(r0) as f32 * cfg.m_per_tick(),
            },
            None => WheelStep::default(),
        };
        self.last = Some((left, right));
        step
    }
}

/// Advances `pose` by a wheel step along the mid-step heading, with `dtheta` as the heading
/// change (odometry's own, or a filter's).
pub fn integrate(pose: &Pose2, distance: f32, dtheta: f32) -> Pose2 {
    let mid = pose.theta + dtheta / 2.0;
    Pose2::new(
        pose.x + distance * libm::cosf(mid),
        pose.y + distance * libm::sinf(mid),
        pose.theta + dtheta,
    )
}

/// Streaming least-squares circle fit (Kåsa) of the horizontal magnetometer readings taken
/// while the robot turns: the centre is the hard-iron offset. No storage, any number of samples.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HardIronFit {
    n: f64,
    sx: f64,
    sy: f64,
    sxx: f64,
    syy: f64,
    sxy: f64,
    sxxx: f64,
    syyy: f64,
    sxxy: f64,
    sxyy: f64,
}

/// A fitted hard-iron offset.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HardIron {
    /// Offset, x, µT.
    pub x_ut: f32,
    /// Offset, y, µT.
    pub y_ut: f32,
    /// Radius of the fitted circle: the horizontal field strength, µT.
    pub field_ut: f32,
}

impl HardIronFit {
    /// Adds one reading (µT, robot frame).
    pub fn add(&mut self, x: f32, y: f32) {
        let (x, y) = (f64::from(x), f64::from(y));
        self.n += 1.0;
        self.sx += x;
        self.sy += y;
        self.sxx += x * x;
        self.syy += y * y;
        self.sxy += x * y;
        self.sxxx += x * x * x;
        self.syyy += y * y * y;
        self.sxxy += x * x * y;
        self.sxyy += x * y * y;
    }

    /// Samples added.
    pub fn len(&self) -> usize {
        self.n as usize
    }

    /// `true` if no sample was added.
    pub fn is_empty(&self) -> bool {
        self.n == 0.0
    }

    /// The fit, or `None` if the samples do not span a circle (too few, or no turning).
    /// The 2 × 2 normal equations are solved by Cramer's rule with an explicit degeneracy
    /// test relative to the spread: a closed form, in f64, that a matrix crate would not improve.
    pub fn solve(&self) -> Option<HardIron> {
        if self.n < 8.0 {
            return None;
        }
        let n = self.n;
        let (mx, my) = (self.sx / n, self.sy / n);
        // Centred moments.
        let suu = self.sxx / n - mx * mx;
        let svv = self.syy / n - my * my;
        let suv = self.sxy / n - mx * my;
        let suuu = self.sxxx / n - 3.0 * mx * self.sxx / n + 2.0 * mx * mx * mx;
        let svvv = self.syyy / n - 3.0 * my * self.syy / n + 2.0 * my * my * my;
        let suvv = self.sxyy / n - mx * self.syy / n - 2.0 * my * self.sxy / n + 2.0 * mx * my * my;
        let svuu = self.sxxy / n - my * self.sxx / n - 2.0 * mx * self.sxy / n + 2.0 * my * mx * mx;
        let det = suu * svv - suv * suv;
        let spread = suu + svv;
        if spread < 1e-6 || libm::fabs(det) < 1e-9 * spread * spread {
            return None;
        }
        let b1 = 0.5 * (suuu + suvv);
        let b2 = 0.5 * (svvv + svuu);
        let uc = (b1 * svv - b2 * suv) / det;
        let vc = (b2 * suu - b1 * suv) / det;
        let r2 = uc * uc + vc * vc + suu + svv;
        Some(HardIron {
            x_ut: (uc + mx) as f32,
            y_ut: (vc + my) as f32,
            field_ut: libm::sqrt(r2.max(0.0)) as f32,
        })
    }
}

/// Heading filter settings (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HeadingConfig {
    /// Slip: heading error per radian of wheel motion (1σ).
    pub slip: f32,
    /// Heading drift per √s regardless of motion, rad (1σ).
    pub drift_rad_per_sqrt_s: f32,
    /// Compass heading noise (1σ), rad.
    pub compass_sigma_rad: f32,
    /// Accepted deviation of the horizontal field strength from the reference, as a fraction.
    pub field_tolerance: f32,
    /// Largest innovation accepted, in standard deviations of the innovation
    /// (`√(P + σ_c²)`): a reading that far from the prediction is a disturbance, not news.
    pub gate_sigmas: f32,
    /// After this long without an accepted compass reading the gate is lifted, s.
    pub regain_after_s: f32,
    /// Compass readings averaged to fix north at start.
    pub init_samples: u16,
    /// Magnetic declination plus mount offset, added to the compass heading, rad.
    pub offset_rad: f32,
}

impl Default for HeadingConfig {
    fn default() -> Self {
        HeadingConfig {
            slip: 0.03,
            drift_rad_per_sqrt_s: 0.001,
            compass_sigma_rad: 0.05,
            field_tolerance: 0.08,
            gate_sigmas: 3.0,
            regain_after_s: 20.0,
            init_samples: 10,
            offset_rad: 0.0,
        }
    }
}

/// How far the heading can be trusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PoseQuality {
    /// Compass readings are being fused.
    Good,
    /// Running on odometry: recent compass readings were rejected (disturbance).
    CompassRejected,
    /// No compass (none attached, or not yet initialised).
    NoCompass,
}

/// What happened to one compass reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CompassVerdict {
    /// Used to fix north at start.
    Initialising,
    /// Fused.
    Accepted,
    /// Field strength implausible.
    RejectedField,
    /// Heading too far from the prediction.
    RejectedGate,
}

/// The fused pose estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PoseFilter {
    odo: OdometryConfig,
    cfg: HeadingConfig,
    hard_iron: (f32, f32),
    ticks: TickCounter,
    pose: Pose2,
    var: f32,
    // Compass initialisation: mean of sin/cos of the raw compass angle, and field strength.
    init_n: u16,
    init_s: f32,
    init_c: f32,
    init_field: f32,
    north: Option<f32>,
    field_ref: f32,
    /// Clean-field reference from the calibration: (horizontal strength, vertical reading).
    reference: Option<(f32, f32)>,
    since_fix_s: f32,
    rejected: u32,
    accepted: u32,
    last_verdict: Option<CompassVerdict>,
}

impl PoseFilter {
    /// A filter at the map origin. `hard_iron` is the calibrated offset (x, y) in µT.
    pub fn new(odo: OdometryConfig, cfg: HeadingConfig, hard_iron: (f32, f32)) -> Self {
        PoseFilter {
            odo,
            cfg,
            hard_iron,
            ticks: TickCounter::default(),
            pose: Pose2::IDENTITY,
            var: 0.0,
            init_n: 0,
            init_s: 0.0,
            init_c: 0.0,
            init_field: 0.0,
            north: None,
            field_ref: 0.0,
            reference: None,
            since_fix_s: 0.0,
            rejected: 0,
            accepted: 0,
            last_verdict: None,
        }
    }

    /// The pose in the map frame.
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// Moves the pose by `correction`, a rigid motion of the map frame (a scan match's:
    /// the pose becomes `correction ∘ pose`). North stays where it is: the compass goes on
    /// correcting the heading as before.
    pub fn correct(&mut self, correction: &Pose2) {
        self.pose = correction.compose(&self.pose);
        self.pose.theta = wrap_angle(self.pose.theta);
    }

    /// Heading variance, rad².
    pub fn heading_variance(&self) -> f32 {
        self.var
    }

    /// Compass readings rejected so far.
    pub fn compass_rejected(&self) -> u32 {
        self.rejected
    }

    /// Compass readings fused so far.
    pub fn compass_accepted(&self) -> u32 {
        self.accepted
    }

    /// The quality flag.
    pub fn quality(&self) -> PoseQuality {
        match self.last_verdict {
            None | Some(CompassVerdict::Initialising) => PoseQuality::NoCompass,
            Some(CompassVerdict::Accepted) => PoseQuality::Good,
            Some(_) => PoseQuality::CompassRejected,
        }
    }

    /// Feeds cumulative encoder ticks taken `dt` seconds after the previous sample.
    pub fn encoders(&mut self, left: i32, right: i32, dt: f32) {
        let step = self.ticks.step(left, right, &self.odo);
        let dth = step.dtheta(&self.odo);
        self.pose = integrate(&self.pose, step.distance(), dth);
        let wheel_rad =
            (libm::fabsf(step.left_m) + libm::fabsf(step.right_m)) / self.odo.wheel_separation_m;
        let dt = dt.max(0.0);
        self.var += (self.cfg.slip * wheel_rad) * (self.cfg.slip * wheel_rad)
            + self.cfg.drift_rad_per_sqrt_s * self.cfg.drift_rad_per_sqrt_s * dt;
        self.since_fix_s += dt;
    }

    /// The pose a `fraction` (0..1) of the way from the last encoder sample to a later one at
    /// `(left, right)`, without feeding it: the pose at a time between two samples, assuming
    /// constant wheel speeds over the step. Returns the current pose before the first sample.
    pub fn interpolate(&self, left: i32, right: i32, fraction: f32) -> Pose2 {
        let mut ticks = self.ticks;
        if ticks.is_empty() {
            return self.pose;
        }
        let step = ticks.step(left, right, &self.odo);
        let f = fraction.clamp(0.0, 1.0);
        integrate(&self.pose, step.distance() * f, step.dtheta(&self.odo) * f)
    }

    /// The compass heading in the map frame from a reading (µT, robot frame), if initialised.
    fn raw_angle(&self, mx: f32, my: f32) -> (f32, f32) {
        let (x, y) = (mx - self.hard_iron.0, my - self.hard_iron.1);
        // North appears at angle (north − θ) in the robot frame.
        (libm::atan2f(y, x), libm::hypotf(x, y))
    }

    /// Sets the clean-field reference measured at calibration, away from steel: horizontal
    /// strength (the fitted circle's radius) and the vertical reading (hard iron included). With
    /// it, readings are screened against it — also while north is being fixed, so that a
    /// magnetically disturbed start spot cannot bias north — and the vertical component is
    /// checked too (see [`PoseFilter::compass_3d`]).
    pub fn set_field_reference(&mut self, horizontal_ut: f32, vertical_ut: f32) {
        self.reference = Some((horizontal_ut, vertical_ut));
        self.field_ref = horizontal_ut;
    }

    /// Feeds a magnetometer reading (µT, robot frame) with its vertical component.
    pub fn compass_3d(&mut self, mx: f32, my: f32, mz: f32) -> CompassVerdict {
        self.compass_inner(mx, my, Some(mz))
    }

    /// Feeds a magnetometer reading (µT, robot frame), horizontal components only.
    pub fn compass(&mut self, mx: f32, my: f32) -> CompassVerdict {
        self.compass_inner(mx, my, None)
    }

    /// `true` if the reading matches the clean-field reference (always, without one).
    fn clean(&self, field: f32, mz: Option<f32>) -> bool {
        match self.reference {
            None => true,
            Some((h, v)) => {
                let tol = self.cfg.field_tolerance * h;
                libm::fabsf(field - h) <= tol && mz.is_none_or(|z| libm::fabsf(z - v) <= tol)
            }
        }
    }

    fn compass_inner(&mut self, mx: f32, my: f32, mz: Option<f32>) -> CompassVerdict {
        let (psi, field) = self.raw_angle(mx, my);
        let verdict = match self.north {
            None if !self.clean(field, mz) => CompassVerdict::RejectedField,
            None => {
                // North in the map frame = ψ + θ at the time of the reading.
                let a = psi + self.pose.theta;
                self.init_s += libm::sinf(a);
                self.init_c += libm::cosf(a);
                self.init_field += field;
                self.init_n += 1;
                if self.init_n >= self.cfg.init_samples.max(1) {
                    self.north = Some(libm::atan2f(self.init_s, self.init_c));
                    if self.reference.is_none() {
                        self.field_ref = self.init_field / f32::from(self.init_n);
                    }
                }
                CompassVerdict::Initialising
            }
            Some(north) => {
                let heading = wrap_angle(north - psi + self.cfg.offset_rad);
                let innovation = wrap_angle(heading - self.pose.theta);
                let field_ok = libm::fabsf(field - self.field_ref)
                    <= self.cfg.field_tolerance * self.field_ref
                    && self.clean(field, mz);
                let r = self.cfg.compass_sigma_rad * self.cfg.compass_sigma_rad;
                let gate = self.cfg.gate_sigmas * libm::sqrtf(self.var + r);
                let gate_ok =
                    libm::fabsf(innovation) <= gate || self.since_fix_s > self.cfg.regain_after_s;
                if !field_ok {
                    CompassVerdict::RejectedField
                } else if !gate_ok {
                    CompassVerdict::RejectedGate
                } else {
                    let k = self.var / (self.var + r);
                    self.pose =
                        Pose2::new(self.pose.x, self.pose.y, self.pose.theta + k * innovation);
                    self.var *= 1.0 - k;
                    self.since_fix_s = 0.0;
                    CompassVerdict::Accepted
                }
            }
        };
        match verdict {
            CompassVerdict::RejectedField | CompassVerdict::RejectedGate => self.rejected += 1,
            CompassVerdict::Accepted => self.accepted += 1,
            CompassVerdict::Initialising => {}
        }
        self.last_verdict = Some(verdict);
        verdict
    }

    /// The compass heading the study would have used (overwrite): `None` until initialised.
    pub fn compass_heading(&self, mx: f32, my: f32) -> Option<f32> {
        let (psi, _) = self.raw_angle(mx, my);
        self.north
            .map(|north| wrap_angle(north - psi + self.cfg.offset_rad))
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use core::f32::consts::PI;

    #[test]
    fn ticks_wrap() {
        let cfg = OdometryConfig::BURGER;
        let mut t = TickCounter::default();
        t.step(i32::MAX - 10, i32::MIN + 5, &cfg);
        let s = t.step(i32::MIN + 9, i32::MAX - 4, &cfg);
        assert!((s.left_m - 20.0 * cfg.m_per_tick()).abs() < 1e-7);
        assert!((s.right_m + 10.0 * cfg.m_per_tick()).abs() < 1e-7);
    }

    #[test]
    fn straight_and_turn() {
        let cfg = OdometryConfig::BURGER;
        let one_m = (1.0 / cfg.m_per_tick()) as i32;
        let mut f = PoseFilter::new(cfg, HeadingConfig::default(), (0.0, 0.0));
        f.encoders(0, 0, 0.05);
        f.encoders(one_m, one_m, 0.05);
        assert!((f.pose().x - 1.0).abs() < 1e-3 && f.pose().y.abs() < 1e-6);
        // Quarter turn in place: each wheel travels b·π/4.
        let q = (0.16 * PI / 4.0 / cfg.m_per_tick()) as i32;
        f.encoders(one_m - q, one_m + q, 0.05);
        assert!(
            (f.pose().theta - PI / 2.0).abs() < 2e-3,
            "{}",
            f.pose().theta
        );
        assert!(f.heading_variance() > 0.0);
    }

    #[test]
    fn interpolation_between_samples() {
        let cfg = OdometryConfig::BURGER;
        let one_m = (1.0 / cfg.m_per_tick()) as i32;
        let mut f = PoseFilter::new(cfg, HeadingConfig::default(), (0.0, 0.0));
        assert_eq!(f.interpolate(one_m, one_m, 0.5), Pose2::IDENTITY);
        f.encoders(0, 0, 0.0);
        let half = f.interpolate(one_m, one_m, 0.5);
        assert!((half.x - 0.5).abs() < 1e-3);
        assert_eq!(
            f.pose(),
            Pose2::IDENTITY,
            "interpolation must not feed the filter"
        );
    }

    #[test]
    fn hard_iron_fit_recovers_offset() {
        let mut fit = HardIronFit::default();
        for i in 0..90 {
            let a = i as f32 * 4.0_f32.to_radians();
            fit.add(13.0 + 21.0 * libm::cosf(a), -7.5 + 21.0 * libm::sinf(a));
        }
        let h = fit.solve().unwrap();
        assert!(
            (h.x_ut - 13.0).abs() < 1e-3 && (h.y_ut + 7.5).abs() < 1e-3,
            "{h:?}"
        );
        assert!((h.field_ut - 21.0).abs() < 1e-3);
        let mut flat = HardIronFit::default();
        for _ in 0..20 {
            flat.add(1.0, 2.0);
        }
        assert!(flat.solve().is_none());
    }

    #[test]
    fn compass_corrects_drift_and_rejects_disturbance() {
        let cfg = OdometryConfig::BURGER;
        let mut f = PoseFilter::new(cfg, HeadingConfig::default(), (0.0, 0.0));
        // North along the robot's start heading: field at angle −θ in the robot frame.
        let field = |theta: f32, strength: f32| {
            (strength * libm::cosf(-theta), strength * libm::sinf(-theta))
        };
        for _ in 0..10 {
            f.encoders(0, 0, 0.05);
            let (x, y) = field(0.0, 20.0);
            assert_eq!(f.compass(x, y), CompassVerdict::Initialising);
        }
        // Turning in place: odometry reads 3 % more rotation than happened (slip). After 60
        // steps of 0.1 rad, odometry is 0.18 rad off; the compass holds the filter near truth.
        let mut odo_only = PoseFilter::new(cfg, HeadingConfig::default(), (0.0, 0.0));
        odo_only.encoders(0, 0, 0.05);
        let per_step = (0.08 * 0.1 / cfg.m_per_tick()) as i32;
        let mut truth = 0.0f32;
        for i in 1..=60 {
            let t = i * per_step;
            f.encoders(-t, t, 0.05);
            odo_only.encoders(-t, t, 0.05);
            truth += per_step as f32 * cfg.m_per_tick() / 0.08 / 1.03;
            let (x, y) = field(truth, 20.0);
            assert_eq!(f.compass(x, y), CompassVerdict::Accepted);
        }
        let odo_err = wrap_angle(odo_only.pose().theta - truth).abs();
        let fused_err = wrap_angle(f.pose().theta - truth).abs();
        assert!(odo_err > 0.15, "{odo_err}");
        assert!(fused_err < 0.05, "fused {fused_err} vs odometry {odo_err}");
        assert_eq!(f.quality(), PoseQuality::Good);
        // A disturbed reading (field 30 % stronger) is rejected.
        let (x, y) = field(1.0, 26.0);
        assert_eq!(f.compass(x, y), CompassVerdict::RejectedField);
        assert_eq!(f.quality(), PoseQuality::CompassRejected);
        assert_eq!(f.compass_rejected(), 1);
    }
}
