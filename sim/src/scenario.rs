//! A scenario: one world, one robot on a script, its LDS-01, encoders and compass, stepped one
//! LiDAR revolution (a frame) at a time, with the ground truth of every reading.
//!
//! Each reading is taken at its own instant: the robot is integrated over the six reading
//! instants of every packet slot, and the ray leaves from the LiDAR's pose at that instant, so
//! a turning robot's scan is skewed exactly as a real one. Encoder and compass samples come at
//! [`ScenarioConfig::odom_hz`] on the same clock as the LiDAR (the sensor clock of
//! `docs/interfaces.md` §2: t = 0 at the start of the first packet).

use drivers::lds01::{PACKETS_PER_REV, READINGS_PER_PACKET, READINGS_PER_REV, RawReading, Repr};
use perception::geometry::{Point2, Pose2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::compass::{Compass, CompassConfig};
use crate::lds01::{LIDAR_MOUNT, Lds01SimConfig, LidarModel};
use crate::people::{ROBOT_RADIUS_M, Walker};
use crate::power::ReceivedPower;
use crate::robot::{Robot, RobotConfig};
use crate::wear::Wear;
use crate::world::{Shape, Surface, World, WorldConfig};

/// Everything a scenario needs besides its seed.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ScenarioConfig {
    /// The world.
    pub world: WorldConfig,
    /// The robot and its motion.
    pub robot: RobotConfig,
    /// The LiDAR.
    pub lidar: Lds01SimConfig,
    /// The compass.
    pub compass: CompassConfig,
    /// Encoder/compass samples per second (0 = none; default 20, the vendor node's 50 ms).
    pub odom_hz: f32,
    /// Share of scenarios whose LiDAR is a worn unit ([`Wear::draw`]), decided from the
    /// scenario's seed on a salted stream of its own; 0 (the default) leaves every scenario as
    /// it was.
    pub worn: f64,
    /// Share of scenarios whose LiDAR returns by the light it receives
    /// ([`crate::power::ReceivedPower::draw`]), decided from the scenario's seed on a salted
    /// stream of its own; 0 (the default) leaves every scenario as it was.
    pub power: f64,
}

impl ScenarioConfig {
    /// Defaults with 20 Hz odometry.
    pub fn standard() -> Self {
        ScenarioConfig {
            odom_hz: 20.0,
            ..ScenarioConfig::default()
        }
    }
}

/// One reading with its truth.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SimReading {
    /// What the sensor sent.
    pub raw: RawReading,
    /// The surface the ray hit (whether or not it returned), if any within 6 m.
    pub hit: Option<Surface>,
    /// True distance to that surface, metres (0 if none).
    pub true_range_m: f32,
}

/// One revolution with its truth.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Revolution number.
    pub seq: u32,
    /// Sensor time of the start of packet slot 0, s.
    pub t_start_s: f64,
    /// Motor speed of this revolution, rpm.
    pub rpm: f32,
    /// Robot pose (world frame) at the first reading, at the middle and at the end.
    pub pose_start: Pose2,
    /// See `pose_start`.
    pub pose_mid: Pose2,
    /// See `pose_start`.
    pub pose_end: Pose2,
    /// Readings by bin `d` (degrees counter-clockwise), as the driver will store them.
    pub readings: [SimReading; READINGS_PER_REV],
    /// The 60 packets as sent.
    pub packets: [Repr; PACKETS_PER_REV],
    /// Where each walking person (midpoint of the legs, world frame) was at the middle reading.
    pub people_mid: Vec<Point2>,
}

impl Default for Frame {
    fn default() -> Self {
        Frame {
            seq: 0,
            t_start_s: 0.0,
            rpm: 0.0,
            pose_start: Pose2::IDENTITY,
            pose_mid: Pose2::IDENTITY,
            pose_end: Pose2::IDENTITY,
            readings: [SimReading::default(); READINGS_PER_REV],
            packets: [Repr::default(); PACKETS_PER_REV],
            people_mid: Vec::new(),
        }
    }
}

impl Frame {
    /// Ranges by bin in metres, 0 where nothing returned (the raster's input).
    pub fn ranges_m(&self) -> [f32; READINGS_PER_REV] {
        let mut r = [0.0; READINGS_PER_REV];
        for (o, s) in r.iter_mut().zip(&self.readings) {
            *o = f32::from(s.raw.range_mm) / 1000.0;
        }
        r
    }

    /// Bytes of this revolution on the wire (60 × 42).
    pub fn emit(&self, out: &mut Vec<u8>) {
        let mut buf = [0u8; drivers::lds01::PACKET_LEN];
        for p in &self.packets {
            // A 42-byte buffer always fits.
            let _ = p.emit_into(&mut buf);
            out.extend_from_slice(&buf);
        }
    }
}

/// An encoder + compass sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdomSample {
    /// Sensor-clock time, s.
    pub t: f64,
    /// Left wheel ticks (cumulative).
    pub left_ticks: i32,
    /// Right wheel ticks (cumulative).
    pub right_ticks: i32,
    /// Magnetometer, robot frame, µT.
    pub mag_ut: [f32; 3],
    /// True pose (not sent by any sensor; for evaluation).
    pub truth: Pose2,
}

/// A running scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The world.
    pub world: World,
    /// The robot.
    pub robot: Robot,
    /// The compass.
    pub compass: Compass,
    /// People walking through the world (none unless added; [`Surface::Person`] is an index
    /// into this).
    pub people: Vec<Walker>,
    lidar: LidarModel,
    start_pose: Pose2,
    odom_period: f64,
    next_odom: f64,
    seq: u32,
}

impl Scenario {
    /// Builds scenario `seed`: world, robot, sensors all seeded from it.
    pub fn new(seed: u64, cfg: &ScenarioConfig) -> Scenario {
        let mut seeds = ChaCha8Rng::seed_from_u64(seed);
        let world = World::generate(seeds.random(), &cfg.world);
        Scenario::in_world(world, seeds.random(), cfg)
    }

    /// A scenario in a given world.
    pub fn in_world(world: World, seed: u64, cfg: &ScenarioConfig) -> Scenario {
        let mut seeds = ChaCha8Rng::seed_from_u64(seed);
        let robot = Robot::new(&world, cfg.robot, seeds.random());
        let compass = Compass::new(&world, cfg.compass, seeds.random());
        let lidar_seed = seeds.random();
        let mut lidar_cfg = if world.varied {
            cfg.lidar.varied(seeds.random())
        } else {
            cfg.lidar.clone()
        };
        if cfg.worn > 0.0 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ WEAR_SALT);
            if rng.random_bool(cfg.worn.min(1.0)) {
                lidar_cfg.wear = Wear::draw(rng.random());
            }
        }
        if cfg.power > 0.0 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ POWER_SALT);
            if rng.random_bool(cfg.power.min(1.0)) {
                lidar_cfg.power = Some(ReceivedPower::draw(rng.random()));
            }
        }
        let lidar = LidarModel::new(lidar_cfg, lidar_seed);
        Scenario {
            start_pose: robot.pose,
            world,
            robot,
            compass,
            people: Vec::new(),
            lidar,
            odom_period: if cfg.odom_hz > 0.0 {
                1.0 / f64::from(cfg.odom_hz)
            } else {
                f64::INFINITY
            },
            next_odom: 0.0,
            seq: 0,
        }
    }

    /// Walks 0 to `max` people (uniformly) through the scenario, drawn from `seed`'s own
    /// salted stream and kept clear of the robot's start ([`Walker::draw`]), so the world,
    /// robot and LiDAR are the same with or without them. Returns how many walk.
    pub fn add_people(&mut self, seed: u64, max: usize) -> usize {
        let clear = Point2::new(self.start_pose.x, self.start_pose.y);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ PEOPLE_SALT);
        for _ in 0..rng.random_range(0..=max) {
            if let Some(w) = Walker::draw(&self.world, &mut rng, clear) {
                self.people.push(w);
            }
        }
        self.people.len()
    }

    /// The robot's pose at the start: the map frame of the output line.
    pub fn robot_start_pose(&self) -> Pose2 {
        self.start_pose
    }

    /// The compass readings (µT, x y z) of what `umbra calibrate-compass` asks of a robot:
    /// two turns in place at the start spot at 0.5 rad/s, readings at 20 Hz. Runs on copies:
    /// the scenario itself does not move.
    pub fn compass_spin_readings(&self) -> Vec<[f32; 3]> {
        let mut compass = self.compass.clone();
        let cfg = RobotConfig {
            motion: crate::robot::Motion::Spin { rate_rad_s: 0.5 },
            slip_sigma: 0.0,
        };
        let mut robot = Robot::new(&self.world, cfg, 0);
        let samples = (2.0 * core::f32::consts::TAU / 0.5 / 0.05) as usize;
        (0..samples)
            .map(|_| {
                for _ in 0..10 {
                    robot.step(0.005);
                }
                compass.read(&robot.pose)
            })
            .collect()
    }

    /// Simulates the next revolution into `frame`, appending the encoder/compass samples that
    /// fall in it to `odom`.
    pub fn next_frame(&mut self, frame: &mut Frame, odom: &mut Vec<OdomSample>) {
        let rpm = self.lidar.draw_rpm();
        let slot = 1.0 / rpm;
        let sub = slot / READINGS_PER_PACKET as f32;
        frame.seq = self.seq;
        frame.rpm = rpm;
        frame.t_start_s = self.robot.time_s();
        self.seq += 1;
        for k in 0..PACKETS_PER_REV {
            let mut readings = [RawReading::default(); READINGS_PER_PACKET];
            for (j, raw) in readings.iter_mut().enumerate() {
                let i = READINGS_PER_PACKET * k + j;
                let d = READINGS_PER_REV - 1 - i;
                let lidar = self.robot.pose.compose(&LIDAR_MOUNT);
                if i == 0 {
                    frame.pose_start = self.robot.pose;
                } else if i == READINGS_PER_REV / 2 {
                    frame.pose_mid = self.robot.pose;
                    frame.people_mid.clear();
                    frame
                        .people_mid
                        .extend(self.people.iter().map(Walker::centre));
                }
                let angle = lidar.theta + (d as f32).to_radians();
                let o = Point2::new(lidar.x, lidar.y);
                let hit = self
                    .world
                    .raycast(o, angle, MAX_RANGE_M)
                    .map(|(t, idx, cos)| {
                        let prim = &self.world.prims[idx];
                        (t, cos, prim.surface, prim.reflectivity)
                    });
                let hit = self.nearer_person(o, angle, hit);
                let (r, surface, reading) = match hit {
                    Some((t, cos, surface, refl)) => {
                        let other = self.spot_side(o, angle);
                        (t, Some(surface), self.lidar.reading(t, cos, refl, other))
                    }
                    None => (0.0, None, self.lidar.miss()),
                };
                *raw = reading;
                frame.readings[d] = SimReading {
                    raw: reading,
                    hit: surface,
                    true_range_m: r,
                };
                self.robot.step(sub);
                for w in &mut self.people {
                    w.step(sub, o);
                }
                while self.robot.time_s() >= self.next_odom {
                    let (l, r) = self.robot.ticks();
                    odom.push(OdomSample {
                        t: self.next_odom,
                        left_ticks: l,
                        right_ticks: r,
                        mag_ut: self.compass.read(&self.robot.pose),
                        truth: self.robot.pose,
                    });
                    self.next_odom += self.odom_period;
                }
            }
            frame.packets[k] = Repr {
                index: k as u8,
                speed_raw: (rpm * 10.0).round() as u16,
                readings,
            };
        }
        frame.pose_end = self.robot.pose;
    }

    /// What the far side of the beam's spot hits, m, for a unit with mixed pixels.
    fn spot_side(&mut self, o: Point2, angle: f32) -> Option<f32> {
        let a = angle + self.lidar.spot_offset()?;
        let hit = self.world.raycast(o, a, MAX_RANGE_M).map(|(t, idx, cos)| {
            let prim = &self.world.prims[idx];
            (t, cos, prim.surface, prim.reflectivity)
        });
        self.nearer_person(o, a, hit).map(|h| h.0)
    }

    /// `hit` (distance, cosine of incidence, surface, reflectivity), or a walking person's leg
    /// if one is nearer along the ray.
    fn nearer_person(
        &self,
        o: Point2,
        angle: f32,
        hit: Option<(f32, f32, Surface, f32)>,
    ) -> Option<(f32, f32, Surface, f32)> {
        let (s, c) = angle.sin_cos();
        let d = Point2::new(c, s);
        let mut best = hit;
        for (k, w) in self.people.iter().enumerate() {
            for leg in w.leg_shapes() {
                let Shape::Circle { c, .. } = leg else {
                    continue;
                };
                if c.distance(o) < ROBOT_RADIUS_M {
                    continue; // stepping round the robot
                }
                if let Some((t, cos)) = leg.intersect(o, d)
                    && t <= MAX_RANGE_M
                    && best.is_none_or(|b| t < b.0)
                {
                    best = Some((t, cos, Surface::Person(k as u16), w.reflectivity));
                }
            }
        }
        best
    }
}

/// Salt of the stream that decides whether a scenario's LiDAR is worn ([`ScenarioConfig::worn`]).
const WEAR_SALT: u64 = 0x3EA2_F00D_71C5_0B9E;

/// Salt of the stream that decides whether a scenario's LiDAR returns by received power
/// ([`ScenarioConfig::power`]).
const POWER_SALT: u64 = 0x51D7_0C3A_E29B_4F61;

/// Salt of the people's own random stream ([`Scenario::add_people`]).
const PEOPLE_SALT: u64 = 0x9E0F_1E5B_2A47_C3D8;

/// Farthest a simulated ray looks, m (beyond every LiDAR model's range).
const MAX_RANGE_M: f32 = 6.0;

#[cfg(test)]
mod test {
    use super::*;
    use drivers::lds01::{Lds01Config, Lds01Stream};
    use drivers::lidar::RevolutionStream as _;
    use rand::SeedableRng;

    #[test]
    fn frames_decode_through_the_real_driver() {
        let mut s = Scenario::new(5, &ScenarioConfig::standard());
        let mut frame = Frame::default();
        let mut odom = Vec::new();
        let mut bytes = Vec::new();
        let mut sent = Vec::new();
        for _ in 0..10 {
            s.next_frame(&mut frame, &mut odom);
            frame.emit(&mut bytes);
            sent.push(frame.ranges_m());
        }
        assert_eq!(bytes.len(), 10 * 2520);
        let mut stream = Lds01Stream::new(Lds01Config::default());
        let mut got = Vec::new();
        stream.feed(&bytes, None, |r| {
            assert!(r.is_complete());
            got.push(r.readings.map(|x| x.range_m));
        });
        assert_eq!(got, sent);
        let f = stream.faults();
        assert_eq!(
            (f.bytes_skipped, f.bad_checksum, f.missing_packets),
            (0, 0, 0)
        );
        // 20 Hz odometry over ~2 s.
        assert!((38..=42).contains(&odom.len()), "{} samples", odom.len());
    }

    #[test]
    fn a_walking_person_is_seen_where_it_walks() {
        let mut s = Scenario::new(9, &ScenarioConfig::standard());
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let start = s.robot.pose;
        let w = (0..20)
            .find_map(|_| Walker::draw(&s.world, &mut rng, Point2::new(start.x, start.y)))
            .expect("a walker fits");
        s.people.push(w);
        let mut f = Frame::default();
        let mut odom = Vec::new();
        let mut seen = Vec::new();
        for _ in 0..25 {
            s.next_frame(&mut f, &mut odom);
            let legs: Vec<Point2> = (0..READINGS_PER_REV)
                .filter(|&d| f.readings[d].hit == Some(Surface::Person(0)))
                .map(|d| {
                    let l = f.pose_mid.compose(&LIDAR_MOUNT);
                    let a = l.theta + (d as f32).to_radians();
                    let r = f.readings[d].true_range_m;
                    Point2::new(l.x + r * a.cos(), l.y + r * a.sin())
                })
                .collect();
            if let (Some(p), [mid]) = (legs.first(), f.people_mid.as_slice()) {
                // Every return on the person lies on its legs: within a stride of its middle.
                assert!(
                    legs.iter().all(|q| q.distance(*mid) < 0.6),
                    "{p:?} vs {mid:?}"
                );
                seen.push(*mid);
            }
        }
        assert!(
            seen.len() >= 5,
            "the person was seen in {} frames",
            seen.len()
        );
        let walked = seen[0].distance(seen[seen.len() - 1]);
        assert!(walked > 0.3, "it moved {walked} m");
    }

    #[test]
    fn a_worn_lidar_reads_between_surfaces_and_loses_far_returns() {
        // (returns, returns off their surface by more than the noise's bound, returns beyond 2 m)
        let tally = |worn: f64| {
            let cfg = ScenarioConfig {
                worn,
                ..ScenarioConfig::standard()
            };
            let (mut off, mut returns, mut far) = (0, 0, 0);
            for seed in 0..4 {
                let mut s = Scenario::new(seed, &cfg);
                assert_eq!(s.lidar.cfg().wear.has_spot(), worn > 0.0);
                let (mut f, mut odom) = (Frame::default(), Vec::new());
                for _ in 0..10 {
                    s.next_frame(&mut f, &mut odom);
                    for r in f.readings.iter().filter(|r| r.raw.range_mm != 0) {
                        let (m, t) = (f32::from(r.raw.range_mm) / 1000.0, r.true_range_m);
                        returns += 1;
                        off += usize::from((m - t).abs() > 0.08 * t + 0.05);
                        far += usize::from(t > 2.0);
                    }
                }
            }
            (returns, off, far)
        };
        let (n0, off0, far0) = tally(0.0);
        let (n1, off1, far1) = tally(1.0);
        assert_eq!(off0, 0, "a fresh unit reads every return on its surface");
        assert!(off1 * 400 > n1, "mixed pixels: {off1} of {n1}");
        assert!(n1 < n0 && far1 < far0, "{n1} < {n0}, {far1} < {far0}");
    }

    #[test]
    fn a_unit_that_returns_by_received_power_thins_with_range() {
        // (returns, returns of surfaces beyond 2.5 m) over the same scenarios.
        let tally = |power: f64| {
            let cfg = ScenarioConfig {
                power,
                ..ScenarioConfig::standard()
            };
            let (mut returns, mut far) = (0usize, 0usize);
            for seed in 0..4 {
                let mut s = Scenario::new(seed, &cfg);
                assert_eq!(s.lidar.cfg().power.is_some(), power > 0.0);
                let (mut f, mut odom) = (Frame::default(), Vec::new());
                for _ in 0..10 {
                    s.next_frame(&mut f, &mut odom);
                    for r in f.readings.iter().filter(|r| r.raw.range_mm != 0) {
                        returns += 1;
                        far += usize::from(r.true_range_m > 2.5);
                    }
                }
            }
            (returns, far)
        };
        let (n0, far0) = tally(0.0);
        let (n1, far1) = tally(1.0);
        // The far share falls: the received power goes with 1 / range².
        assert!(
            far1 * n0 < far0 * n1 && far1 < far0,
            "{far1} of {n1} against {far0} of {n0}"
        );
    }

    #[test]
    fn same_seed_same_frames() {
        let run = || {
            let mut s = Scenario::new(9, &ScenarioConfig::standard());
            let mut f = Frame::default();
            let mut odom = Vec::new();
            let mut bytes = Vec::new();
            for _ in 0..5 {
                s.next_frame(&mut f, &mut odom);
                f.emit(&mut bytes);
            }
            (bytes, odom)
        };
        let (a, oa) = run();
        let (b, ob) = run();
        assert_eq!(a, b);
        assert_eq!(oa, ob);
    }
}
