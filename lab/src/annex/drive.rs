//! The annex's robot: a TurtleBot3 Burger's differential drive on a script (turning in place,
//! or a tour of straight legs between free points), and its wheel encoders.
//!
//! The ground follows the script exactly; the encoders do not: each wheel's ticks carry a
//! fixed scale error (a tyre a little larger or worn, ±0.5 %) and white noise, so odometry
//! drifts the way a real one does without the robot ever leaving its planned path.

use perception::geometry::{Point2, Pose2, wrap_angle};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::plan::Plan;

/// Wheel radius, m (TurtleBot3 Burger, as umbra's default `[odometry]`).
pub const WHEEL_RADIUS: f64 = 0.033;
/// Wheel separation, m.
pub const WHEEL_SEPARATION: f64 = 0.160;
/// Ticks per wheel turn.
pub const TICKS_PER_REV: f64 = 4096.0;

/// A leg of a tour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Leg {
    /// Turn in place for `duration` s at `rate` (rad/s, signed).
    Turn {
        /// Seconds.
        duration: f64,
        /// rad/s.
        rate: f64,
    },
    /// Drive straight at `speed` (m/s) for `duration` s.
    Straight {
        /// Seconds.
        duration: f64,
        /// m/s.
        speed: f64,
    },
}

/// How the robot moves.
#[derive(Debug, Clone, PartialEq)]
pub enum Script {
    /// Turning in place: `rate + amp · sin(2πt / period)`.
    Turn {
        /// Constant part, rad/s.
        rate: f64,
        /// Oscillating part, rad/s.
        amp: f64,
        /// Its period, s.
        period: f64,
    },
    /// A tour.
    Tour(Vec<Leg>),
}

impl Script {
    /// In words.
    pub fn name(&self) -> &'static str {
        match self {
            Script::Turn { .. } => "turning in place",
            Script::Tour(_) => "touring",
        }
    }

    fn command(&self, t: f64) -> (f64, f64) {
        match self {
            Script::Turn { rate, amp, period } => (
                0.0,
                rate + amp * (core::f64::consts::TAU * t / period).sin(),
            ),
            Script::Tour(legs) => {
                let mut s = t;
                for leg in legs {
                    match *leg {
                        Leg::Turn { duration, rate } if s < duration => return (0.0, rate),
                        Leg::Straight { duration, speed } if s < duration => return (speed, 0.0),
                        Leg::Turn { duration, .. } | Leg::Straight { duration, .. } => {
                            s -= duration
                        }
                    }
                }
                (0.0, 0.0)
            }
        }
    }
}

/// Plans a script of `seconds` from `start` in `plan`: half of the runs turn in place.
pub fn script(rng: &mut ChaCha8Rng, plan: &Plan, start: Pose2, seconds: f64, tour: bool) -> Script {
    if !tour {
        return Script::Turn {
            rate: if rng.random_bool(0.5) {
                rng.random_range(0.3..0.7)
            } else {
                0.0
            },
            amp: rng.random_range(0.3..0.8),
            period: rng.random_range(6.0..12.0),
        };
    }
    let mut legs = Vec::new();
    let (mut at, mut heading, mut total) =
        (Point2::new(start.x, start.y), f64::from(start.theta), 0.0);
    let mut stuck = 0;
    while total < seconds && stuck < 50 {
        let Some(q) = plan.free_point(rng, 0.4) else {
            break;
        };
        if q.distance(at) < 1.0 || !plan.path_free(at, q, 0.3) {
            stuck += 1;
            continue;
        }
        stuck = 0;
        let want = f64::from((q.y - at.y).atan2(q.x - at.x));
        let turn = f64::from(wrap_angle((want - heading) as f32));
        let rate = 0.9f64.copysign(turn);
        legs.push(Leg::Turn {
            duration: turn.abs() / 0.9,
            rate,
        });
        let speed = rng.random_range(0.12..0.22);
        let duration = f64::from(q.distance(at)) / speed;
        legs.push(Leg::Straight { duration, speed });
        total += turn.abs() / 0.9 + duration;
        at = q;
        heading = want;
    }
    if legs.is_empty() {
        legs.push(Leg::Turn {
            duration: seconds,
            rate: 0.5,
        });
    }
    Script::Tour(legs)
}

/// The robot: true pose and encoders.
#[derive(Debug, Clone)]
pub struct Drive {
    /// True pose, world frame.
    pub pose: Pose2,
    x: f64,
    y: f64,
    th: f64,
    t: f64,
    wheel: [f64; 2],
    scale: [f64; 2],
    rng: ChaCha8Rng,
    script: Script,
}

impl Drive {
    /// A robot at `start` on `script`.
    pub fn new(start: Pose2, script: Script, mut rng: ChaCha8Rng) -> Drive {
        let scale = [
            1.0 + rng.random_range(-0.005..0.005),
            1.0 + rng.random_range(-0.005..0.005),
        ];
        Drive {
            pose: start,
            x: f64::from(start.x),
            y: f64::from(start.y),
            th: f64::from(start.theta),
            t: 0.0,
            wheel: [0.0; 2],
            scale,
            rng,
            script,
        }
    }

    /// The script.
    pub fn script(&self) -> &Script {
        &self.script
    }

    /// Runs the robot on to time `t` (1 ms steps).
    pub fn advance_to(&mut self, t: f64) {
        while self.t < t {
            let dt = (t - self.t).min(0.001);
            let (v, w) = self.script.command(self.t + dt / 2.0);
            // Ground: exact arc.
            let mid = self.th + w * dt / 2.0;
            self.x += v * dt * mid.cos();
            self.y += v * dt * mid.sin();
            self.th += w * dt;
            // Wheels turn by what the ground needs; the encoders count with their scale error.
            let wl = (v - w * WHEEL_SEPARATION / 2.0) / WHEEL_RADIUS;
            let wr = (v + w * WHEEL_SEPARATION / 2.0) / WHEEL_RADIUS;
            for (k, rate) in [wl, wr].into_iter().enumerate() {
                let noise = self.rng.random_range(-0.02..0.02) * rate.abs();
                self.wheel[k] += (rate + noise) * dt * self.scale[k];
            }
            self.t += dt;
        }
        self.pose = Pose2::new(self.x as f32, self.y as f32, wrap_angle(self.th as f32));
    }

    /// Cumulative encoder ticks (left, right).
    pub fn ticks(&self) -> (i64, i64) {
        let k = TICKS_PER_REV / core::f64::consts::TAU;
        (
            (self.wheel[0] * k).round() as i64,
            (self.wheel[1] * k).round() as i64,
        )
    }
}
