//! Runs from umbra's own simulator (the family that trained and tuned both methods), on
//! held-out seeds, as capture bytes, odometry and truth for the world evaluation.

use drivers::lidar::LidarModel;
use perception::geometry::Point2;
use sim::dataset::{scenario_config, scenario_seed};
use sim::scenario::{Frame, Scenario};
use sim::world::{RoomKind, Surface, WorldConfig};

use crate::annex::GeneratedRun;
use crate::run_truth::{Door, FrameTruth, Furniture, RunTruth, VISIBLE_RETURNS};

/// Simulator run `i` of the evaluation seed `seed`: `seconds` long (even runs turn in place,
/// odd runs tour, as the dataset's scenarios do), all three room kinds, clutter; a share
/// `varied` of the worlds drawn varied (`WorldConfig::varied`, then with up to 6 clutter
/// items as the training data has them).
pub fn generate(seed: u64, i: usize, seconds: f64, varied: f64) -> GeneratedRun {
    let world = WorldConfig {
        kinds: vec![RoomKind::Rect, RoomKind::LShape, RoomKind::TwoRooms],
        varied,
        max_clutter: if varied > 0.0 { 6 } else { 3 },
        ..WorldConfig::default()
    };
    let cfg = scenario_config(i, &world);
    let mut s = Scenario::new(scenario_seed(seed, i), &cfg);
    let to_map = s.robot_start_pose().inverse();
    let n_obj = s.world.objects.len();
    let mut returns = vec![0u32; n_obj];
    let mut visible_from = vec![None; n_obj];
    let mut door_returns = vec![0u32; s.world.doors.len()];
    let mut frame = Frame::default();
    let mut odom = Vec::new();
    let mut capture = Vec::new();
    let mut odom_lines = String::new();
    let mut frames = Vec::new();
    let n = (seconds * 5.0) as usize;
    for f in 0..n {
        odom.clear();
        s.next_frame(&mut frame, &mut odom);
        frame.emit(&mut capture);
        for o in &odom {
            odom_lines.push_str(&format!(
                "{{\"t\":{:.6},\"left_ticks\":{},\"right_ticks\":{},\"mag_ut\":[{:.4},{:.4},{:.4}]}}\n",
                o.t, o.left_ticks, o.right_ticks, o.mag_ut[0], o.mag_ut[1], o.mag_ut[2]
            ));
        }
        for r in frame.readings.iter().filter(|r| r.raw.range_mm != 0) {
            match r.hit {
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
            people: Vec::new(),
        });
    }
    let w = &s.world;
    let truth = RunTruth {
        name: format!(
            "sim {i}: {}, {}, {} piece(s), {} door(s)",
            w.kind.name(),
            if i.is_multiple_of(2) {
                "turning in place"
            } else {
                "touring"
            },
            n_obj,
            w.doors.len()
        ),
        furniture: w
            .objects
            .iter()
            .enumerate()
            .map(|(k, o)| Furniture {
                piece: k,
                class: o.class,
                footprint: o.footprint.iter().map(|&p| to_map.transform(p)).collect(),
                from_frame: 0,
                to_frame: usize::MAX,
                visible_from: visible_from[k],
                returns: returns[k],
                what: o.class.as_str().into(),
                against_wall: o.footprint.iter().any(|&c| {
                    w.prims
                        .iter()
                        .any(|p| p.surface == Surface::Wall && p.shape.distance(c) < 0.1)
                }),
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
        moves: Vec::new(),
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
