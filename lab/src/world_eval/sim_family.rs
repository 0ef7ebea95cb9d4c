//! Runs from umbra's own simulator (the family that trained and tuned both methods), on
//! held-out seeds, as capture bytes, odometry and truth for the world evaluation.

use drivers::lidar::LidarModel;
use perception::class::ObjectClass;
use perception::geometry::{Point2, Pose2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sim::dataset::{scenario_config, scenario_seed};
use sim::lds01::LIDAR_MOUNT;
use sim::scenario::{Frame, Scenario};
use sim::world::grid::Grid;
use sim::world::{ObjectTruth, Prim, RoomKind, Shape, Surface, World, WorldConfig};

use crate::annex::sensor::passes_through;
use crate::annex::{GeneratedRun, MOVE_ROBOT_CLEAR_M};
use crate::run_truth::{Door, FrameTruth, Furniture, Move, Person, RunTruth, VISIBLE_RETURNS};

/// Salt of the move's own random stream, so a run's world, robot and LiDAR are the same
/// whether or not a piece is moved in it.
const MOVE_SALT: u64 = 0x4D0F_E5A1_7C3B_9D21;

/// Shortest distance a moved piece is carried, m: farther than the world model's gate, so its
/// old place is left empty rather than the piece nudged.
const MOVE_MIN_M: f32 = 1.5;

/// Most people walking in one run (0 to this many, drawn per run).
const MAX_WALKERS: usize = 2;

/// A piece taken away (or carried elsewhere) a third of the way into a run.
struct PlannedMove {
    /// Index of the piece in the world's objects.
    piece: usize,
    /// Frame from which its old place is empty.
    frame: usize,
    /// Where its centre goes (None: carried out of the room).
    to: Option<Point2>,
}

/// Draws the run's move as the annex does: half the runs move one piece that is not a desk a
/// third of the way in, carried out of the room (40 %) or to a free spot 0.7 m clear of
/// everything, at least [`MOVE_MIN_M`] from where it stood and [`MOVE_ROBOT_CLEAR_M`] from
/// `robot` (where the robot starts) (60 %).
fn plan_move(world: &World, seed: u64, frames: usize, robot: Point2) -> Option<PlannedMove> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ MOVE_SALT);
    let movable: Vec<usize> = (0..world.objects.len())
        .filter(|&k| world.objects[k].class != ObjectClass::Desk)
        .collect();
    if movable.is_empty() || !rng.random_bool(0.5) {
        return None;
    }
    let piece = movable[rng.random_range(0..movable.len())];
    let to = if rng.random_bool(0.6) {
        let mut rest = world.clone();
        rest.prims
            .retain(|p| p.surface != Surface::Object(piece as u16));
        rest.objects.remove(piece);
        let from = world.objects[piece].centre;
        (0..20)
            .filter_map(|_| rest.free_point(&mut rng, 0.7))
            .find(|q| q.distance(from) >= MOVE_MIN_M && q.distance(robot) >= MOVE_ROBOT_CLEAR_M)
    } else {
        None
    };
    Some(PlannedMove {
        piece,
        frame: frames / 3,
        to,
    })
}

/// Carries out `mv` on the world: the piece's surfaces leave; if it is carried elsewhere, they
/// come back shifted as a new object (the world's last) with its own truth. The ray index is
/// built again.
fn carry_out(world: &mut World, mv: &PlannedMove) {
    let id = Surface::Object(mv.piece as u16);
    let old: Vec<Prim> = world
        .prims
        .iter()
        .filter(|p| p.surface == id)
        .cloned()
        .collect();
    world.prims.retain(|p| p.surface != id);
    let Some(to) = mv.to else {
        world.grid = Grid::build(&world.prims);
        return;
    };
    let from = world.objects[mv.piece].centre;
    let shift = |p: Point2| Point2::new(p.x - from.x + to.x, p.y - from.y + to.y);
    let new = world.objects.len();
    let o = &world.objects[mv.piece];
    let moved = ObjectTruth {
        class: o.class,
        centre: to,
        yaw: o.yaw,
        footprint: o.footprint.map(shift),
    };
    world.objects.push(moved);
    world.prims.extend(old.into_iter().map(|p| Prim {
        shape: match p.shape {
            Shape::Segment { a, b } => Shape::Segment {
                a: shift(a),
                b: shift(b),
            },
            Shape::Circle { c, r } => Shape::Circle { c: shift(c), r },
        },
        surface: Surface::Object(new as u16),
        reflectivity: p.reflectivity,
    }));
    world.grid = Grid::build(&world.prims);
}

/// Clean returns of `frame` whose rays pass through `footprint` (world frame): the LiDAR seeing
/// a place empty.
fn rays_through(frame: &Frame, footprint: &[Point2]) -> usize {
    let lidar: Pose2 = frame.pose_mid.compose(&LIDAR_MOUNT);
    let o = Point2::new(lidar.x, lidar.y);
    frame
        .readings
        .iter()
        .enumerate()
        .filter(|(d, r)| {
            r.raw.range_mm != 0 && {
                let a = lidar.theta + (*d as f32).to_radians();
                let range = f32::from(r.raw.range_mm) / 1000.0;
                passes_through(
                    footprint,
                    o,
                    Point2::new(o.x + range * a.cos(), o.y + range * a.sin()),
                )
            }
        })
        .count()
}

/// Simulator run `i` of the evaluation seed `seed`: `seconds` long (even runs turn in place,
/// odd runs tour, as the dataset's scenarios do), all three room kinds, clutter, 0–2 people
/// walking (`sim::people`, drawn from their own salted stream, so the room, robot and LiDAR
/// are the same with or without them), one piece moved in half the runs; a share
/// `varied` of the worlds drawn varied (`WorldConfig::varied`, then with up to 6 clutter
/// items as the training data has them); a share `worn` of the runs seen by a worn LiDAR
/// (`ScenarioConfig::worn`).
pub fn generate(seed: u64, i: usize, seconds: f64, varied: f64, worn: f64) -> GeneratedRun {
    let world = WorldConfig {
        kinds: vec![RoomKind::Rect, RoomKind::LShape, RoomKind::TwoRooms],
        varied,
        max_clutter: if varied > 0.0 { 6 } else { 3 },
        ..WorldConfig::default()
    };
    let cfg = scenario_config(i, &world, worn);
    let run_seed = scenario_seed(seed, i);
    let mut s = Scenario::new(run_seed, &cfg);
    let start = s.robot_start_pose();
    let to_map = start.inverse();
    let n = (seconds * 5.0) as usize;
    let n_obj = s.world.objects.len();
    let planned = plan_move(&s.world, run_seed, n, Point2::new(start.x, start.y));
    s.add_people(run_seed, MAX_WALKERS);
    let old_footprint = planned.as_ref().map(|m| s.world.objects[m.piece].footprint);
    let mut seen_empty = None;
    let mut returns = vec![0u32; n_obj + 1];
    let mut visible_from = vec![None; n_obj + 1];
    let mut door_returns = vec![0u32; s.world.doors.len()];
    let mut frame = Frame::default();
    let mut odom = Vec::new();
    let mut capture = Vec::new();
    let mut odom_lines = String::new();
    let mut frames = Vec::new();
    for f in 0..n {
        if let Some(m) = planned.as_ref().filter(|m| m.frame == f) {
            carry_out(&mut s.world, m);
        }
        odom.clear();
        s.next_frame(&mut frame, &mut odom);
        frame.emit(&mut capture);
        if let (Some(m), Some(fp), None) = (&planned, &old_footprint, seen_empty)
            && f >= m.frame
            && rays_through(&frame, fp) >= 5
        {
            seen_empty = Some(f);
        }
        for o in &odom {
            odom_lines.push_str(&format!(
                "{{\"t\":{:.6},\"left_ticks\":{},\"right_ticks\":{},\"mag_ut\":[{:.4},{:.4},{:.4}]}}\n",
                o.t, o.left_ticks, o.right_ticks, o.mag_ut[0], o.mag_ut[1], o.mag_ut[2]
            ));
        }
        let mut person_returns = [0u32; MAX_WALKERS];
        for r in frame.readings.iter().filter(|r| r.raw.range_mm != 0) {
            match r.hit {
                Some(Surface::Person(id)) => {
                    if let Some(n) = person_returns.get_mut(usize::from(id)) {
                        *n += 1;
                    }
                }
                Some(Surface::Object(k)) => {
                    let k = usize::from(k);
                    returns[k] += 1;
                    if returns[k] == VISIBLE_RETURNS {
                        visible_from[k] = Some(f);
                    }
                }
                Some(Surface::DoorFrame(k)) => door_returns[usize::from(k)] += 1,
                _ => {}
            }
        }
        frames.push(FrameTruth {
            t: frame.t_start_s,
            robot: Some(to_map.compose(&frame.pose_start)),
            people: frame
                .people_mid
                .iter()
                .enumerate()
                .map(|(id, &at)| Person {
                    id,
                    at: to_map.transform(at),
                    returns: person_returns.get(id).copied().unwrap_or(0),
                })
                .collect(),
        });
    }
    let w = &s.world;
    let truth = RunTruth {
        name: format!(
            "sim {i}: {}, {}, {} piece(s), {} door(s), {} walker(s){}",
            w.kind.name(),
            if i.is_multiple_of(2) {
                "turning in place"
            } else {
                "touring"
            },
            n_obj,
            w.doors.len(),
            s.people.len(),
            match &planned {
                Some(m) if m.to.is_some() => ", one piece moved",
                Some(_) => ", one piece taken away",
                None => "",
            }
        ),
        furniture: w
            .objects
            .iter()
            .enumerate()
            .map(|(k, o)| {
                let this_moved = planned.as_ref().is_some_and(|m| m.piece == k);
                let (piece, from_frame, what) = match &planned {
                    Some(m) if k >= n_obj => (
                        m.piece,
                        m.frame,
                        format!("{} (moved here)", o.class.as_str()),
                    ),
                    Some(m) if this_moved => (
                        k,
                        0,
                        format!("{} (taken away at frame {})", o.class.as_str(), m.frame),
                    ),
                    _ => (k, 0, o.class.as_str().into()),
                };
                Furniture {
                    piece,
                    class: o.class,
                    footprint: o.footprint.iter().map(|&p| to_map.transform(p)).collect(),
                    from_frame,
                    to_frame: match &planned {
                        Some(m) if this_moved => m.frame,
                        _ => usize::MAX,
                    },
                    visible_from: visible_from[k],
                    returns: returns[k],
                    what,
                    against_wall: k < n_obj
                        && o.footprint.iter().any(|&c| {
                            w.prims
                                .iter()
                                .any(|p| p.surface == Surface::Wall && p.shape.distance(c) < 0.1)
                        }),
                }
            })
            .collect(),
        doors: w
            .doors
            .iter()
            .zip(&door_returns)
            .map(|(d, &r)| Door {
                centre: to_map.transform(d.centre),
                width: d.width,
                returns: r,
            })
            .collect(),
        clutter: w
            .clutter
            .iter()
            .map(|c| (to_map.transform(c.centre), c.kind.to_string()))
            .collect::<Vec<(Point2, String)>>(),
        frames,
        moves: planned
            .iter()
            .map(|m| Move {
                before: m.piece,
                frame: m.frame,
                seen_empty,
            })
            .collect(),
        walls: w
            .prims
            .iter()
            .filter_map(|p| match (p.surface, p.shape) {
                (Surface::Wall | Surface::DoorFrame(_), sim::world::Shape::Segment { a, b }) => {
                    Some((to_map.transform(a), to_map.transform(b)))
                }
                _ => None,
            })
            .collect(),
    };
    GeneratedRun {
        capture,
        odom: odom_lines,
        lidar: LidarModel::Lds01,
        truth,
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn a_moved_piece_is_never_carried_on_to_the_robot() {
        let world = WorldConfig {
            kinds: vec![RoomKind::Rect, RoomKind::LShape, RoomKind::TwoRooms],
            varied: 0.5,
            max_clutter: 6,
            ..WorldConfig::default()
        };
        let mut carried = 0;
        for i in 0..60 {
            let run_seed = scenario_seed(4242, i);
            let s = Scenario::new(run_seed, &scenario_config(i, &world, 0.0));
            let start = s.robot_start_pose();
            let robot = Point2::new(start.x, start.y);
            if let Some(q) = plan_move(&s.world, run_seed, 150, robot).and_then(|m| m.to) {
                carried += 1;
                assert!(q.distance(robot) >= MOVE_ROBOT_CLEAR_M, "run {i}: {q:?}");
            }
        }
        assert!(carried > 5, "pieces carried elsewhere: {carried}");
    }
}
