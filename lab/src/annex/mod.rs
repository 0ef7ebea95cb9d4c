//! # The annex: a second scene family, written apart from the simulator
//!
//! Rooms, furniture, a sensor model and a robot that nothing in umbra was trained or tuned
//! on: the figures that say whether the perception works in a room nobody designed for it.
//! It shares with `sim` only what is not a modelling choice: the LiDARs' wire formats (the
//! LDS-01 packet and LDROBOT frame encoders) and ray–shape intersection. Everything else
//! differs on purpose: floor plans and wall thickness ([`plan`]), furniture variants (office
//! chairs on five-star bases, round tables, panel-end desks, pieces against walls and chairs
//! tucked at desks), clutter (shelves, square pillars, walking people), the reading model
//! ([`sensor`]: reflectivity × incidence × range falloff, mixed pixels, spurious returns),
//! the motion and the encoders' errors ([`drive`]), the LiDAR's speed, a 25 Hz odometry
//! without a compass, and pieces that are moved or carried away during a run.
//!
//! **Rule:** nothing may be trained, tuned or thresholded on annex scenes. It is an exam.

pub mod drive;
pub mod furnish;
pub mod plan;
pub mod sensor;

use drivers::lds01::{PACKETS_PER_REV, READINGS_PER_PACKET, READINGS_PER_REV, RawReading, Repr};
use drivers::lidar::LidarModel;
use perception::geometry::{Point2, Pose2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sim::scenario::Frame;

use crate::run_truth::{Door, FrameTruth, Furniture, Move, Person, RunTruth, VISIBLE_RETURNS};
use drive::{Drive, script};
use plan::{Owner, Prim};

/// The LiDAR's place on the robot (TurtleBot3 Burger; umbra's default mount).
const MOUNT: Pose2 = Pose2 {
    x: -0.032,
    y: 0.0,
    theta: 0.0,
};

/// One generated run: what the robot's ports carried and what was true.
#[derive(Debug, Clone)]
pub struct GeneratedRun {
    /// The LiDAR's bytes.
    pub capture: Vec<u8>,
    /// Odometry JSON Lines on the capture's clock.
    pub odom: String,
    /// Which LiDAR (`umbra replay --lidar-model`).
    pub lidar: LidarModel,
    /// The truth.
    pub truth: RunTruth,
}

/// Closest a moved piece's centre is put to where the robot starts, m, here and in the
/// simulator's families: a piece carried on to the robot (a chair 0.14 m from the LiDAR, inside
/// the robot's body, in sim-4242 run 0) is no room anyone makes.
pub const MOVE_ROBOT_CLEAR_M: f32 = 1.0;

/// Generates annex run `seed`: `seconds` long, touring or turning in place, from `lidar`.
pub fn generate(seed: u64, seconds: f64, tour: bool, lidar: LidarModel) -> GeneratedRun {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let plan = plan::generate(&mut rng);
    let start_xy = plan
        .free_point(&mut rng, 0.6)
        .or_else(|| plan.free_point(&mut rng, 0.35))
        .unwrap_or(Point2::new(0.5, 0.5));
    let start = Pose2::new(start_xy.x, start_xy.y, rng.random_range(-3.1..3.1));
    let script = script(&mut rng, &plan, start, seconds, tour);
    let motion = script.name();
    let mut drive = Drive::new(start, script, ChaCha8Rng::seed_from_u64(rng.random()));
    let mut beam_rng = ChaCha8Rng::seed_from_u64(rng.random());
    let to_map = start.inverse();

    // Furniture entries; one piece may be moved or carried away a third of the way in.
    let frames_total = (seconds * 5.0) as usize;
    let mut entries: Vec<(usize, plan::Piece, usize, usize)> = plan
        .pieces
        .iter()
        .enumerate()
        .map(|(i, p)| (i, p.clone(), 0, usize::MAX))
        .collect();
    let mut moved = None;
    let movable: Vec<usize> = (0..plan.pieces.len())
        .filter(|&i| plan.pieces[i].class != perception::class::ObjectClass::Desk)
        .collect();
    if !movable.is_empty() && rng.random_bool(0.5) {
        let i = movable[rng.random_range(0..movable.len())];
        let f_move = frames_total / 3;
        entries[i].3 = f_move;
        if rng.random_bool(0.6) {
            let mut others = plan.clone();
            others.pieces.remove(i);
            if let Some(q) = (0..20)
                .filter_map(|_| others.free_point(&mut rng, 0.7))
                .find(|q| q.distance(start_xy) >= MOVE_ROBOT_CLEAR_M)
            {
                let old = &plan.pieces[i];
                let c = old.centre();
                let shift = |p: Point2| Point2::new(p.x - c.x + q.x, p.y - c.y + q.y);
                let mut new = old.clone();
                new.footprint.iter_mut().for_each(|p| *p = shift(*p));
                for s in &mut new.shapes {
                    *s = match *s {
                        sim::world::Shape::Segment { a, b } => sim::world::Shape::Segment {
                            a: shift(a),
                            b: shift(b),
                        },
                        sim::world::Shape::Circle { c, r } => {
                            sim::world::Shape::Circle { c: shift(c), r }
                        }
                    };
                }
                new.against_wall = false;
                new.what = format!(
                    "{} (moved here)",
                    old.what.split(" against").next().unwrap_or("")
                );
                entries.push((i, new, f_move, usize::MAX));
            }
        }
        moved = Some((i, f_move));
    }

    let mut capture = Vec::new();
    let mut odom = String::new();
    let mut returns = vec![0u32; entries.len()];
    let mut visible_from = vec![None; entries.len()];
    let mut door_returns = vec![0u32; plan.doors.len()];
    let mut frames = Vec::with_capacity(frames_total);
    let mut seen_empty = None;
    let rpm_base = rng.random_range(285.0..312.0f32);
    let mut t = 0.0f64;
    let mut next_odom = 0.0f64;
    let mut frame = Frame::default();
    let mut prims: Vec<Prim> = Vec::new();
    for f in 0..frames_total {
        let rpm = rpm_base + rng.random_range(-2.0..2.0f32);
        let dt = 60.0 / f64::from(rpm) / READINGS_PER_REV as f64;
        prims.clear();
        prims.extend_from_slice(&plan.fixed);
        for (e, (_, piece, from, to)) in entries.iter().enumerate() {
            if (*from..*to).contains(&f) {
                prims.extend(piece.shapes.iter().map(|&shape| Prim {
                    shape,
                    owner: Owner::Piece(e),
                    refl: piece.refl,
                }));
            }
        }
        let n_fixed = prims.len();
        frame.seq = f as u32;
        frame.rpm = rpm;
        frame.t_start_s = t;
        let mut through_old = 0;
        let mut mid_people: Vec<Person> = plan
            .walkers
            .iter()
            .enumerate()
            .map(|(id, w)| Person {
                id,
                at: to_map.transform(w.at((t + 180.0 * dt) as f32).0),
                returns: 0,
            })
            .collect();
        let mut robot_at_first_ray = None;
        for i in 0..READINGS_PER_REV {
            let ti = t + i as f64 * dt;
            drive.advance_to(ti);
            robot_at_first_ray.get_or_insert(drive.pose);
            while next_odom <= ti {
                let (l, r) = drive.ticks();
                odom.push_str(&format!(
                    "{{\"t\":{:.6},\"left_ticks\":{l},\"right_ticks\":{r}}}\n",
                    next_odom
                ));
                next_odom += 0.04;
            }
            prims.truncate(n_fixed);
            for (k, w) in plan.walkers.iter().enumerate() {
                for c in w.at(ti as f32).1 {
                    prims.push(Prim {
                        shape: sim::world::Shape::Circle { c, r: w.leg_r },
                        owner: Owner::Person(k),
                        refl: 0.5,
                    });
                }
            }
            let lidar = drive.pose.compose(&MOUNT);
            let o = Point2::new(lidar.x, lidar.y);
            let d = READINGS_PER_REV - 1 - i;
            let b = sensor::beam(
                &mut beam_rng,
                &prims,
                o,
                lidar.theta + (d as f32).to_radians(),
            );
            if b.clean {
                match b.hit {
                    Some((Owner::Piece(e), _)) => {
                        returns[e] += 1;
                        if returns[e] == VISIBLE_RETURNS {
                            visible_from[e] = Some(f);
                        }
                    }
                    Some((Owner::Jamb(k), _)) => door_returns[k] += 1,
                    Some((Owner::Person(k), _)) => mid_people[k].returns += 1,
                    _ => {}
                }
                if let (Some((piece, f_move)), None) = (moved, seen_empty)
                    && f >= f_move
                {
                    let a = lidar.theta + (d as f32).to_radians();
                    let q = Point2::new(o.x + b.range_m * a.cos(), o.y + b.range_m * a.sin());
                    if sensor::passes_through(&plan.pieces[piece].footprint, o, q) {
                        through_old += 1;
                    }
                }
            }
            frame.readings[d].raw = RawReading {
                intensity: b.intensity,
                range_mm: (b.range_m * 1000.0).round().clamp(0.0, 65_535.0) as u16,
                reserved: 0,
            };
        }
        if through_old >= 5 {
            seen_empty = Some(f);
        }
        for k in 0..PACKETS_PER_REV {
            frame.packets[k] = Repr {
                index: k as u8,
                speed_raw: (rpm * 10.0).round() as u16,
                readings: core::array::from_fn(|j| {
                    frame.readings[READINGS_PER_REV - 1 - (READINGS_PER_PACKET * k + j)].raw
                }),
            };
        }
        match lidar {
            LidarModel::Lds01 => frame.emit(&mut capture),
            m => sim::wire::emit_ldrobot(m, &frame, &mut capture),
        }
        frames.push(FrameTruth {
            t,
            people: mid_people,
            robot: robot_at_first_ray.map(|p| to_map.compose(&p)),
        });
        t += dt * READINGS_PER_REV as f64;
    }
    let wall_near = |p: &plan::Piece| p.against_wall;
    let truth = RunTruth {
        name: format!(
            "annex {seed}: {} {:.0}×{:.0} m room, {}, {} piece(s), {} door(s), {} walker(s), {}",
            plan.kind,
            plan.floor
                .iter()
                .map(|(a, b)| b.x.max(a.x))
                .fold(0.0, f32::max),
            plan.floor
                .iter()
                .map(|(a, b)| b.y.max(a.y))
                .fold(0.0, f32::max),
            motion,
            plan.pieces.len(),
            plan.doors.len(),
            plan.walkers.len(),
            lidar.cli_name()
        ),
        furniture: entries
            .iter()
            .enumerate()
            .map(|(e, (piece, p, from, to))| Furniture {
                piece: *piece,
                class: p.class,
                footprint: p.footprint.iter().map(|&q| to_map.transform(q)).collect(),
                from_frame: *from,
                to_frame: *to,
                visible_from: visible_from[e],
                returns: returns[e],
                what: p.what.clone(),
                against_wall: wall_near(p),
            })
            .collect(),
        doors: plan
            .doors
            .iter()
            .zip(&door_returns)
            .map(|(d, &r)| Door {
                centre: to_map.transform(d.centre),
                width: d.width,
                returns: r,
            })
            .collect(),
        clutter: plan
            .clutter
            .iter()
            .map(|(c, w)| (to_map.transform(*c), w.clone()))
            .collect(),
        frames,
        moves: moved
            .map(|(piece, frame)| Move {
                before: piece,
                frame,
                seen_empty,
            })
            .into_iter()
            .collect(),
        walls: plan
            .fixed
            .iter()
            .filter_map(|p| match (p.owner, p.shape) {
                (
                    Owner::Wall | Owner::Jamb(_) | Owner::Leaf,
                    sim::world::Shape::Segment { a, b },
                ) => Some((to_map.transform(a), to_map.transform(b))),
                _ => None,
            })
            .collect(),
    };
    GeneratedRun {
        capture,
        odom,
        lidar,
        truth,
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use drivers::lds01::{Lds01Config, Lds01Stream};
    use drivers::lidar::RevolutionStream as _;

    #[test]
    fn same_seed_same_run_and_the_driver_reads_every_revolution() {
        let a = generate(7, 4.0, true, LidarModel::Lds01);
        let b = generate(7, 4.0, true, LidarModel::Lds01);
        assert_eq!(a.capture, b.capture);
        assert_eq!(a.odom, b.odom);
        assert_eq!(a.truth, b.truth);
        assert_eq!(a.capture.len(), 20 * 2520);
        let mut stream = Lds01Stream::new(Lds01Config::default());
        let mut revs = 0;
        stream.feed(&a.capture, None, |r| {
            assert!(r.is_complete());
            revs += 1;
        });
        assert_eq!(revs, 20);
        let f = stream.faults();
        assert_eq!(
            (f.bytes_skipped, f.bad_checksum, f.missing_packets),
            (0, 0, 0)
        );
        // 25 Hz ticks over 4 s.
        assert!(
            (99..=102).contains(&a.odom.lines().count()),
            "{}",
            a.odom.lines().count()
        );
    }

    #[test]
    fn runs_hold_furniture_doors_and_walls_and_seeds_differ() {
        let runs: Vec<_> = (0..6u64)
            .map(|s| generate(100 + s, 2.0, s % 2 == 1, LidarModel::Lds01))
            .collect();
        for r in &runs {
            assert!(!r.truth.furniture.is_empty(), "{}", r.truth.name);
            assert!(!r.truth.doors.is_empty(), "{}", r.truth.name);
            assert!(r.truth.walls.len() >= 8, "{}", r.truth.name);
            assert_eq!(r.truth.frames.len(), 10);
        }
        assert_ne!(runs[0].capture, runs[2].capture);
    }
}
