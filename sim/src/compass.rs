//! The compass: an LSM303AGR-like magnetometer on the robot, in microtesla, robot frame
//! (x forward, y left, z up). It sees the earth's field turned by the robot's heading, plus a
//! hard-iron offset (fixed in the robot frame: the motors and battery), noise, and local
//! disturbances near steel (pillars, desk frames) that fall off with the cube of distance.

use perception::geometry::{Point2, Pose2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::world::World;

/// Compass settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompassConfig {
    /// Horizontal earth field, µT.
    pub horizontal_ut: f32,
    /// Vertical earth field (down negative), µT.
    pub vertical_ut: f32,
    /// Largest hard-iron offset per axis, µT.
    pub hard_iron_max_ut: f32,
    /// Noise per axis (roughly σ), µT.
    pub noise_ut: f32,
    /// Disturbance strength at 0.3 m from a source, µT.
    pub disturbance_ut: f32,
}

impl Default for CompassConfig {
    fn default() -> Self {
        CompassConfig {
            horizontal_ut: 20.0,
            vertical_ut: -44.0,
            hard_iron_max_ut: 15.0,
            noise_ut: 0.4,
            disturbance_ut: 25.0,
        }
    }
}

/// The simulated magnetometer.
#[derive(Debug, Clone)]
pub struct Compass {
    cfg: CompassConfig,
    /// World angle of magnetic north, rad.
    pub north_rad: f32,
    /// Hard-iron offset, robot frame, µT.
    pub hard_iron_ut: [f32; 3],
    /// Disturbance sources: position and field direction (unit 3-D vector, world frame: steel
    /// near the floor bends the field in every direction, the vertical included).
    sources: Vec<(Point2, [f32; 3])>,
    rng: ChaCha8Rng,
}

impl Compass {
    /// A compass for `world`; steel sources are the pillars and desks.
    pub fn new(world: &World, cfg: CompassConfig, seed: u64) -> Compass {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let north_rad = rng.random_range(-core::f32::consts::PI..core::f32::consts::PI);
        let hi = cfg.hard_iron_max_ut;
        let hard_iron_ut = [
            rng.random_range(-hi..=hi),
            rng.random_range(-hi..=hi),
            rng.random_range(-hi..=hi),
        ];
        let mut sources = Vec::new();
        let mut add = |p: Point2, rng: &mut ChaCha8Rng| {
            // Uniform on the sphere.
            let a: f32 = rng.random_range(-core::f32::consts::PI..core::f32::consts::PI);
            let z: f32 = rng.random_range(-1.0..1.0);
            let r = (1.0 - z * z).sqrt();
            sources.push((p, [r * a.cos(), r * a.sin(), z]));
        };
        for c in world.clutter.iter().filter(|c| c.kind == "pillar") {
            add(c.centre, &mut rng);
        }
        for o in world
            .objects
            .iter()
            .filter(|o| o.class == perception::class::ObjectClass::Desk)
        {
            add(o.centre, &mut rng);
        }
        Compass {
            cfg,
            north_rad,
            hard_iron_ut,
            sources,
            rng,
        }
    }

    /// The field at `at` without noise, world frame (µT): the earth's plus the disturbances.
    pub fn field_world(&self, at: Point2) -> [f32; 3] {
        let mut f = [
            self.cfg.horizontal_ut * self.north_rad.cos(),
            self.cfg.horizontal_ut * self.north_rad.sin(),
            self.cfg.vertical_ut,
        ];
        for (p, dir) in &self.sources {
            let d = at.distance(*p).max(0.1);
            let s = self.cfg.disturbance_ut * (0.3 / d).powi(3);
            for (fi, di) in f.iter_mut().zip(dir) {
                *fi += di * s;
            }
        }
        f
    }

    /// How much the disturbances add to the field at `at`, µT.
    pub fn disturbance_ut(&self, at: Point2) -> f32 {
        self.sources
            .iter()
            .map(|(p, _)| self.cfg.disturbance_ut * (0.3 / at.distance(*p).max(0.1)).powi(3))
            .sum()
    }

    /// One reading at `pose`, robot frame, µT.
    pub fn read(&mut self, pose: &Pose2) -> [f32; 3] {
        let h = self.field_world(Point2::new(pose.x, pose.y));
        let (s, c) = pose.theta.sin_cos();
        let body = [c * h[0] + s * h[1], -s * h[0] + c * h[1], h[2]];
        let mut out = [0.0; 3];
        for (i, o) in out.iter_mut().enumerate() {
            let n = crate::noise::unit(&mut self.rng) * self.cfg.noise_ut;
            *o = body[i] + self.hard_iron_ut[i] + n;
        }
        out
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn heading_from_calibrated_field() {
        let w = World::random_room(1);
        let mut c = Compass::new(
            &w,
            CompassConfig {
                noise_ut: 0.0,
                disturbance_ut: 0.0,
                ..Default::default()
            },
            3,
        );
        for th in [-2.0f32, -0.5, 0.0, 1.0, 3.0] {
            let m = c.read(&Pose2::new(1.0, 1.0, th));
            let (x, y) = (m[0] - c.hard_iron_ut[0], m[1] - c.hard_iron_ut[1]);
            // North in the robot frame is at angle atan2(y, x) = north − θ.
            let est = perception::geometry::wrap_angle(c.north_rad - y.atan2(x));
            assert!((perception::geometry::wrap_angle(est - th)).abs() < 1e-4);
        }
    }
}
