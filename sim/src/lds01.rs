//! The simulated LDS-01: its reading model (range noise, dropouts, returns beyond the spec
//! range, intensity, rpm jitter) and [`Lds01Sim`], a byte source that plays a scenario as the
//! exact 42-byte packets the real part sends.
//!
//! Angles follow the real part: raw reading `i` is taken at `(359 − i)°` counter-clockwise from
//! the LiDAR's forward axis (see `drivers::lds01::revolution`). The LiDAR sits at the TurtleBot3
//! Burger mount, x = −0.032 m from the robot centre.
//!
//! Dropouts (range 0): a base rate, more on dark surfaces (low reflectivity) and at glancing
//! incidence, and most returns beyond the 3.5 m spec range are lost (a few come back, up to
//! 4.2 m), as in real recordings (~14 % zeros, 4 % beyond 3.5 m). On request a unit returns
//! by the light it receives instead of the dark and glancing terms (`crate::power`).

use drivers::lds01::{PACKET_LEN, PACKETS_PER_REV, RawReading};
use perception::geometry::Pose2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::power::ReceivedPower;
use crate::scenario::{Frame, Scenario, ScenarioConfig};
use crate::wear::Wear;
use crate::world::World;

/// LiDAR mount relative to the robot centre (TurtleBot3 Burger).
pub const LIDAR_MOUNT: Pose2 = Pose2 {
    x: -0.032,
    y: 0.0,
    theta: 0.0,
};

/// LiDAR settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Lds01SimConfig {
    /// Mean motor speed, rpm.
    pub rpm: f32,
    /// Spread of the per-revolution speed, rpm (≈ σ).
    pub rpm_jitter: f32,
    /// Dropout probability on a bright surface hit head-on inside the spec range.
    pub dropout: f64,
    /// Extra dropout probability on a black surface (scaled by 1 − reflectivity).
    pub dark_dropout: f64,
    /// Extra dropout probability at grazing incidence (scaled by how grazing).
    pub glancing_dropout: f64,
    /// Spec range limit, metres.
    pub spec_max_m: f32,
    /// Probability of a return between the spec limit and [`Lds01SimConfig::far_max_m`].
    pub far_return: f64,
    /// No returns beyond this, metres.
    pub far_max_m: f32,
    /// Range noise as a fraction of range above 0.5 m (≈ σ; spec ±5 % taken as ~2σ).
    pub noise_frac: f32,
    /// A real unit's wear (fading returns, mixed pixels); none by default.
    pub wear: Wear,
    /// Returns decided by the received power ([`ReceivedPower`]) instead of the dark and
    /// glancing terms; `None` by default (the additive model).
    pub power: Option<ReceivedPower>,
}

impl Default for Lds01SimConfig {
    fn default() -> Self {
        Lds01SimConfig {
            rpm: 300.0,
            rpm_jitter: 3.0,
            dropout: 0.04,
            dark_dropout: 0.25,
            glancing_dropout: 0.6,
            spec_max_m: 3.5,
            far_return: 0.3,
            far_max_m: 4.2,
            noise_frac: 0.025,
            wear: Wear::default(),
            power: None,
        }
    }
}

impl Lds01SimConfig {
    /// No dropouts at all (for tests that compare ranges with the truth).
    pub fn no_dropouts() -> Self {
        Lds01SimConfig {
            dropout: 0.0,
            dark_dropout: 0.0,
            glancing_dropout: 0.0,
            far_return: 1.0,
            ..Lds01SimConfig::default()
        }
    }
}

impl Lds01SimConfig {
    /// This LiDAR as one unit of a varied world sees it (`WorldConfig::varied`): a dirtier
    /// window or a weaker unit reaches less far (strong returns to 2.6–3.5 m, a few to 0.3–1 m
    /// beyond), and drops out more or less on dark and grazing surfaces; drawn from `seed`.
    pub fn varied(&self, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let spec_max_m = rng.random_range(2.6..3.5f32);
        Lds01SimConfig {
            dropout: rng.random_range(0.02..0.08),
            dark_dropout: rng.random_range(0.1..0.5),
            glancing_dropout: rng.random_range(0.3..0.9),
            spec_max_m,
            far_return: rng.random_range(0.05..0.4),
            far_max_m: spec_max_m + rng.random_range(0.3..1.0f32),
            noise_frac: rng.random_range(0.015..0.035),
            ..self.clone()
        }
    }
}

/// The reading model with its own random stream.
#[derive(Debug, Clone)]
pub struct LidarModel {
    cfg: Lds01SimConfig,
    rng: ChaCha8Rng,
}

impl LidarModel {
    /// A model seeded with `seed`.
    pub fn new(cfg: Lds01SimConfig, seed: u64) -> Self {
        LidarModel {
            cfg,
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// Its settings.
    pub fn cfg(&self) -> &Lds01SimConfig {
        &self.cfg
    }

    fn gauss(&mut self) -> f32 {
        crate::noise::unit(&mut self.rng)
    }

    /// The speed of the next revolution, rpm.
    pub fn draw_rpm(&mut self) -> f32 {
        (self.cfg.rpm + self.gauss() * self.cfg.rpm_jitter).clamp(60.0, 600.0)
    }

    /// Where the spot's other side looks, radians from the beam (a side drawn at random), or
    /// `None` for a unit without mixed pixels (then nothing is drawn).
    pub fn spot_offset(&mut self) -> Option<f32> {
        let w = self.cfg.wear;
        if !w.has_spot() {
            return None;
        }
        let side = if self.rng.random_bool(0.5) { 1.0 } else { -1.0 };
        Some(side * w.half_spot_deg.to_radians())
    }

    /// A reading that found nothing.
    pub fn miss(&mut self) -> RawReading {
        RawReading {
            intensity: self.rng.random_range(0..200),
            range_mm: 0,
            reserved: 0,
        }
    }

    /// A reading of a surface at true range `r` (m), incidence cosine `cos`, `reflectivity`;
    /// `other`: the range the spot's other side hits ([`LidarModel::spot_offset`]), if any.
    pub fn reading(
        &mut self,
        r: f32,
        cos: f32,
        reflectivity: f32,
        other: Option<f32>,
    ) -> RawReading {
        let c = &self.cfg;
        let returns = if r <= c.spec_max_m {
            let p_drop = match c.power {
                Some(power) => 1.0 - (1.0 - c.dropout) * power.return_chance(r, cos, reflectivity),
                None => {
                    c.dropout
                        + c.dark_dropout * f64::from(1.0 - reflectivity)
                        + c.glancing_dropout * f64::from((0.3 - cos).max(0.0) / 0.3)
                }
            } + c.wear.fade_at(r, c.spec_max_m);
            !self.rng.random_bool(p_drop.clamp(0.0, 1.0))
        } else {
            r <= c.far_max_m && self.rng.random_bool(c.far_return * f64::from(reflectivity))
        };
        if !returns {
            return self.miss();
        }
        let wear = self.cfg.wear;
        let r = wear.mix(r, other, &mut self.rng);
        let sigma = if r < 0.5 {
            0.0075
        } else {
            self.cfg.noise_frac * r
        };
        let measured = (r + self.gauss() * sigma).max(0.001);
        let floor: u16 = self.rng.random_range(0..200);
        RawReading {
            intensity: (14_000.0 * reflectivity * cos.max(0.05) / (1.0 + measured * measured))
                as u16
                + floor,
            range_mm: (measured * 1000.0).round().min(f32::from(u16::MAX)) as u16,
            reserved: 0,
        }
    }
}

/// A simulated LDS-01 on a robot, as a stream of packets.
#[derive(Debug, Clone)]
pub struct Lds01Sim {
    scenario: Scenario,
    frame: Box<Frame>,
    next_packet: usize,
    odom: Vec<crate::scenario::OdomSample>,
}

impl Lds01Sim {
    /// The robot oscillating in place in `world`, with the given LiDAR; `seed` drives the rest.
    pub fn new(world: World, cfg: Lds01SimConfig, seed: u64) -> Self {
        let sc = ScenarioConfig {
            lidar: cfg,
            ..ScenarioConfig::default()
        };
        Lds01Sim::from_scenario(Scenario::in_world(world, seed, &sc))
    }

    /// Plays any scenario.
    pub fn from_scenario(scenario: Scenario) -> Self {
        Lds01Sim {
            scenario,
            frame: Box::default(),
            next_packet: PACKETS_PER_REV,
            odom: Vec::new(),
        }
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.scenario.world
    }

    /// The scenario (robot, sensors).
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The revolution being sent (its truth).
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// Duration of one packet slot of the revolution being sent, seconds (`1/rpm`).
    pub fn slot_s(&self) -> f64 {
        if self.frame.rpm > 0.0 {
            1.0 / f64::from(self.frame.rpm)
        } else {
            1.0 / 300.0
        }
    }

    /// Takes the encoder/compass samples of the revolution being sent (they are produced when
    /// its first packet is emitted; drain them after every read so none is lost).
    pub fn drain_odometry(&mut self) -> std::vec::Drain<'_, crate::scenario::OdomSample> {
        self.odom.drain(..)
    }

    /// Emits the next packet's 42 bytes into `out`.
    pub fn emit_packet(&mut self, out: &mut [u8; PACKET_LEN]) {
        if self.next_packet >= PACKETS_PER_REV {
            self.odom.clear();
            self.scenario.next_frame(&mut self.frame, &mut self.odom);
            self.next_packet = 0;
        }
        // A 42-byte array always fits: emit_into cannot fail here.
        let _ = self.frame.packets[self.next_packet].emit_into(out);
        self.next_packet += 1;
    }

    /// Appends `n` revolutions of bytes to `out`.
    pub fn emit_revolutions(&mut self, n: usize, out: &mut Vec<u8>) {
        let mut buf = [0u8; PACKET_LEN];
        for _ in 0..n * PACKETS_PER_REV {
            self.emit_packet(&mut buf);
            out.extend_from_slice(&buf);
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::robot::{Motion, RobotConfig};
    use drivers::lds01::{Lds01Config, Lds01Stream};

    #[test]
    fn a_varied_unit_reaches_less_far_and_is_reproducible() {
        let base = Lds01SimConfig::default();
        for seed in 0..50 {
            let v = base.varied(seed);
            assert_eq!(v, base.varied(seed));
            assert!((2.6..3.5).contains(&v.spec_max_m), "{v:?}");
            assert!(v.far_max_m > v.spec_max_m && v.far_max_m <= v.spec_max_m + 1.0);
            assert!(v.dropout < v.dark_dropout && v.far_return < 0.4);
            assert_eq!(v.rpm, base.rpm);
        }
        assert_ne!(base.varied(1), base.varied(2));
    }
    use drivers::lidar::RevolutionStream as _;
    use perception::geometry::Point2;

    #[test]
    fn decodes_as_real_bytes_and_is_reproducible() {
        let mut a = Lds01Sim::new(World::random_room(3), Lds01SimConfig::default(), 11);
        let mut b = Lds01Sim::new(World::random_room(3), Lds01SimConfig::default(), 11);
        let (mut x, mut y) = (Vec::new(), Vec::new());
        a.emit_revolutions(5, &mut x);
        b.emit_revolutions(5, &mut y);
        assert_eq!(x, y);
        assert_eq!(x.len(), 5 * 2520);

        let mut stream = Lds01Stream::new(Lds01Config::default());
        let mut revs = Vec::new();
        stream.feed(&x, None, |r| {
            revs.push((r.is_complete(), r.valid_count(), r.rpm))
        });
        assert_eq!(revs.len(), 5);
        for (complete, valid, rpm) in revs {
            assert!(complete);
            assert!(valid > 150, "only {valid} valid readings");
            assert!((285.0..315.0).contains(&rpm));
        }
        assert_eq!(stream.faults().bytes_skipped, 0);
    }

    #[test]
    fn still_robot_sees_what_the_world_says() {
        let world = World::random_room(5);
        let cfg = ScenarioConfig {
            robot: RobotConfig {
                motion: Motion::Still,
                slip_sigma: 0.0,
            },
            lidar: Lds01SimConfig::no_dropouts(),
            ..ScenarioConfig::default()
        };
        let scenario = Scenario::in_world(world.clone(), 1, &cfg);
        let pose = scenario.robot.pose;
        let mut sim = Lds01Sim::from_scenario(scenario);
        let mut bytes = Vec::new();
        sim.emit_revolutions(1, &mut bytes);
        let lidar = pose.compose(&LIDAR_MOUNT);
        let mut stream = Lds01Stream::new(Lds01Config::default());
        let mut checked = 0;
        stream.feed(&bytes, None, |rev| {
            for d in (0..360).step_by(15) {
                let angle = lidar.theta + (d as f32).to_radians();
                let truth = world.raycast(Point2::new(lidar.x, lidar.y), angle, 6.0);
                let r = rev.readings[d];
                if let (Some((t, ..)), true) = (truth, r.valid) {
                    assert!((r.range_m - t).abs() < 0.3, "bin {d}: {} vs {t}", r.range_m);
                    checked += 1;
                }
            }
        });
        assert!(checked > 10, "{checked}");
    }
}
