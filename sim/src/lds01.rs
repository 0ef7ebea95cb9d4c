//! The simulated LDS-01: it spins at ~300 rpm with jitter, takes each reading at its own
//! instant from the robot's pose at that instant (so motion skews the scan as on the real part),
//! and emits the exact 42-byte packets with their checksum.
//!
//! Angles follow the real part: raw reading `i` is taken at `(359 − i)°` counter-clockwise
//! from the LiDAR's forward axis (see `drivers::lds01::revolution`). The LiDAR sits at the
//! TurtleBot3 Burger mount, x = −0.032 m from the robot centre.

use drivers::lds01::{PACKET_LEN, PACKETS_PER_REV, READINGS_PER_PACKET, RawReading, Repr};
use perception::geometry::{Point2, Pose2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::world::World;

/// LiDAR mount relative to the robot centre (TurtleBot3 Burger).
pub const LIDAR_MOUNT: Pose2 = Pose2 {
    x: -0.032,
    y: 0.0,
    theta: 0.0,
};

/// Simulated LiDAR and motion settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Lds01SimConfig {
    /// Mean motor speed, rpm.
    pub rpm: f32,
    /// Standard deviation of the per-revolution speed, rpm.
    pub rpm_jitter: f32,
    /// Probability that a reading inside the spec range returns nothing.
    pub dropout: f64,
    /// Spec range limit, metres; beyond it returns become rare.
    pub spec_max_m: f32,
    /// Probability of a return between the spec limit and [`Lds01SimConfig::far_max_m`].
    pub far_return: f64,
    /// No returns at all beyond this, metres.
    pub far_max_m: f32,
    /// Amplitude of the oscillating rotation in place, radians (0 = robot still).
    pub oscillation_rad: f32,
    /// Period of the oscillation, seconds.
    pub oscillation_period_s: f32,
}

impl Default for Lds01SimConfig {
    fn default() -> Self {
        Lds01SimConfig {
            rpm: 300.0,
            rpm_jitter: 3.0,
            dropout: 0.08,
            spec_max_m: 3.5,
            far_return: 0.3,
            far_max_m: 4.2,
            oscillation_rad: 0.6,
            oscillation_period_s: 8.0,
        }
    }
}

/// A robot in a world with an LDS-01 on top.
#[derive(Debug, Clone)]
pub struct Lds01Sim {
    world: World,
    cfg: Lds01SimConfig,
    rng: ChaCha8Rng,
    /// Sensor time of the next packet slot's start, seconds.
    t: f64,
    next_index: u8,
    rev_rpm: f32,
}

impl Lds01Sim {
    /// A simulated robot at the world's start spot; `seed` drives all noise.
    pub fn new(world: World, cfg: Lds01SimConfig, seed: u64) -> Self {
        let mut sim = Lds01Sim {
            world,
            rev_rpm: cfg.rpm,
            cfg,
            rng: ChaCha8Rng::seed_from_u64(seed),
            t: 0.0,
            next_index: 0,
        };
        sim.rev_rpm = sim.draw_rpm();
        sim
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Sensor time of the next packet slot, seconds.
    pub fn time_s(&self) -> f64 {
        self.t
    }

    /// Duration of one packet slot at the current speed, seconds (`1/rpm`).
    pub fn slot_s(&self) -> f64 {
        1.0 / f64::from(self.rev_rpm)
    }

    /// The robot's pose at sensor time `t`.
    pub fn robot_pose(&self, t: f64) -> Pose2 {
        let w = self.world.robot_start;
        let phase = 2.0 * std::f64::consts::PI * t / f64::from(self.cfg.oscillation_period_s);
        Pose2::new(w.x, w.y, self.cfg.oscillation_rad * phase.sin() as f32)
    }

    fn draw_rpm(&mut self) -> f32 {
        // Sum of uniforms: a cheap, bounded, roughly normal jitter.
        let u: f32 = (0..4).map(|_| self.rng.random_range(-1.0..1.0f32)).sum();
        (self.cfg.rpm + u * self.cfg.rpm_jitter * 0.866).clamp(60.0, 600.0)
    }

    /// The next packet (plain form), advancing the sensor clock by one slot.
    pub fn next_packet(&mut self) -> Repr {
        let k = self.next_index;
        let slot = self.slot_s();
        let mut readings = [RawReading::default(); READINGS_PER_PACKET];
        for (j, r) in readings.iter_mut().enumerate() {
            let i = READINGS_PER_PACKET * usize::from(k) + j;
            let t = self.t + slot * j as f64 / READINGS_PER_PACKET as f64;
            *r = self.reading(i, t);
        }
        let repr = Repr {
            index: k,
            speed_raw: (self.rev_rpm * 10.0).round() as u16,
            readings,
        };
        self.t += slot;
        self.next_index += 1;
        if usize::from(self.next_index) == PACKETS_PER_REV {
            self.next_index = 0;
            self.rev_rpm = self.draw_rpm();
        }
        repr
    }

    /// Emits the next packet's 42 bytes into `out`.
    pub fn emit_packet(&mut self, out: &mut [u8; PACKET_LEN]) {
        let repr = self.next_packet();
        // A 42-byte array always fits: emit_into cannot fail here.
        let _ = repr.emit_into(out);
    }

    /// Appends `n` revolutions of bytes to `out`.
    pub fn emit_revolutions(&mut self, n: usize, out: &mut Vec<u8>) {
        let mut buf = [0u8; PACKET_LEN];
        for _ in 0..n * PACKETS_PER_REV {
            self.emit_packet(&mut buf);
            out.extend_from_slice(&buf);
        }
    }

    fn reading(&mut self, i: usize, t: f64) -> RawReading {
        let lidar = self.robot_pose(t).compose(&LIDAR_MOUNT);
        let angle = lidar.theta + ((359 - i) as f32).to_radians();
        let truth = self.world.raycast(Point2::new(lidar.x, lidar.y), angle);
        let noise_floor: u16 = self.rng.random_range(0..200);
        let miss = RawReading {
            intensity: noise_floor,
            range_mm: 0,
            reserved: 0,
        };
        let Some(r) = truth else { return miss };
        let returns = if r <= self.cfg.spec_max_m {
            !self.rng.random_bool(self.cfg.dropout)
        } else {
            r <= self.cfg.far_max_m && self.rng.random_bool(self.cfg.far_return)
        };
        if !returns {
            return miss;
        }
        // Spec accuracy: ±15 mm under 0.5 m, ±5 % above; used as ~2σ.
        let sigma = if r < 0.5 { 0.0075 } else { 0.025 * r };
        let g: f32 = (0..4)
            .map(|_| self.rng.random_range(-1.0..1.0f32))
            .sum::<f32>()
            * 0.866;
        let measured = (r + g * sigma).max(0.001);
        RawReading {
            intensity: (12_000.0 / (1.0 + measured * measured)) as u16 + noise_floor,
            range_mm: (measured * 1000.0).round().min(f32::from(u16::MAX)) as u16,
            reserved: 0,
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use drivers::lds01::{Lds01Config, Lds01Stream};

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
            assert!(valid > 200, "only {valid} valid readings");
            assert!((280.0..320.0).contains(&rpm));
        }
        assert_eq!(stream.faults().bytes_skipped, 0);
    }

    #[test]
    fn still_robot_sees_walls_where_they_are() {
        let cfg = Lds01SimConfig {
            oscillation_rad: 0.0,
            dropout: 0.0,
            rpm_jitter: 0.0,
            ..Lds01SimConfig::default()
        };
        let world = World::random_room(5);
        let start = world.robot_start;
        let mut sim = Lds01Sim::new(world.clone(), cfg, 1);
        let mut bytes = Vec::new();
        sim.emit_revolutions(1, &mut bytes);
        let mut stream = Lds01Stream::new(Lds01Config::default());
        let mut checked = 0;
        stream.feed(&bytes, None, |rev| {
            // Bin 0 looks along +x from the LiDAR (mount −0.032 m, robot unrotated).
            let truth = world
                .raycast(Point2::new(start.x - 0.032, start.y), 0.0)
                .unwrap();
            let r = rev.readings[0];
            if r.valid {
                assert!((r.range_m - truth).abs() < 0.2, "{} vs {truth}", r.range_m);
                checked += 1;
            }
            let truth = world
                .raycast(
                    Point2::new(start.x - 0.032, start.y),
                    core::f32::consts::FRAC_PI_2,
                )
                .unwrap();
            let r = rev.readings[90];
            if r.valid {
                assert!((r.range_m - truth).abs() < 0.2, "{} vs {truth}", r.range_m);
                checked += 1;
            }
        });
        assert!(checked > 0);
    }
}
