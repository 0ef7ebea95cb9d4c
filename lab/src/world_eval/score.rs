//! Scoring `umbra`'s output lines against a run's truth: the final map (per-class precision
//! and recall over the furniture that was visible), phantoms per frame by source, identity
//! over time (IDF1 and ID switches, CLEAR-MOT sense), moved pieces leaving the map, doors,
//! and walking people reported as furniture.

use perception::class::ObjectClass;
use perception::geometry::{Point2, wrap_angle};

pub use super::assignment::max_assignment;
pub use super::line::{Line, Reported};
pub use super::places::{BESIDE_M, CLUTTER_M, DOORWAY_M, PHANTOM_PLACES, WALL_FACE_M};
use super::places::{at_wall_face, phantom_place};
use super::unrefuted::unrefuted;
use super::{confusion, reliability};
use crate::eval_a::class_index;
use crate::run_truth::{Furniture, PERSON_VISIBLE_RETURNS, Person, RunTruth};

/// A reported object is on a piece of furniture when within this distance of its footprint.
pub const MATCH_M: f32 = 0.3;
/// A reported door (or door frame) is on a doorway when within this distance of its centre.
pub const DOOR_MATCH_M: f32 = 0.5;
/// A reported object is on a walking person when within this distance of the legs' midpoint.
pub const PERSON_M: f32 = 0.4;
/// Where the bands of `Tally::people_in_view_by_range` part, m from the robot.
pub const PEOPLE_RANGES_M: [f32; 2] = [1.5, 2.5];

/// Counts, summed over runs; the rates are derived when reporting.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tally {
    /// Runs.
    pub runs: u32,
    /// Frames scored.
    pub frames: u32,
    /// Final map, per class (chair, box, desk): matched visible furniture.
    pub map_tp: [u32; 3],
    /// Final map: reported objects of the class (not counting ones on unseen furniture).
    pub map_reported: [u32; 3],
    /// Final map: visible furniture of the class.
    pub map_visible: [u32; 3],
    /// Final map recall split: (found, visible) against a wall, and in the open.
    pub wall_found: [u32; 2],
    /// See `wall_found`.
    pub open_found: [u32; 2],
    /// Final `doors`: matched visible doors, reported doors, visible doors.
    pub doors: [u32; 3],
    /// Final `objects` of class door_frame on a visible door: doors found that way.
    pub door_frames_found: u32,
    /// Reported objects per frame that lie on no furniture and no door, by source A, B, AB.
    pub phantoms: [u32; 3],
    /// Phantom objects: the distinct `objects` ids reported as a phantom in at least one frame
    /// of a run, summed over runs. Phantoms per frame weighs each by how long it lived, and a
    /// few long-lived ones make most of it; this counts each once.
    #[serde(default)]
    pub phantom_objects: u32,
    /// Phantoms (among `objects`) within 0.15 m of a wall face, and by class (chair, box, desk,
    /// door frame).
    pub phantoms_at_wall: u32,
    /// See `phantoms_at_wall`.
    pub phantoms_by_class: [u32; 4],
    /// Phantoms (among `objects`) by what they lie on, first that applies: a piece of clutter
    /// (within `CLUTTER_M` of its centre), beside furniture (within `BESIDE_M` of a footprint:
    /// an offset or a second report of one piece), at a doorway (within `DOORWAY_M` of its
    /// centre), at a wall face (within 0.15 m), anywhere else. Names: `PHANTOM_PLACES`.
    #[serde(default)]
    pub phantoms_where: [u32; 5],
    /// Reports among `objects` (summed over frames) at the old place of a piece taken away or
    /// moved before the LiDAR saw that place empty: no phantom, since nothing sensed says the
    /// piece went (`unrefuted.rs`). `phantoms` plus these is the count before that rule.
    #[serde(default)]
    pub unrefuted: u32,
    /// The same among the final map's objects, which are then left out of `map_reported`.
    #[serde(default)]
    pub map_unrefuted: u32,
    /// Reported objects on furniture of another class (and none of their own within reach).
    pub wrong_class: u32,
    /// Frames with a `detections` list, and the phantoms among those detections by source.
    pub det_frames: u32,
    /// See `det_frames`.
    pub det_phantoms: [u32; 3],
    /// IDF1's parts: ground-truth detections, reported detections, identity-true positives.
    pub id_gt: u32,
    /// See `id_gt`.
    pub id_hyp: u32,
    /// See `id_gt`.
    pub idtp: u32,
    /// Identity switches (CLEAR-MOT).
    pub id_switches: u32,
    /// Moves: seen empty and gone, seconds from seeing the place empty to its last report.
    pub move_gone_s: Vec<f64>,
    /// Moves seen empty whose old place was still reported at the end.
    pub move_stuck: u32,
    /// Moves whose old place the LiDAR never saw empty.
    pub move_unseen: u32,
    /// Object reports on a walking person (and on no furniture), and frames with a person.
    pub people_as_furniture: u32,
    /// See `people_as_furniture`.
    pub people_frames: u32,
    /// Frames × people of a `people` list, and how many it had within reach.
    pub people_found: [u32; 2],
    /// The same for the people in view (legs with at least `PERSON_VISIBLE_RETURNS` returns
    /// in the revolution).
    #[serde(default)]
    pub people_in_view_found: [u32; 2],
    /// `people` entries with no walking person within reach.
    #[serde(default)]
    pub people_phantoms: u32,
    /// The people in view by their distance from the robot (`PEOPLE_RANGES_M`: under 1.5 m,
    /// 1.5–2.5 m, farther): frames × people, and how many a `people` entry was within reach
    /// of.
    #[serde(default)]
    pub people_in_view_by_range: [[u32; 2]; 3],
    /// `people_phantoms` by where they lie (`PHANTOM_PLACES`).
    #[serde(default)]
    pub people_phantoms_where: [u32; 5],
    /// Frames whose `pose` was scored against the robot's true pose, the sum of their
    /// absolute heading errors (degrees), and the largest.
    #[serde(default)]
    pub pose_frames: u32,
    /// See `pose_frames`.
    #[serde(default)]
    pub heading_err_sum_deg: f64,
    /// See `pose_frames`.
    #[serde(default)]
    pub heading_err_max_deg: f64,
    /// Each run's position error at its last scored frame, m.
    #[serde(default)]
    pub final_position_err_m: Vec<f64>,
    /// How often a detection's score came true: for each source (A, B, AB), class (chair, box,
    /// desk, door frame) and tenth of the score, the detections and how many of them stood
    /// on a piece of their class (a door frame: on a door), `[n, true]` pairs in that order
    /// ([`reliability::reliability_index`]); empty until a detection was scored.
    #[serde(default)]
    pub reliability: Vec<u32>,
    /// Pieces the final map is scored on by class (chair, box, desk) and `fates::FATES`.
    #[serde(default)]
    pub fates: [[u32; super::fates::FATE_COUNT]; 3],
    /// The detections on a piece by source, the piece's class and the class they gave it
    /// ([`super::confusion`]).
    #[serde(default)]
    pub confusion: super::confusion::Confusion,
    /// The reports on walking people, one line each (frame, id, class, source), for reading.
    #[serde(skip)]
    pub people_reports: Vec<String>,
    /// Every reported piece of furniture (door frames left to the doors), as `(frame, id,
    /// phantom)` by this scorer's rule: the labels `training/fit_report_model.py` fits the
    /// report model on (`labels.txt` beside a run's track log). One run's; [`Tally::add`]
    /// does not sum them.
    #[serde(skip)]
    pub object_labels: Vec<(u64, u64, bool)>,
}

/// Class names of the tally's per-class arrays.
pub const CLASSES: [&str; 3] = ["chair", "box", "desk"];

fn on_furniture<'a>(
    alive: &'a [&'a Furniture],
    p: Point2,
) -> impl Iterator<Item = &'a &'a Furniture> + 'a {
    alive.iter().filter(move |f| f.distance(p) <= MATCH_M)
}

/// Scores one run's lines into `tally`.
pub fn score_run(truth: &RunTruth, lines: &[Line], tally: &mut Tally) {
    tally.runs += 1;
    let n_f = truth.furniture.len();
    let mut hyp_ids: Vec<u64> = Vec::new();
    let mut co: Vec<Vec<i64>> = vec![Vec::new(); n_f];
    let mut last_match: Vec<Option<u64>> = vec![None; n_f];
    let mut last_pose_err = None;
    let mut phantom_ids: Vec<u64> = Vec::new();
    for line in lines {
        let Some(fi) = truth.frame_at(line.t) else {
            continue;
        };
        tally.frames += 1;
        if let (Some(p), Some(r)) = (line.pose, truth.frames[fi].robot) {
            let e = f64::from(wrap_angle(p.theta - r.theta).abs().to_degrees());
            tally.pose_frames += 1;
            tally.heading_err_sum_deg += e;
            tally.heading_err_max_deg = tally.heading_err_max_deg.max(e);
            last_pose_err = Some(f64::from(
                Point2::new(p.x, p.y).distance(Point2::new(r.x, r.y)),
            ));
        }
        let alive: Vec<&Furniture> = truth.furniture.iter().filter(|f| f.alive(fi)).collect();
        let people = &truth.frames[fi].people;
        if !people.is_empty() {
            tally.people_frames += 1;
        }
        let mut tally_objects = |objs: &[Reported], phantoms: &mut [u32; 3], main: bool| {
            for o in objs {
                if !main && let Some(c) = o.class {
                    let right = if c == ObjectClass::DoorFrame {
                        truth
                            .doors
                            .iter()
                            .any(|d| d.centre.distance(o.at) <= DOOR_MATCH_M)
                    } else {
                        on_furniture(&alive, o.at).any(|f| f.class == c)
                    };
                    reliability::count(&mut tally.reliability, o.source, c, o.score, right);
                    confusion::count(&mut tally.confusion, &alive, o.source, c, o.at, MATCH_M);
                }
                match o.class {
                    Some(ObjectClass::DoorFrame) => {
                        if !truth
                            .doors
                            .iter()
                            .any(|d| d.centre.distance(o.at) <= DOOR_MATCH_M)
                        {
                            phantoms[o.source] += 1;
                            if main {
                                phantom_ids.push(o.id);
                                tally.phantoms_by_class[3] += 1;
                                tally.phantoms_where[phantom_place(truth, &alive, o.at)] += 1;
                            }
                        }
                    }
                    c => {
                        let mut near = on_furniture(&alive, o.at).peekable();
                        // Only reported objects may be excused; detections skip the test.
                        let gone_unseen =
                            main && near.peek().is_none() && unrefuted(truth, fi, o.at, MATCH_M);
                        if let (true, Some(frame)) = (main, line.frame) {
                            let phantom = near.peek().is_none() && !gone_unseen;
                            tally.object_labels.push((frame, o.id, phantom));
                        }
                        if gone_unseen {
                            tally.unrefuted += 1;
                        } else if near.peek().is_none() {
                            phantoms[o.source] += 1;
                            if main {
                                phantom_ids.push(o.id);
                                tally.phantoms_at_wall += u32::from(at_wall_face(truth, o.at));
                                if let Some(c) = c {
                                    tally.phantoms_by_class[c as usize] += 1;
                                }
                                tally.phantoms_where[phantom_place(truth, &alive, o.at)] += 1;
                            }
                            let nearest_person = || {
                                people
                                    .iter()
                                    .filter(|p| p.at.distance(o.at) <= PERSON_M)
                                    .min_by(|a, b| {
                                        a.at.distance(o.at).total_cmp(&b.at.distance(o.at))
                                    })
                            };
                            if let Some(p) = main.then(nearest_person).flatten() {
                                tally.people_as_furniture += 1;
                                tally.people_reports.push(format!(
                                    "frame {}: id {} {} ({}) at ({:.2}, {:.2}), person {} at ({:.2}, {:.2})",
                                    fi,
                                    o.id,
                                    c.map_or("?", ObjectClass::as_str),
                                    ["A", "B", "AB"][o.source.min(2)],
                                    o.at.x,
                                    o.at.y,
                                    p.id,
                                    p.at.x,
                                    p.at.y
                                ));
                            }
                        } else if main && !near.any(|f| Some(f.class) == c) {
                            tally.wrong_class += 1;
                        }
                    }
                }
            }
        };
        let mut ph = tally.phantoms;
        tally_objects(&line.objects, &mut ph, true);
        tally.phantoms = ph;
        if let Some(det) = &line.detections {
            tally.det_frames += 1;
            let mut ph = tally.det_phantoms;
            tally_objects(det, &mut ph, false);
            tally.det_phantoms = ph;
        }
        if let Some(found) = &line.people {
            let hit = |p: &&Person| found.iter().any(|q| q.distance(p.at) <= PERSON_M);
            tally.people_found[0] += people.len() as u32;
            tally.people_found[1] += people.iter().filter(hit).count() as u32;
            let robot = truth.frames[fi].robot.map(|r| Point2::new(r.x, r.y));
            for p in people
                .iter()
                .filter(|p| p.returns >= PERSON_VISIBLE_RETURNS)
            {
                let got = u32::from(hit(&p));
                tally.people_in_view_found[0] += 1;
                tally.people_in_view_found[1] += got;
                if let Some(robot) = robot {
                    let d = p.at.distance(robot);
                    let band = PEOPLE_RANGES_M.iter().take_while(|&&m| d >= m).count();
                    tally.people_in_view_by_range[band][0] += 1;
                    tally.people_in_view_by_range[band][1] += got;
                }
            }
            for q in found
                .iter()
                .filter(|q| people.iter().all(|p| q.distance(p.at) > PERSON_M))
            {
                tally.people_phantoms += 1;
                tally.people_phantoms_where[phantom_place(truth, &alive, *q)] += 1;
            }
        }
        // Identity: furniture alive and already visible vs reported furniture-class objects.
        let gt: Vec<usize> = (0..n_f)
            .filter(|&g| {
                truth.furniture[g].alive(fi)
                    && truth.furniture[g].visible_from.is_some_and(|v| v <= fi)
            })
            .collect();
        let hyp: Vec<&Reported> = line
            .objects
            .iter()
            .filter(|o| o.class.is_some_and(|c| c != ObjectClass::DoorFrame))
            .filter(|o| {
                !unrefuted(truth, fi, o.at, MATCH_M) || on_furniture(&alive, o.at).next().is_some()
            })
            .collect();
        tally.id_gt += gt.len() as u32;
        tally.id_hyp += hyp.len() as u32;
        let mut pairs = Vec::new();
        for &g in &gt {
            for h in &hyp {
                let d = truth.furniture[g].distance(h.at);
                if d <= MATCH_M {
                    let j = match hyp_ids.iter().position(|&x| x == h.id) {
                        Some(j) => j,
                        None => {
                            hyp_ids.push(h.id);
                            hyp_ids.len() - 1
                        }
                    };
                    if co[g].len() <= j {
                        co[g].resize(j + 1, 0);
                    }
                    co[g][j] += 1;
                    // Keeping last frame's match comes first (CLEAR-MOT), then nearest.
                    let keep = last_match[g] == Some(h.id);
                    pairs.push((!keep, d, g, h.id));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let (mut used_g, mut used_h) = (Vec::new(), Vec::new());
        for (_, _, g, h) in pairs {
            if used_g.contains(&g) || used_h.contains(&h) {
                continue;
            }
            used_g.push(g);
            used_h.push(h);
            if last_match[g].is_some_and(|l| l != h) {
                tally.id_switches += 1;
            }
            last_match[g] = Some(h);
        }
    }
    tally.idtp += max_assignment(&co) as u32;
    tally.final_position_err_m.extend(last_pose_err);
    phantom_ids.sort_unstable();
    phantom_ids.dedup();
    tally.phantom_objects += phantom_ids.len() as u32;

    // Moves.
    for mv in &truth.moves {
        let old = &truth.furniture[mv.before];
        let Some(seen) = mv.seen_empty else {
            tally.move_unseen += 1;
            continue;
        };
        let t_seen = truth.frames[seen].t;
        let reported_there = |l: &Line| {
            l.objects.iter().any(|o| {
                o.class.is_some_and(|c| c != ObjectClass::DoorFrame)
                    && old.distance(o.at) <= MATCH_M
            })
        };
        match lines.iter().rposition(reported_there) {
            Some(k) if k + 1 == lines.len() => tally.move_stuck += 1,
            Some(k) => tally.move_gone_s.push((lines[k + 1].t - t_seen).max(0.0)),
            None => tally.move_gone_s.push(0.0),
        }
    }

    // Final map.
    let Some(last) = lines.last() else {
        return;
    };
    let Some(fi) = truth.frame_at(last.t) else {
        return;
    };
    let alive: Vec<&Furniture> = truth.furniture.iter().filter(|f| f.alive(fi)).collect();
    let visible = |f: &Furniture| f.visible_from.is_some();
    let mut taken = vec![false; alive.len()];
    let mut order: Vec<(f32, usize, usize)> = Vec::new();
    for (r, o) in last.objects.iter().enumerate() {
        for (g, f) in alive.iter().enumerate() {
            if o.class == Some(f.class) {
                let d = f.distance(o.at);
                if d <= MATCH_M {
                    order.push((d, r, g));
                }
            }
        }
    }
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut report_matched = vec![None; last.objects.len()];
    for (_, r, g) in order {
        if report_matched[r].is_none() && !taken[g] {
            taken[g] = true;
            report_matched[r] = Some(g);
        }
    }
    for (r, o) in last.objects.iter().enumerate() {
        let Some(ci) = o.class.and_then(class_index) else {
            continue;
        };
        match report_matched[r] {
            Some(g) if !visible(alive[g]) => {} // on furniture too little seen to score
            Some(_) => {
                tally.map_reported[ci] += 1;
                tally.map_tp[ci] += 1;
            }
            None if unrefuted(truth, fi, o.at, MATCH_M) => tally.map_unrefuted += 1,
            None => tally.map_reported[ci] += 1,
        }
    }
    for (g, f) in alive.iter().enumerate() {
        if !visible(f) {
            continue;
        }
        if let Some(ci) = class_index(f.class) {
            tally.map_visible[ci] += 1;
            tally.fates[ci][super::fates::fate(truth, lines, f, taken[g]).index()] += 1;
        }
        let split = if f.against_wall {
            &mut tally.wall_found
        } else {
            &mut tally.open_found
        };
        split[1] += 1;
        split[0] += u32::from(taken[g]);
    }
    // Doors.
    let seen_doors: Vec<_> = truth
        .doors
        .iter()
        .filter(|d| d.returns >= crate::run_truth::VISIBLE_RETURNS)
        .collect();
    tally.doors[2] += seen_doors.len() as u32;
    tally.doors[1] += last.doors.len() as u32;
    let mut door_taken = vec![false; truth.doors.len()];
    for d in &last.doors {
        if let Some(k) = truth
            .doors
            .iter()
            .enumerate()
            .position(|(k, t)| !door_taken[k] && t.centre.distance(*d) <= DOOR_MATCH_M)
        {
            door_taken[k] = true;
            if truth.doors[k].returns >= crate::run_truth::VISIBLE_RETURNS {
                tally.doors[0] += 1;
            } else {
                tally.doors[1] -= 1; // a door too little seen to score
            }
        }
    }
    tally.door_frames_found += seen_doors
        .iter()
        .filter(|t| {
            last.objects.iter().any(|o| {
                o.class == Some(ObjectClass::DoorFrame) && o.at.distance(t.centre) <= DOOR_MATCH_M
            })
        })
        .count() as u32;
}

impl Tally {
    /// Sums another tally into this one.
    pub fn add(&mut self, o: &Tally) {
        macro_rules! sum {
            ($($f:ident),*) => { $( self.$f += o.$f; )* };
        }
        macro_rules! sum_arr {
            ($($f:ident),*) => { $( for (a, b) in self.$f.iter_mut().zip(&o.$f) { *a += b; } )* };
        }
        sum!(
            runs,
            frames,
            door_frames_found,
            phantom_objects,
            wrong_class,
            det_frames,
            id_gt,
            id_hyp,
            idtp
        );
        sum!(
            id_switches,
            unrefuted,
            map_unrefuted,
            phantoms_at_wall,
            move_stuck,
            move_unseen,
            people_as_furniture,
            people_frames,
            people_phantoms
        );
        sum_arr!(
            map_tp,
            map_reported,
            map_visible,
            wall_found,
            open_found,
            doors,
            phantoms
        );
        sum_arr!(
            det_phantoms,
            people_found,
            people_in_view_found,
            phantoms_by_class,
            phantoms_where,
            people_phantoms_where
        );
        for (a, b) in self
            .people_in_view_by_range
            .iter_mut()
            .zip(&o.people_in_view_by_range)
        {
            a[0] += b[0];
            a[1] += b[1];
        }
        self.pose_frames += o.pose_frames;
        self.heading_err_sum_deg += o.heading_err_sum_deg;
        self.heading_err_max_deg = self.heading_err_max_deg.max(o.heading_err_max_deg);
        self.final_position_err_m
            .extend_from_slice(&o.final_position_err_m);
        self.move_gone_s.extend_from_slice(&o.move_gone_s);
        self.people_reports.extend_from_slice(&o.people_reports);
        if self.reliability.len() < o.reliability.len() {
            self.reliability.resize(o.reliability.len(), 0);
        }
        for (a, b) in self.reliability.iter_mut().zip(&o.reliability) {
            *a += b;
        }
        super::fates::add(&mut self.fates, &o.fates);
        confusion::add(&mut self.confusion, &o.confusion);
    }

    /// IDF1 = 2·IDTP / (GT + reported).
    pub fn idf1(&self) -> f64 {
        ratio(2 * self.idtp, self.id_gt + self.id_hyp)
    }
}

/// `a / b`, NaN when `b` is 0.
pub fn ratio(a: u32, b: u32) -> f64 {
    if b == 0 {
        f64::NAN
    } else {
        f64::from(a) / f64::from(b)
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::run_truth::{Door, FrameTruth, Move};
    use perception::geometry::Pose2;

    fn truth() -> RunTruth {
        let f = |piece, class, x, y| Furniture::square(piece, class, Point2::new(x, y), 0.2);
        RunTruth {
            name: "t".into(),
            furniture: vec![
                f(0, ObjectClass::Chair, 1.0, 0.0),
                f(1, ObjectClass::Box, -1.0, 0.0),
            ],
            doors: vec![Door {
                centre: Point2::new(0.0, 2.0),
                width: 0.9,
                returns: 50,
            }],
            clutter: vec![],
            frames: (0..4)
                .map(|k| FrameTruth {
                    t: 0.2 * f64::from(k),
                    ..FrameTruth::default()
                })
                .collect(),
            moves: vec![],
            walls: vec![],
        }
    }

    fn obj(id: u64, class: ObjectClass, x: f32, y: f32) -> Reported {
        Reported {
            id,
            class: Some(class),
            at: Point2::new(x, y),
            source: 2,
            score: 0.9,
        }
    }

    #[test]
    fn perfect_lines_score_perfectly() {
        let t = truth();
        let lines: Vec<Line> = (0..4)
            .map(|k| Line {
                frame: None,
                t: 0.2 * f64::from(k),
                objects: vec![
                    obj(7, ObjectClass::Chair, 1.0, 0.05),
                    obj(9, ObjectClass::Box, -1.1, 0.0),
                ],
                doors: vec![Point2::new(0.1, 2.0)],
                ..Line::default()
            })
            .collect();
        let mut s = Tally::default();
        score_run(&t, &lines, &mut s);
        assert_eq!(s.map_tp, [1, 1, 0]);
        assert_eq!(s.map_reported, [1, 1, 0]);
        assert_eq!(s.map_visible, [1, 1, 0]);
        assert_eq!(s.doors, [1, 1, 1]);
        assert_eq!(s.phantoms, [0, 0, 0]);
        assert_eq!((s.id_switches, s.idtp, s.id_gt, s.id_hyp), (0, 8, 8, 8));
        assert!((s.idf1() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn the_pose_is_scored_against_the_robot_where_the_truth_knows_it() {
        let mut t = truth();
        // The robot turns 0.1 rad a frame; the line's heading lags it by 2° from frame 1 on,
        // across ±π in frame 3, and the last frame's position is 0.3 m off.
        for (k, f) in t.frames.iter_mut().enumerate() {
            f.robot = (k != 2).then(|| Pose2::new(0.0, 0.0, wrap_angle(3.0 + 0.1 * k as f32)));
        }
        let lines: Vec<Line> = (0..4)
            .map(|k| {
                let lag = if k == 0 { 0.0 } else { 2f32.to_radians() };
                let theta = wrap_angle(3.0 + 0.1 * k as f32 - lag);
                Line {
                    frame: None,
                    t: 0.2 * f64::from(k),
                    pose: Some(Pose2::new(if k == 3 { 0.3 } else { 0.0 }, 0.0, theta)),
                    ..Line::default()
                }
            })
            .collect();
        let mut s = Tally::default();
        score_run(&t, &lines, &mut s);
        assert_eq!(s.pose_frames, 3, "frame 2 has no true pose");
        assert!(
            (s.heading_err_sum_deg - 4.0).abs() < 1e-3,
            "{}",
            s.heading_err_sum_deg
        );
        assert!((s.heading_err_max_deg - 2.0).abs() < 1e-3);
        assert_eq!(s.final_position_err_m.len(), 1);
        assert!((s.final_position_err_m[0] - 0.3).abs() < 1e-6);
        let mut sum = Tally::default();
        sum.add(&s);
        sum.add(&s);
        assert_eq!((sum.pose_frames, sum.final_position_err_m.len()), (6, 2));
    }

    #[test]
    fn people_in_view_are_split_by_range_and_made_up_ones_by_place() {
        let mut t = truth();
        // Each frame: one person 1 m from the robot, one 3 m off, one with too few returns
        // to be in view; the list finds the near one and makes one up in the open.
        for f in &mut t.frames {
            f.robot = Some(Pose2::new(0.0, -1.0, 0.0));
            f.people = vec![
                Person {
                    id: 0,
                    at: Point2::new(0.0, 0.0),
                    returns: 6,
                },
                Person {
                    id: 1,
                    at: Point2::new(3.0, -1.0),
                    returns: 4,
                },
                Person {
                    id: 2,
                    at: Point2::new(-2.0, -1.0),
                    returns: 1,
                },
            ];
        }
        let lines: Vec<Line> = (0..4)
            .map(|k| Line {
                t: 0.2 * f64::from(k),
                people: Some(vec![Point2::new(0.1, 0.1), Point2::new(0.0, -3.0)]),
                ..Line::default()
            })
            .collect();
        let mut s = Tally::default();
        score_run(&t, &lines, &mut s);
        assert_eq!(s.people_in_view_found, [8, 4]);
        assert_eq!(s.people_in_view_by_range, [[4, 4], [0, 0], [4, 0]]);
        assert_eq!(s.people_phantoms, 4);
        assert_eq!(s.people_phantoms_where, [0, 0, 0, 0, 4], "in the open");
        let mut sum = Tally::default();
        sum.add(&s);
        sum.add(&s);
        assert_eq!(sum.people_in_view_by_range, [[8, 8], [0, 0], [8, 0]]);
        assert_eq!(sum.people_phantoms_where[4], 8);
    }

    #[test]
    fn ids_that_trade_places_switch_and_lower_idf1() {
        let t = truth();
        // Ids are list positions, and the list order flips after two frames.
        let lines: Vec<Line> = (0..4)
            .map(|k| {
                let mut objects = vec![
                    obj(0, ObjectClass::Chair, 1.0, 0.0),
                    obj(1, ObjectClass::Box, -1.0, 0.0),
                ];
                if k >= 2 {
                    objects.reverse();
                    objects[0].id = 0;
                    objects[1].id = 1;
                }
                Line {
                    frame: None,
                    t: 0.2 * f64::from(k),
                    objects,
                    ..Line::default()
                }
            })
            .collect();
        let mut s = Tally::default();
        score_run(&t, &lines, &mut s);
        assert_eq!(s.id_switches, 2);
        assert_eq!(s.idtp, 4);
        assert!((s.idf1() - 0.5).abs() < 1e-9);
    }

    #[test]
    fn phantoms_wrong_classes_and_a_stuck_move_are_counted() {
        let mut t = truth();
        t.moves.push(Move {
            before: 1,
            frame: 1,
            seen_empty: Some(2),
        });
        t.furniture[1].to_frame = 1;
        let lines: Vec<Line> = (0..4)
            .map(|k| Line {
                frame: None,
                t: 0.2 * f64::from(k),
                objects: vec![
                    Reported {
                        source: 0,
                        score: 0.9,
                        ..obj(3, ObjectClass::Desk, 1.0, 0.0)
                    },
                    Reported {
                        source: 1,
                        score: 0.9,
                        ..obj(4, ObjectClass::Box, 3.0, 3.0)
                    },
                    obj(5, ObjectClass::Box, -1.0, 0.0),
                ],
                ..Line::default()
            })
            .collect();
        let mut s = Tally::default();
        score_run(&t, &lines, &mut s);
        // The box at (3, 3) is a phantom in every frame; the one at the moved box's old place
        // is one from frame 2 on, when the place was seen empty (in frame 1 nothing sensed
        // had said it went).
        assert_eq!(s.phantoms, [0, 4, 2]);
        // Two objects, ids 4 and 5, over six phantom reports.
        assert_eq!(s.phantom_objects, 2);
        assert_eq!(s.unrefuted, 1);
        assert_eq!(s.wrong_class, 4);
        assert_eq!(s.move_stuck, 1);
        assert_eq!(s.map_tp, [0, 0, 0]);
        assert_eq!(s.map_visible, [1, 0, 0]);
        assert_eq!(s.map_reported, [0, 2, 1]);
    }

    #[test]
    fn a_piece_taken_away_unseen_is_no_phantom_until_its_place_is_seen_empty() {
        let mut t = truth();
        t.moves.push(Move {
            before: 1,
            frame: 1,
            seen_empty: None,
        });
        t.furniture[1].to_frame = 1;
        let lines: Vec<Line> = (0..4u32)
            .map(|k| Line {
                frame: Some(u64::from(k) + 10),
                t: 0.2 * f64::from(k),
                objects: vec![obj(5, ObjectClass::Box, -1.0, 0.0)],
                ..Line::default()
            })
            .collect();
        let mut s = Tally::default();
        score_run(&t, &lines, &mut s);
        // On the box while it stood (frame 0), then kept where nothing said it went.
        assert_eq!(s.phantoms, [0, 0, 0]);
        assert_eq!(s.unrefuted, 3);
        assert_eq!(s.move_unseen, 1);
        // Neither a true nor a false entry of the final map, nor a hypothesis for identity.
        assert_eq!(s.map_reported, [0, 0, 0]);
        assert_eq!(s.map_unrefuted, 1);
        assert_eq!((s.id_hyp, s.idtp), (1, 1));
        // Seen empty at frame 2: a phantom from then on.
        t.moves[0].seen_empty = Some(2);
        let mut s = Tally::default();
        score_run(&t, &lines, &mut s);
        assert_eq!((s.phantoms, s.unrefuted), ([0, 0, 2], 1));
        assert_eq!((s.map_reported, s.map_unrefuted), ([0, 1, 0], 0));
        // The report model's labels say the same, frame by frame, by the line's frame number.
        let labels = [(10, 5, false), (11, 5, false), (12, 5, true), (13, 5, true)];
        assert_eq!(s.object_labels, labels);
    }

    #[test]
    fn detections_are_counted_by_source_class_and_score_with_whether_they_came_true() {
        let t = truth();
        let det = |source, class, x, y, score| Reported {
            source,
            score,
            ..obj(u64::MAX, class, x, y)
        };
        let line = Line {
            frame: None,
            detections: Some(vec![
                // Method B: a chair on the chair, a box on the chair (wrong class), a box on
                // nothing; both methods: a door frame on the door; a score that is no number.
                det(1, ObjectClass::Chair, 1.05, 0.0, 0.72),
                det(1, ObjectClass::Box, 1.0, 0.1, 0.31),
                det(1, ObjectClass::Box, 3.0, 3.0, 0.35),
                det(2, ObjectClass::DoorFrame, 0.1, 2.0, 1.0),
                det(0, ObjectClass::Desk, 1.0, 0.0, f32::NAN),
            ]),
            ..Line::default()
        };
        let mut s = Tally::default();
        score_run(&t, &[line], &mut s);
        use reliability::{RELIABILITY_LEN, reliability_index};
        assert_eq!(s.reliability.len(), RELIABILITY_LEN);
        let at = |src, c, score| reliability_index(src, c, score).unwrap();
        let pair = |k: usize| [s.reliability[k], s.reliability[k + 1]];
        assert_eq!(pair(at(1, ObjectClass::Chair, 0.72)), [1, 1]);
        assert_eq!(pair(at(1, ObjectClass::Box, 0.3)), [2, 0]);
        // A score of 1 is in the top tenth.
        assert_eq!(pair(at(2, ObjectClass::DoorFrame, 0.95)), [1, 1]);
        assert_eq!(s.reliability.iter().step_by(2).sum::<u32>(), 4);
        assert!(reliability_index(0, ObjectClass::Desk, f32::NAN).is_none());
    }

    #[test]
    fn phantoms_are_placed_on_what_they_lie_on() {
        let mut t = truth();
        t.clutter.push((Point2::new(3.0, -2.0), "pillar".into()));
        t.walls
            .push((Point2::new(-5.0, 3.0), Point2::new(5.0, 3.0)));
        let line = Line {
            frame: None,
            t: 0.0,
            objects: vec![
                obj(1, ObjectClass::Box, 3.2, -2.0),      // on the pillar
                obj(2, ObjectClass::Chair, 1.0, 0.7),     // 0.5 m from the chair's edge
                obj(3, ObjectClass::DoorFrame, 0.0, 1.4), // 0.6 m from the doorway's centre
                obj(4, ObjectClass::Box, 3.5, 2.9),       // at the wall face
                obj(5, ObjectClass::Desk, -3.0, -2.0),    // nowhere
                obj(6, ObjectClass::Chair, 1.0, 0.1),     // on the chair: no phantom
            ],
            ..Line::default()
        };
        let mut s = Tally::default();
        score_run(&t, &[line], &mut s);
        // The door frame is 0.1 m further from the doorway than `DOOR_MATCH_M`.
        assert_eq!(s.phantoms_where, [1, 1, 1, 1, 1]);
        assert_eq!(s.phantoms_by_class, [1, 2, 1, 1]);
        let far_frame = Line {
            frame: None,
            t: 0.2,
            objects: vec![obj(3, ObjectClass::DoorFrame, 0.0, 2.8)],
            ..Line::default()
        };
        let mut s = Tally::default();
        score_run(&t, &[far_frame], &mut s);
        assert_eq!(
            (s.phantoms_where, s.phantoms_by_class),
            ([0, 0, 1, 0, 0], [0, 0, 0, 1])
        );
    }

    #[test]
    fn summing_tallies_sums_every_count() {
        // Every numeric field of the JSON form of `a + a` is twice that of `a`: a field left
        // out of `add` (as `phantoms_at_wall` once was) shows here.
        fn numbers(v: &serde_json::Value, out: &mut Vec<f64>) {
            match v {
                serde_json::Value::Number(n) => out.push(n.as_f64().unwrap_or(f64::NAN)),
                serde_json::Value::Array(a) => a.iter().for_each(|x| numbers(x, out)),
                serde_json::Value::Object(o) => o.values().for_each(|x| numbers(x, out)),
                _ => {}
            }
        }
        // Every number in nested arrays set to `x`.
        fn fill(v: &mut serde_json::Value, x: u32) {
            match v {
                serde_json::Value::Array(a) => a.iter_mut().for_each(|e| fill(e, x)),
                _ => *v = x.into(),
            }
        }
        let one = |k: u32| {
            let mut t = Tally::default();
            let mut j = serde_json::to_value(&t).unwrap();
            if let serde_json::Value::Object(o) = &mut j {
                for (i, v) in o.values_mut().enumerate() {
                    let x = k + i as u32;
                    match v {
                        serde_json::Value::Number(_) => *v = x.into(),
                        serde_json::Value::Array(a) if a.is_empty() => {
                            *v = vec![serde_json::Value::from(x)].into()
                        }
                        serde_json::Value::Array(_) => fill(v, x),
                        _ => {}
                    }
                }
            }
            t = serde_json::from_value(j).unwrap();
            t
        };
        let a = one(1);
        let mut sum = Tally::default();
        sum.add(&a);
        sum.add(&a);
        let (ja, js) = (
            serde_json::to_value(&a).unwrap(),
            serde_json::to_value(&sum).unwrap(),
        );
        let (serde_json::Value::Object(oa), serde_json::Value::Object(os)) = (&ja, &js) else {
            panic!("a tally is a JSON object");
        };
        for (key, va) in oa {
            let (mut xa, mut xs) = (Vec::new(), Vec::new());
            numbers(va, &mut xa);
            numbers(&os[key], &mut xs);
            if key == "move_gone_s" || key == "final_position_err_m" {
                // A list per run: concatenated, not doubled.
                assert_eq!(xs.len(), 2 * xa.len(), "{key}");
                continue;
            }
            if key == "heading_err_max_deg" {
                // The largest of two equal tallies' largest.
                assert_eq!(xs, xa, "{key}");
                continue;
            }
            let doubled: Vec<f64> = xa.iter().map(|x| 2.0 * x).collect();
            assert_eq!(xs, doubled, "{key} is left out of Tally::add");
        }
    }

    #[test]
    fn line_parsing_reads_the_contract() {
        let l = Line::parse(r#"{"frame":3,"t":0.6,"pose":{"x":0,"y":0,"theta":0},"objects":[{"id":4,"class":"chair","x":1.0,"y":2.0,"score":0.9,"source":"B"}],"doors":[{"x":0.5,"y":0.1,"width":0.9}],"walls":[]}"#).unwrap();
        assert_eq!(
            l.objects,
            vec![Reported {
                id: 4,
                class: Some(ObjectClass::Chair),
                at: Point2::new(1.0, 2.0),
                source: 1,
                score: 0.9
            }]
        );
        assert_eq!(l.doors, vec![Point2::new(0.5, 0.1)]);
        assert!(l.detections.is_none());
        assert!(Line::parse("umbra: done").is_none());
    }
}
