//! The robot: a TurtleBot3 Burger differential drive with wheel slip, its wheel encoders
//! (4,096 ticks a turn), and the scripted motions that drive it.
//!
//! Motion is integrated exactly along arcs. Slip makes the ground move less (or more) than the
//! wheels turned: each step, each wheel's ground travel is its rotation × (1 − s), s drawn from
//! a zero-mean noise ([`RobotConfig::slip_sigma`]). Encoders count the wheels' rotation, so
//! odometry drifts from the truth as on a real robot.

use perception::geometry::{Point2, Pose2, wrap_angle};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::world::World;

/// Wheel radius, metres (TurtleBot3 Burger).
pub const WHEEL_RADIUS: f32 = 0.033;
/// Distance between the wheels, metres (Burger).
pub const WHEEL_SEPARATION: f32 = 0.160;
/// Encoder ticks per wheel turn (DYNAMIXEL XL430).
pub const TICKS_PER_REV: f64 = 4096.0;
/// Fastest wheel speed, rad/s (0.22 m/s).
pub const MAX_WHEEL_RAD_S: f32 = 0.22 / WHEEL_RADIUS;

/// How the robot moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Standing still.
    Still,
    /// The study's motion: rotation in place, angular speed `amplitude · sin(2πt/period)`.
    Oscillate {
        /// Peak angular speed, rad/s.
        amplitude_rad_s: f32,
        /// Period, s.
        period_s: f32,
    },
    /// Turning in place at a constant rate (compass calibration).
    Spin {
        /// Angular speed, rad/s.
        rate_rad_s: f32,
    },
    /// A tour of random waypoints with clearance, driven turn-then-go at `speed_m_s`.
    Tour {
        /// Cruise speed, m/s.
        speed_m_s: f32,
    },
}

/// Robot settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotConfig {
    /// The motion script.
    pub motion: Motion,
    /// Standard deviation of the slip fraction (a per-wheel process correlated over
    /// [`SLIP_TAU_S`], as on a real floor: a patch of carpet, a turn on a smooth tile).
    pub slip_sigma: f32,
}

/// Correlation time of the slip process, s.
pub const SLIP_TAU_S: f32 = 1.0;
/// Largest per-wheel systematic travel error (effective radius vs nominal), fraction.
pub const SLIP_BIAS_MAX: f32 = 0.003;

impl Default for RobotConfig {
    fn default() -> Self {
        RobotConfig {
            motion: Motion::Oscillate {
                amplitude_rad_s: 0.6,
                period_s: 8.0,
            },
            slip_sigma: 0.02,
        }
    }
}

/// The simulated robot.
#[derive(Debug, Clone)]
pub struct Robot {
    cfg: RobotConfig,
    /// True pose in the world.
    pub pose: Pose2,
    /// Wheel rotation since start, radians (left, right): what the encoders see.
    wheel_rad: [f64; 2],
    t: f64,
    waypoints: Vec<Point2>,
    next_wp: usize,
    rng: ChaCha8Rng,
    /// Per-wheel slip: systematic part and correlated random part.
    slip_bias: [f32; 2],
    slip_state: [f32; 2],
}

impl Robot {
    /// A robot at the world's start spot with a random heading.
    pub fn new(world: &World, cfg: RobotConfig, seed: u64) -> Robot {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let heading = rng.random_range(-core::f32::consts::PI..core::f32::consts::PI);
        let start = world.robot_start;
        let mut waypoints = Vec::new();
        if let Motion::Tour { .. } = cfg.motion {
            let mut at = start;
            for _ in 0..200 {
                if waypoints.len() >= 12 {
                    break;
                }
                if let Some(p) = world.free_point(&mut rng, 0.4)
                    && p.distance(at) > 0.8
                    && world.path_clear(at, p, 0.3)
                {
                    waypoints.push(p);
                    at = p;
                }
            }
            // Close the loop when the way back is clear.
            if waypoints.len() > 1 && world.path_clear(at, start, 0.3) {
                waypoints.push(start);
            }
        }
        Robot {
            cfg,
            pose: Pose2::new(start.x, start.y, heading),
            wheel_rad: [0.0; 2],
            t: 0.0,
            waypoints,
            next_wp: 0,
            slip_bias: if cfg.slip_sigma > 0.0 {
                [
                    rng.random_range(-SLIP_BIAS_MAX..SLIP_BIAS_MAX),
                    rng.random_range(-SLIP_BIAS_MAX..SLIP_BIAS_MAX),
                ]
            } else {
                [0.0; 2]
            },
            slip_state: [0.0; 2],
            rng,
        }
    }

    /// Moves the robot to `pose` (for a calibration spin somewhere else than the start).
    pub fn place(&mut self, pose: Pose2) {
        self.pose = pose;
    }

    /// Simulation time, s.
    pub fn time_s(&self) -> f64 {
        self.t
    }

    /// The waypoints of a tour (empty otherwise).
    pub fn waypoints(&self) -> &[Point2] {
        &self.waypoints
    }

    /// Encoder counts (left, right), cumulative, as the OpenCR reports them (i32 wraps).
    pub fn ticks(&self) -> (i32, i32) {
        let t = |rad: f64| ((rad / core::f64::consts::TAU * TICKS_PER_REV).floor() as i64) as i32;
        (t(self.wheel_rad[0]), t(self.wheel_rad[1]))
    }

    /// Commanded (v, ω) at the current state.
    fn command(&mut self) -> (f32, f32) {
        match self.cfg.motion {
            Motion::Still => (0.0, 0.0),
            Motion::Oscillate {
                amplitude_rad_s,
                period_s,
            } => {
                let phase = core::f64::consts::TAU * self.t / f64::from(period_s);
                (0.0, amplitude_rad_s * phase.sin() as f32)
            }
            Motion::Spin { rate_rad_s } => (0.0, rate_rad_s),
            Motion::Tour { speed_m_s } => {
                let Some(&target) = self.waypoints.get(self.next_wp) else {
                    return (0.0, 0.0);
                };
                let dx = target.x - self.pose.x;
                let dy = target.y - self.pose.y;
                if dx.hypot(dy) < 0.08 {
                    self.next_wp = (self.next_wp + 1) % self.waypoints.len();
                    return (0.0, 0.0);
                }
                let err = wrap_angle(dy.atan2(dx) - self.pose.theta);
                let w = (2.0 * err).clamp(-1.2, 1.2);
                if err.abs() > 0.25 {
                    (0.0, w)
                } else {
                    (speed_m_s, w)
                }
            }
        }
    }

    /// Advances the robot by `dt` seconds.
    pub fn step(&mut self, dt: f32) {
        let (v, w) = self.command();
        // Wheel speeds from (v, ω), limited like the real motors.
        let half = WHEEL_SEPARATION / 2.0;
        let wl = ((v - w * half) / WHEEL_RADIUS).clamp(-MAX_WHEEL_RAD_S, MAX_WHEEL_RAD_S);
        let wr = ((v + w * half) / WHEEL_RADIUS).clamp(-MAX_WHEEL_RAD_S, MAX_WHEEL_RAD_S);
        let (dl, dr) = (wl * dt, wr * dt);
        self.wheel_rad[0] += f64::from(dl);
        self.wheel_rad[1] += f64::from(dr);
        // Ground travel with slip: an Ornstein–Uhlenbeck process per wheel plus its bias.
        let a = (dt / SLIP_TAU_S).min(1.0);
        let kick = self.cfg.slip_sigma * (2.0 * a).sqrt();
        for w in 0..2 {
            let g = crate::noise::unit(&mut self.rng);
            self.slip_state[w] += -self.slip_state[w] * a + kick * g;
        }
        let sl = dl * WHEEL_RADIUS * (1.0 - self.slip_bias[0] - self.slip_state[0]);
        let sr = dr * WHEEL_RADIUS * (1.0 - self.slip_bias[1] - self.slip_state[1]);
        let ds = (sl + sr) / 2.0;
        let dth = (sr - sl) / WHEEL_SEPARATION;
        let th = self.pose.theta;
        let (x, y) = if dth.abs() < 1e-6 {
            (self.pose.x + ds * th.cos(), self.pose.y + ds * th.sin())
        } else {
            let r = ds / dth;
            (
                self.pose.x + r * ((th + dth).sin() - th.sin()),
                self.pose.y - r * ((th + dth).cos() - th.cos()),
            )
        };
        self.pose = Pose2::new(x, y, th + dth);
        self.t += f64::from(dt);
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::world::World;

    #[test]
    fn oscillation_turns_in_place_and_ticks_follow() {
        let w = World::random_room(2);
        let mut r = Robot::new(
            &w,
            RobotConfig {
                slip_sigma: 0.0,
                ..RobotConfig::default()
            },
            1,
        );
        let start = r.pose;
        for _ in 0..2000 {
            r.step(0.002); // 4 s: half a period, all turning one way
        }
        assert!(Point2::new(r.pose.x, r.pose.y).distance(Point2::new(start.x, start.y)) < 1e-3);
        // ∫ 0.6 sin(2πt/8) dt over 0..4 = 0.6·8/π ≈ 1.528 rad.
        let turned = wrap_angle(r.pose.theta - start.theta);
        assert!((turned - 1.528).abs() < 0.02, "{turned}");
        let (l, rt) = r.ticks();
        assert!(l < 0 && rt > 0 && (l + rt).abs() <= 2);
        // Ticks ↔ heading: Δθ = (R − L)·2π/4096 · r / b.
        let th = f64::from(rt - l) * core::f64::consts::TAU / 4096.0 * 0.033 / 0.16;
        assert!((th as f32 - turned).abs() < 0.01);
    }

    #[test]
    fn tour_moves_and_keeps_clear() {
        for seed in 0..5 {
            let w = World::random_room(seed);
            let cfg = RobotConfig {
                motion: Motion::Tour { speed_m_s: 0.15 },
                slip_sigma: 0.01,
            };
            let mut r = Robot::new(&w, cfg, seed);
            let mut travelled = 0.0;
            let mut last = Point2::new(r.pose.x, r.pose.y);
            for _ in 0..30_000 {
                r.step(0.002); // 60 s
                let p = Point2::new(r.pose.x, r.pose.y);
                travelled += p.distance(last);
                last = p;
                assert!(
                    w.clearance(p) > 0.12,
                    "seed {seed}: robot hit something at {p:?}"
                );
            }
            if r.waypoints().len() > 1 {
                assert!(travelled > 2.0, "seed {seed}: travelled {travelled} m");
            }
        }
    }
}
