//! Heading and position drift of three pose estimators on the simulated robot, with wheel slip
//! and compass disturbances on:
//!
//! * **odometry** alone (encoders only);
//! * **compass overwrite**, the study's rule: odometry's heading replaced by the compass heading
//!   at every reading;
//! * **fusion**, `perception::pose::PoseFilter`.
//!
//! Each scenario first spins the robot in place for two turns in the room's most open spot and
//! fits the compass's hard-iron offset and clean-field reference from those readings (what
//! `umbra calibrate-compass` does), then drives from the start spot for the given time with
//! encoders and compass sampled at 20 Hz. Errors are against the simulator's true pose
//! in the map frame (the robot's start pose).

use perception::geometry::{Pose2, wrap_angle};
use perception::pose::{
    HardIronFit, HeadingConfig, OdometryConfig, PoseFilter, TickCounter, integrate,
};

use sim::compass::{Compass, CompassConfig};
use sim::dataset::scenario_seed;
use sim::robot::{Motion, Robot, RobotConfig};
use sim::world::{World, WorldConfig};

/// Sample period of encoders and compass, s (the vendor node's 50 ms).
pub const SAMPLE_S: f32 = 0.05;
/// Robot integration steps per sample.
const SUBSTEPS: usize = 10;

/// Errors of one estimator over one run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Drift {
    /// RMS heading error over the run, degrees.
    pub heading_rms_deg: f64,
    /// Mean signed heading error over the run, degrees (a constant offset shows here).
    pub heading_mean_deg: f64,
    /// Heading error at the end, degrees (absolute).
    pub heading_final_deg: f64,
    /// Position error at the end, metres.
    pub position_final_m: f64,
}

/// One scenario's result.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalRow {
    /// Scenario index.
    pub scenario: usize,
    /// `oscillate` or `tour`.
    pub motion: &'static str,
    /// Room description.
    pub room: String,
    /// Odometry alone.
    pub odometry: Drift,
    /// The study's compass overwrite.
    pub overwrite: Drift,
    /// Our fusion.
    pub fusion: Drift,
    /// Compass readings the fusion rejected, of all.
    pub rejected: (u32, u32),
    /// Hard-iron fit error, µT.
    pub hard_iron_error_ut: f32,
}

struct Acc {
    sq: f64,
    sum: f64,
    n: f64,
}

impl Acc {
    fn add(&mut self, err: f32) {
        self.sq += f64::from(err) * f64::from(err);
        self.sum += f64::from(err);
        self.n += 1.0;
    }

    fn drift(&self, est: &Pose2, truth: &Pose2) -> Drift {
        Drift {
            heading_rms_deg: (self.sq / self.n.max(1.0)).sqrt().to_degrees(),
            heading_mean_deg: (self.sum / self.n.max(1.0)).to_degrees(),
            heading_final_deg: f64::from(wrap_angle(est.theta - truth.theta).abs()).to_degrees(),
            position_final_m: f64::from(
                ((est.x - truth.x).powi(2) + (est.y - truth.y).powi(2)).sqrt(),
            ),
        }
    }
}

/// Runs scenario `i` of `seed` for `seconds` with the given motion.
pub fn run(i: usize, seed: u64, seconds: f32, motion: Motion) -> EvalRow {
    let s = scenario_seed(seed, i);
    let world = World::generate(s, &WorldConfig::default());
    let mut compass = Compass::new(&world, CompassConfig::default(), s ^ 1);
    // Calibration, as a user does it: two turns in place at 0.5 rad/s in the most open spot
    // (least disturbed of 200 candidates), giving the hard iron and the clean-field reference.
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(s ^ 4);
    let spot = (0..200)
        .filter_map(|_| world.free_point(&mut rng, 0.4))
        .min_by(|a, b| {
            compass
                .disturbance_ut(*a)
                .total_cmp(&compass.disturbance_ut(*b))
        })
        .unwrap_or(world.robot_start);
    let spin_cfg = RobotConfig {
        motion: Motion::Spin { rate_rad_s: 0.5 },
        slip_sigma: 0.0,
    };
    let mut spin = Robot::new(&world, spin_cfg, s ^ 2);
    spin.place(Pose2::new(spot.x, spot.y, 0.0));
    let mut fit = HardIronFit::default();
    let mut vertical = 0.0f32;
    let spin_samples = (2.0 * core::f32::consts::TAU / 0.5 / SAMPLE_S) as usize;
    for _ in 0..spin_samples {
        for _ in 0..SUBSTEPS {
            spin.step(SAMPLE_S / SUBSTEPS as f32);
        }
        let m = compass.read(&spin.pose);
        fit.add(m[0], m[1]);
        vertical += m[2] / spin_samples as f32;
    }
    let fitted = fit.solve();
    let hi = fitted.map_or((0.0, 0.0), |h| (h.x_ut, h.y_ut));
    let hard_iron_error_ut = ((hi.0 - compass.hard_iron_ut[0]).powi(2)
        + (hi.1 - compass.hard_iron_ut[1]).powi(2))
    .sqrt();

    let mut robot = Robot::new(
        &world,
        RobotConfig {
            motion,
            slip_sigma: 0.02,
        },
        s ^ 3,
    );
    let map = robot.pose.inverse();
    let odo_cfg = OdometryConfig::BURGER;
    let mut fusion = PoseFilter::new(odo_cfg, HeadingConfig::default(), hi);
    if let Some(h) = fitted {
        fusion.set_field_reference(h.field_ut, vertical);
    }
    let mut odometry = PoseFilter::new(odo_cfg, HeadingConfig::default(), hi);
    let mut overwrite = Pose2::IDENTITY;
    let mut ow_ticks = TickCounter::default();
    let (mut a_odo, mut a_ow, mut a_fu) = (
        Acc {
            sq: 0.0,
            sum: 0.0,
            n: 0.0,
        },
        Acc {
            sq: 0.0,
            sum: 0.0,
            n: 0.0,
        },
        Acc {
            sq: 0.0,
            sum: 0.0,
            n: 0.0,
        },
    );
    let samples = (seconds / SAMPLE_S) as usize;
    // The encoders' zero: a sample at t = 0, before the robot moves (the map frame's origin).
    let (l0, r0) = robot.ticks();
    odometry.encoders(l0, r0, 0.0);
    fusion.encoders(l0, r0, 0.0);
    ow_ticks.step(l0, r0, &odo_cfg);
    let mut truth = Pose2::IDENTITY;
    for _ in 0..samples {
        for _ in 0..SUBSTEPS {
            robot.step(SAMPLE_S / SUBSTEPS as f32);
        }
        let (l, r) = robot.ticks();
        let m = compass.read(&robot.pose);
        truth = map.compose(&robot.pose);
        odometry.encoders(l, r, SAMPLE_S);
        fusion.encoders(l, r, SAMPLE_S);
        fusion.compass_3d(m[0], m[1], m[2]);
        let step = ow_ticks.step(l, r, &odo_cfg);
        let dth = match fusion.compass_heading(m[0], m[1]) {
            Some(h) => wrap_angle(h - overwrite.theta),
            None => step.dtheta(&odo_cfg),
        };
        overwrite = integrate(&overwrite, step.distance(), dth);
        a_odo.add(wrap_angle(odometry.pose().theta - truth.theta));
        a_ow.add(wrap_angle(overwrite.theta - truth.theta));
        a_fu.add(wrap_angle(fusion.pose().theta - truth.theta));
    }
    EvalRow {
        scenario: i,
        motion: match motion {
            Motion::Tour { .. } => "tour",
            Motion::Oscillate { .. } => "oscillate",
            Motion::Spin { .. } => "spin",
            Motion::Still => "still",
        },
        room: world.describe(),
        odometry: a_odo.drift(&odometry.pose(), &truth),
        overwrite: a_ow.drift(&overwrite, &truth),
        fusion: a_fu.drift(&fusion.pose(), &truth),
        rejected: (
            fusion.compass_rejected(),
            fusion.compass_rejected() + fusion.compass_accepted(),
        ),
        hard_iron_error_ut,
    }
}

/// The standard evaluation: `n` scenarios each with oscillation and with a tour.
pub fn table(seed: u64, n: usize, seconds: f32) -> Vec<EvalRow> {
    let mut rows = Vec::new();
    for i in 0..n {
        rows.push(run(i, seed, seconds, RobotConfig::default().motion));
        rows.push(run(i, seed, seconds, Motion::Tour { speed_m_s: 0.15 }));
    }
    rows
}

/// The table as Markdown.
pub fn markdown(rows: &[EvalRow]) -> String {
    let mut s = String::from(
        "| scenario | motion | heading RMS ° odometry / overwrite / **fusion** | mean heading error ° o / w / **f** | final heading ° o / w / **f** | final position m o / w / **f** | compass rejected | hard-iron fit error µT |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {:.2} / {:.2} / **{:.2}** | {:.2} / {:.2} / **{:.2}** | {:.2} / {:.2} / **{:.2}** | {:.3} / {:.3} / **{:.3}** | {} of {} | {:.2} |\n",
            r.scenario,
            r.motion,
            r.odometry.heading_rms_deg,
            r.overwrite.heading_rms_deg,
            r.fusion.heading_rms_deg,
            r.odometry.heading_mean_deg,
            r.overwrite.heading_mean_deg,
            r.fusion.heading_mean_deg,
            r.odometry.heading_final_deg,
            r.overwrite.heading_final_deg,
            r.fusion.heading_final_deg,
            r.odometry.position_final_m,
            r.overwrite.position_final_m,
            r.fusion.position_final_m,
            r.rejected.0,
            r.rejected.1,
            r.hard_iron_error_ut
        );
    }
    s
}
