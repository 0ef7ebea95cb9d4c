//! Method A on simulated scenes, with the ground truth to label and score it.
//!
//! A scene is scenario `i` of a seed (the dataset's scenarios: even indices oscillate in place
//! as in the study, odd ones tour the room). Each revolution goes through the real pipeline
//! ([`perception::method_a::MethodA`]) in the map frame (the robot's start pose), with the
//! pose from wheel odometry (slip included) or, for reference, the true pose. At chosen frames
//! a [`SceneView`] hands the pipeline's state and the truth to the caller: the forest's
//! training-data command labels candidates with [`label_points`]; the evaluator scores.

use perception::class::ObjectClass;
use perception::cloud::Scan;
use perception::geometry::{Point2, Pose2};
use perception::method_a::{Classifier, MethodA, MethodAConfig};
use perception::pose::{OdometryConfig, TickCounter, integrate};

use sim::dataset::{scenario_config, scenario_seed};
use sim::lds01::LIDAR_MOUNT;
use sim::scenario::{Frame, OdomSample, Scenario, ScenarioConfig};
use sim::world::{Surface, World, WorldConfig};

/// Where the pipeline's pose comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PoseSource {
    /// The simulator's true pose (no drift): isolates Method A.
    Truth,
    /// Wheel odometry with the simulated slip, as a robot without a compass has it.
    Odometry,
}

/// Scene settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneConfig {
    /// Master seed; scene `i` is the dataset's scenario `i`.
    pub seed: u64,
    /// World generation.
    pub world: WorldConfig,
    /// Revolutions simulated.
    pub frames: usize,
    /// The views: every `every`-th frame from `first` on.
    pub first: usize,
    /// See `first`.
    pub every: usize,
    /// Pose source.
    pub pose: PoseSource,
    /// Share of scenes seen by a worn LiDAR (`ScenarioConfig::worn`; 0: none).
    pub worn: f64,
    /// Share of scenes seen by a LiDAR that returns by received power
    /// (`ScenarioConfig::power`; 0: none).
    pub power: f64,
}

impl Default for SceneConfig {
    fn default() -> Self {
        SceneConfig {
            seed: 0,
            world: WorldConfig::default(),
            frames: 60,
            first: 25,
            every: 15,
            pose: PoseSource::Odometry,
            worn: 0.0,
            power: 0.0,
        }
    }
}

/// The pipeline after one revolution, with the truth.
pub struct SceneView<'a> {
    /// Scene index.
    pub scene: usize,
    /// Frame index.
    pub frame: usize,
    /// The world.
    pub world: &'a World,
    /// Map frame → world frame.
    pub map_to_world: Pose2,
    /// The pipeline.
    pub method: &'a MethodA,
    /// The sensor's position (map frame) that the pipeline used.
    pub sensor: Point2,
}

/// What a set of points belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TruthLabel {
    /// Furniture `n` of this class.
    Object(ObjectClass, u16),
    /// Clutter item `n`.
    Clutter(u16),
    /// Walls or door jambs.
    Wall,
    /// Nothing within reach (ghost points, smear from pose error).
    Nothing,
}

/// The majority owner of `points` (map frame): each point votes for the surface within
/// `reach` metres nearest to it.
pub fn label_points<'a>(
    world: &World,
    map_to_world: &Pose2,
    points: impl Iterator<Item = &'a Point2>,
    reach: f32,
) -> TruthLabel {
    let mut votes: Vec<(TruthLabel, u32)> = Vec::new();
    for p in points {
        let w = map_to_world.transform(*p);
        let mut best: Option<(f32, Surface)> = None;
        for prim in &world.prims {
            let d = prim.shape.distance(w);
            if d <= reach && best.is_none_or(|b| d < b.0) {
                best = Some((d, prim.surface));
            }
        }
        let l = match best {
            None => TruthLabel::Nothing,
            Some((_, Surface::Object(n))) => TruthLabel::Object(world.objects[n as usize].class, n),
            Some((_, Surface::Clutter(n))) => TruthLabel::Clutter(n),
            // Scenes for Method A's labels have no walking people; one is clutter if it comes.
            Some((_, Surface::Person(n))) => TruthLabel::Clutter(n),
            Some((_, Surface::Wall | Surface::DoorFrame(_))) => TruthLabel::Wall,
        };
        match votes.iter_mut().find(|v| v.0 == l) {
            Some(v) => v.1 += 1,
            None => votes.push((l, 1)),
        }
    }
    votes
        .into_iter()
        .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
        .map_or(TruthLabel::Nothing, |v| v.0)
}

/// Number of `cloud` points (map frame) inside `footprint` (world frame) grown by `grow` metres.
pub fn points_on(
    footprint: &[Point2; 4],
    map_to_world: &Pose2,
    cloud: impl Iterator<Item = Point2>,
    grow: f32,
) -> usize {
    let c = Point2::new(
        footprint.iter().map(|p| p.x).sum::<f32>() / 4.0,
        footprint.iter().map(|p| p.y).sum::<f32>() / 4.0,
    );
    let grown: [Point2; 4] = footprint.map(|p| {
        let d = p - c;
        let l = d.norm().max(1e-6);
        Point2::new(p.x + d.x / l * grow, p.y + d.y / l * grow)
    });
    cloud
        .filter(|p| {
            let w = map_to_world.transform(*p);
            (0..4).all(|i| {
                let (a, b) = (grown[i], grown[(i + 1) % 4]);
                (b.x - a.x) * (w.y - a.y) - (b.y - a.y) * (w.x - a.x) >= 0.0
            })
        })
        .count()
}

struct OdomPose {
    counter: TickCounter,
    pose: Pose2,
    cfg: OdometryConfig,
    samples: Vec<(f64, Pose2)>,
}

impl OdomPose {
    fn feed(&mut self, s: &OdomSample) {
        let step = self.counter.step(s.left_ticks, s.right_ticks, &self.cfg);
        self.pose = integrate(&self.pose, step.distance(), step.dtheta(&self.cfg));
        self.samples.push((s.t, self.pose));
    }

    fn at(&self, t: f64) -> Pose2 {
        let i = self.samples.partition_point(|s| s.0 <= t);
        match (
            i.checked_sub(1).map(|k| self.samples[k]),
            self.samples.get(i),
        ) {
            (Some(a), Some(b)) => {
                let u = ((t - a.0) / (b.0 - a.0)) as f32;
                let dth = perception::geometry::wrap_angle(b.1.theta - a.1.theta);
                Pose2::new(
                    a.1.x + (b.1.x - a.1.x) * u,
                    a.1.y + (b.1.y - a.1.y) * u,
                    a.1.theta + dth * u,
                )
            }
            (Some(a), None) => a.1,
            (None, _) => Pose2::IDENTITY,
        }
    }
}

/// Runs scene `i` through `method` (reset first) and calls `view` at the chosen frames.
pub fn run_scene(
    i: usize,
    cfg: &SceneConfig,
    acfg: &MethodAConfig,
    method: &mut MethodA,
    classifier: &impl Classifier,
    mut view: impl FnMut(&SceneView<'_>),
) {
    let sc = ScenarioConfig {
        power: cfg.power,
        ..scenario_config(i, &cfg.world, cfg.worn)
    };
    let mut scenario = Scenario::new(scenario_seed(cfg.seed, i), &sc);
    let start = scenario.robot_start_pose();
    let world_to_map = start.inverse();
    let mut frame = Box::<Frame>::default();
    let mut odom = Vec::new();
    let mut est = OdomPose {
        counter: TickCounter::default(),
        pose: Pose2::IDENTITY,
        cfg: OdometryConfig::BURGER,
        samples: vec![(0.0, Pose2::IDENTITY)],
    };
    method.reset();
    for n in 0..cfg.frames {
        odom.clear();
        scenario.next_frame(&mut frame, &mut odom);
        for s in &odom {
            est.feed(s);
        }
        let (p0, p1) = match cfg.pose {
            PoseSource::Truth => (
                world_to_map.compose(&frame.pose_start),
                world_to_map.compose(&frame.pose_end),
            ),
            PoseSource::Odometry => {
                let dur = 1.0 / f64::from(frame.rpm / 60.0);
                let t0 = frame.t_start_s;
                (est.at(t0), est.at(t0 + dur * 359.0 / 360.0))
            }
        };
        let ranges = frame.ranges_m();
        method.add_scan(
            &Scan {
                ranges: &ranges,
                start: p0,
                end: p1,
                mount: LIDAR_MOUNT,
            },
            acfg,
        );
        if n >= cfg.first && (n - cfg.first).is_multiple_of(cfg.every.max(1)) {
            let sensor = p1.compose(&LIDAR_MOUNT);
            let sensor = Point2::new(sensor.x, sensor.y);
            method.run(sensor, acfg, classifier);
            view(&SceneView {
                scene: i,
                frame: n,
                world: &scenario.world,
                map_to_world: start,
                method,
                sensor,
            });
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use perception::method_a::Unclassified;

    #[test]
    fn scenes_find_walls_and_label_furniture() {
        let cfg = SceneConfig {
            frames: 30,
            first: 29,
            ..SceneConfig::default()
        };
        let mut m = Box::new(MethodA::new());
        let mut furniture = 0;
        let mut views = 0;
        for i in [0, 2] {
            run_scene(
                i,
                &cfg,
                &MethodAConfig::default(),
                &mut m,
                &Unclassified,
                |v| {
                    views += 1;
                    assert!(!v.method.segments().is_empty());
                    for k in 0..v.method.candidates().len() {
                        let l = label_points(
                            v.world,
                            &v.map_to_world,
                            v.method.candidate_points(k),
                            0.1,
                        );
                        if matches!(l, TruthLabel::Object(..)) {
                            furniture += 1;
                        }
                    }
                },
            );
        }
        assert_eq!(views, 2);
        assert!(furniture >= 2, "{furniture}");
    }
}
