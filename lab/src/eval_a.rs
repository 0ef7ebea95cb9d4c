//! Method A against the simulator's ground truth: training rows for the forest, and the
//! held-out score (per-class precision / recall / F1, confusion matrix, clutter, door frames,
//! merge errors).
//!
//! **Matching** (`docs/interfaces.md` §3): a detection matches the nearest true object of any class
//! (furniture or clutter) within 0.3 m of its centre; each true object takes at most one
//! detection (closest first); the rest are false positives. **Observable**: a true object
//! counts for recall when at least `min_cluster_points` (20) cloud points lie on its footprint
//! grown by 5 cm; a door when at least 10 cloud points lie within 0.3 m of each of its jambs
//! and its centre is within the range limit. **Doors** are scored per view: correct when every
//! observable door is found within 0.3 m and nothing else is reported as a door.
//! **Merge errors**: a candidate whose points belong to two or more true objects (≥ 20 % of its
//! points each) is a fusion of distinct objects.

use std::fmt::Write as _;

use crate::scenes_a::{SceneConfig, SceneView, TruthLabel, label_points, points_on, run_scene};
use perception::class::ObjectClass;
use perception::features::{self, N_FEATURES};
use perception::geometry::Point2;
use perception::method_a::{Classifier, MethodA, MethodAConfig};

/// Matching radius, metres.
pub const MATCH_M: f32 = 0.3;

/// Rows of the confusion matrix (truth): chair, box, desk, clutter, nothing.
pub const TRUTH_ROWS: [&str; 5] = ["chair", "box", "desk", "clutter", "nothing"];
/// Columns (prediction): chair, box, desk, not reported.
pub const PRED_COLS: [&str; 4] = ["chair", "box", "desk", "not reported"];

/// One training row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Scene.
    pub scene: usize,
    /// Frame.
    pub frame: usize,
    /// Forest label: chair, box, desk or none.
    pub label: &'static str,
    /// What the truth says in detail.
    pub truth: &'static str,
    /// Object-frame features.
    pub object: [f32; N_FEATURES],
    /// Map-axis features.
    pub axis: [f32; N_FEATURES],
}

/// The CSV header of training rows.
pub fn csv_header() -> String {
    let mut h = String::from("scene,frame,label,truth");
    for p in ["o_", "a_"] {
        for n in features::FEATURE_NAMES {
            let _ = write!(h, ",{p}{n}");
        }
    }
    h
}

impl Row {
    /// One CSV line (floats in shortest round-trip form).
    pub fn csv(&self) -> String {
        let mut s = format!(
            "{},{},{},{}",
            self.scene, self.frame, self.label, self.truth
        );
        for v in self.object.iter().chain(&self.axis) {
            let _ = write!(s, ",{v}");
        }
        s
    }
}

/// The forest's label for a candidate: its majority owner's class when the candidate, completed
/// as that class, is centred within [`MATCH_M`] of the owner (a detection worth reporting);
/// `none` otherwise (a lone leg, a wall piece, clutter).
fn truth_name(
    l: TruthLabel,
    view: &SceneView<'_>,
    bbox: &perception::shape::OrientedBox,
) -> (&'static str, &'static str) {
    match l {
        TruthLabel::Object(c, n) => {
            let centre = perception::method_a::complete_centre(c, bbox, view.sensor);
            let truth = view.world.objects[n as usize].centre;
            if view.map_to_world.transform(centre).distance(truth) <= MATCH_M {
                (c.as_str(), c.as_str())
            } else {
                ("none", "off-centre")
            }
        }
        TruthLabel::Clutter(_) => ("none", "clutter"),
        TruthLabel::Wall => ("none", "wall"),
        TruthLabel::Nothing => ("none", "nothing"),
    }
}

/// The training rows of one view: every candidate, labelled by the majority of its points.
pub fn rows_of(view: &SceneView<'_>) -> Vec<Row> {
    let m = view.method;
    (0..m.candidates().len())
        .map(|k| {
            let pts: Vec<Point2> = m.candidate_points(k).copied().collect();
            let l = label_points(view.world, &view.map_to_world, pts.iter(), 0.1);
            let bbox = m.candidates()[k].bbox;
            let (label, truth) = truth_name(l, view, &bbox);
            let angle = bbox.angle;
            Row {
                scene: view.scene,
                frame: view.frame,
                label,
                truth,
                object: features::features(&[&pts], angle),
                axis: features::features(&[&pts], 0.0),
            }
        })
        .collect()
}

/// Everything the evaluation counts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Score {
    /// Views scored.
    pub views: usize,
    /// Confusion counts `[truth row][prediction column]`.
    pub confusion: [[u32; 4]; 5],
    /// Observable furniture per class.
    pub observable: [u32; 3],
    /// Furniture present per class (observable or not).
    pub present: [u32; 3],
    /// Clutter items by kind (`CLUTTER_KINDS`) and what they were labelled as (chair, box,
    /// desk, not reported).
    pub clutter: [[u32; 4]; CLUTTER_KINDS.len()],
    /// Views with an observable door: (correct, total).
    pub door_views: (u32, u32),
    /// Views without one: (correct, total).
    pub no_door_views: (u32, u32),
    /// Doors found / observable / reported.
    pub doors: (u32, u32, u32),
    /// Candidates fusing two or more true objects.
    pub fused: u32,
    /// Candidates in all.
    pub candidates: u32,
    /// Furniture split into two or more candidates (views × objects).
    pub split: u32,
}

/// Index of a furniture class in the evaluators' per-class arrays (chair, box, desk).
pub(crate) fn class_index(c: ObjectClass) -> Option<usize> {
    match c {
        ObjectClass::Chair => Some(0),
        ObjectClass::Box => Some(1),
        ObjectClass::Desk => Some(2),
        ObjectClass::DoorFrame => None,
    }
}

/// Clutter kinds of the simulator: the study's three, then a varied world's.
const CLUTTER_KINDS: [&str; 6] = [
    "bin",
    "pillar",
    "legs",
    "shelf",
    "radiator",
    "square pillar",
];

impl Score {
    /// Scores one view.
    pub fn add(&mut self, v: &SceneView<'_>, dbscan_min: u16) {
        self.views += 1;
        let m = v.method;
        let world = v.world;
        // True items: furniture then clutter, with world centres.
        let mut items: Vec<(Option<usize>, Point2, bool)> = Vec::new();
        for o in &world.objects {
            let k = class_index(o.class);
            let obs = points_on(
                &o.footprint,
                &v.map_to_world,
                m.cloud().iter().copied(),
                0.05,
            ) >= usize::from(dbscan_min);
            if let Some(k) = k {
                self.present[k] += 1;
                if obs {
                    self.observable[k] += 1;
                }
            }
            items.push((k, o.centre, obs));
        }
        let n_furniture = items.len();
        for c in &world.clutter {
            items.push((None, c.centre, true));
        }
        // Detections with world centres, matched closest first.
        let dets: Vec<(usize, Point2)> = m
            .objects()
            .filter_map(|(c, cand)| {
                class_index(c).map(|k| (k, v.map_to_world.transform(cand.centre)))
            })
            .collect();
        let mut pairs: Vec<(f32, usize, usize)> = Vec::new();
        for (d, (_, p)) in dets.iter().enumerate() {
            for (t, (_, c, _)) in items.iter().enumerate() {
                let dist = p.distance(*c);
                if dist <= MATCH_M {
                    pairs.push((dist, d, t));
                }
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut det_of_item = vec![None; items.len()];
        let mut det_used = vec![false; dets.len()];
        for (_, d, t) in pairs {
            if det_used[d] || det_of_item[t].is_some() {
                continue;
            }
            det_used[d] = true;
            det_of_item[t] = Some(dets[d].0);
        }
        for (t, item) in items.iter().enumerate() {
            let col = det_of_item[t].unwrap_or(3);
            if t < n_furniture {
                if let Some(k) = item.0 {
                    // Unmatched and unobservable furniture is not a miss.
                    if det_of_item[t].is_some() || item.2 {
                        self.confusion[k][col] += 1;
                    }
                }
            } else {
                let c = &world.clutter[t - n_furniture];
                let kind = CLUTTER_KINDS.iter().position(|k| *k == c.kind).unwrap_or(0);
                self.clutter[kind][col] += 1;
                if col < 3 {
                    self.confusion[3][col] += 1;
                }
            }
        }
        for (d, used) in det_used.iter().enumerate() {
            if !used {
                self.confusion[4][dets[d].0] += 1;
            }
        }

        // Fusions and splits, from the candidates' points.
        let mut owners_per_object = vec![0u32; world.objects.len()];
        for k in 0..m.candidates().len() {
            self.candidates += 1;
            let mut votes: Vec<(u16, u32)> = Vec::new();
            let mut total = 0u32;
            for p in m.candidate_points(k) {
                total += 1;
                let w = v.map_to_world.transform(*p);
                for prim in &world.prims {
                    if let sim::world::Surface::Object(n) = prim.surface
                        && prim.shape.distance(w) <= 0.05
                    {
                        match votes.iter_mut().find(|x| x.0 == n) {
                            Some(x) => x.1 += 1,
                            None => votes.push((n, 1)),
                        }
                        break;
                    }
                }
            }
            let big: Vec<u16> = votes
                .iter()
                .filter(|x| x.1 * 5 >= total)
                .map(|x| x.0)
                .collect();
            if big.len() >= 2 {
                self.fused += 1;
            }
            for n in big {
                owners_per_object[n as usize] += 1;
            }
        }
        self.split += owners_per_object.iter().filter(|&&c| c >= 2).count() as u32;

        // Doors.
        let cloud: Vec<Point2> = m.cloud().iter().copied().collect();
        let mut observable = Vec::new();
        for d in &world.doors {
            let c = v.map_to_world.inverse().transform(d.centre);
            let (s, co) = (d.wall_angle.sin(), d.wall_angle.cos());
            let half = d.width / 2.0 + 0.02;
            let jambs = [
                Point2::new(d.centre.x - co * half, d.centre.y - s * half),
                Point2::new(d.centre.x + co * half, d.centre.y + s * half),
            ]
            .map(|j| v.map_to_world.inverse().transform(j));
            let near = |j: Point2| cloud.iter().filter(|p| p.distance(j) <= 0.3).count();
            let in_range = c.distance(v.sensor) <= 3.5;
            observable.push((c, in_range && jambs.iter().all(|&j| near(j) >= 10)));
        }
        let found: Vec<Point2> = m.doors().iter().map(|d| d.centre).collect();
        let mut matched_truth = vec![false; observable.len()];
        let mut false_doors = 0;
        for f in &found {
            match observable
                .iter()
                .enumerate()
                .filter(|(_, (c, _))| c.distance(*f) <= MATCH_M)
                .min_by(|a, b| a.1.0.distance(*f).total_cmp(&b.1.0.distance(*f)))
            {
                Some((i, _)) => matched_truth[i] = true,
                None => false_doors += 1,
            }
        }
        let n_obs = observable.iter().filter(|o| o.1).count() as u32;
        let found_obs = observable
            .iter()
            .zip(&matched_truth)
            .filter(|(o, m)| o.1 && **m)
            .count() as u32;
        self.doors.0 += found_obs;
        self.doors.1 += n_obs;
        self.doors.2 += found.len() as u32;
        let correct = u32::from(found_obs == n_obs && false_doors == 0);
        if n_obs > 0 {
            self.door_views.0 += correct;
            self.door_views.1 += 1;
        } else {
            self.no_door_views.0 += correct;
            self.no_door_views.1 += 1;
        }
    }

    /// Per class (chair, box, desk): precision, recall, F1.
    pub fn prf(&self) -> [(f64, f64, f64); 3] {
        core::array::from_fn(|k| {
            let tp = f64::from(self.confusion[k][k]);
            let predicted: f64 = (0..5).map(|r| f64::from(self.confusion[r][k])).sum();
            let actual: f64 = (0..4).map(|c| f64::from(self.confusion[k][c])).sum();
            let p = if predicted > 0.0 { tp / predicted } else { 0.0 };
            let r = if actual > 0.0 { tp / actual } else { 0.0 };
            let f = if p + r > 0.0 {
                2.0 * p * r / (p + r)
            } else {
                0.0
            };
            (p, r, f)
        })
    }

    /// Classification accuracy of detected furniture: right class / furniture detections.
    pub fn object_accuracy(&self) -> (u32, u32) {
        let right = (0..3).map(|k| self.confusion[k][k]).sum();
        let all = (0..3)
            .flat_map(|k| (0..3).map(move |c| (k, c)))
            .map(|(k, c)| self.confusion[k][c])
            .sum();
        (right, all)
    }

    /// Door-frame accuracy over views: correct / views.
    pub fn door_accuracy(&self) -> (u32, u32) {
        (
            self.door_views.0 + self.no_door_views.0,
            self.door_views.1 + self.no_door_views.1,
        )
    }

    /// A Markdown report.
    pub fn markdown(&self) -> String {
        let mut s = String::new();
        let pct = |a: u32, b: u32| {
            if b == 0 {
                0.0
            } else {
                100.0 * f64::from(a) / f64::from(b)
            }
        };
        let _ = writeln!(
            s,
            "| class | precision | recall | F1 | observable | present |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|");
        for (k, (p, r, f)) in self.prf().iter().enumerate() {
            let _ = writeln!(
                s,
                "| {} | {:.4} | {:.4} | {:.4} | {} | {} |",
                TRUTH_ROWS[k], p, r, f, self.observable[k], self.present[k]
            );
        }
        let (a, b) = self.object_accuracy();
        let _ = writeln!(
            s,
            "\nObject accuracy (right class among detected furniture): {a}/{b} = {:.2} %",
            pct(a, b)
        );
        let _ = writeln!(s, "\nConfusion (rows truth, columns prediction):\n");
        let _ = writeln!(s, "| truth \\ predicted | {} |", PRED_COLS.join(" | "));
        let _ = writeln!(s, "|---|---|---|---|---|");
        for (r, row) in self.confusion.iter().enumerate() {
            let cells: Vec<String> = row.iter().map(|c| c.to_string()).collect();
            let _ = writeln!(s, "| {} | {} |", TRUTH_ROWS[r], cells.join(" | "));
        }
        let _ = writeln!(
            s,
            "\nClutter labelled as (chair, box, desk, not reported):\n"
        );
        for (k, row) in self.clutter.iter().enumerate() {
            let _ = writeln!(s, "- {}: {:?}", CLUTTER_KINDS[k], row);
        }
        let (da, db) = self.door_accuracy();
        let _ = writeln!(
            s,
            "\nDoor frames: accuracy {da}/{db} = {:.2} % of views (with a door {}/{}, without {}/{}); doors found {}/{} observable, {} reported",
            pct(da, db),
            self.door_views.0,
            self.door_views.1,
            self.no_door_views.0,
            self.no_door_views.1,
            self.doors.0,
            self.doors.1,
            self.doors.2
        );
        let _ = writeln!(
            s,
            "\nMerge: {} of {} candidates fuse distinct objects; {} object-views split into several candidates",
            self.fused, self.candidates, self.split
        );
        s
    }
}

/// Method A scored with each merge guard alone, with none and with all (`eval-a
/// --merge-guards`), as a Markdown table; `score` evaluates one configuration.
pub fn merge_guard_table(acfg: &MethodAConfig, score: impl Fn(&MethodAConfig) -> Score) -> String {
    let base = acfg.merge;
    let variants = [
        ("no guard", false, false, false),
        ("legs only", true, false, false),
        ("solid only", false, true, false),
        ("extent only", false, false, true),
        ("all guards", true, true, true),
    ];
    let mut out = String::from(
        "\n| merge rule | candidates fusing distinct objects | split object-views | object accuracy | F1 chair / box / desk |\n|---|---|---|---|---|\n",
    );
    for (name, l, s, e) in variants {
        let a = MethodAConfig {
            merge: perception::merge::MergeConfig {
                guard_legs: l,
                guard_solid: s,
                guard_extent: e,
                ..base
            },
            ..*acfg
        };
        let sc = score(&a);
        let (r, n) = sc.object_accuracy();
        let f1: Vec<String> = sc.prf().iter().map(|x| format!("{:.4}", x.2)).collect();
        let _ = writeln!(
            out,
            "| {name} | {} of {} | {} | {:.2} % | {} |",
            sc.fused,
            sc.candidates,
            sc.split,
            100.0 * f64::from(r) / f64::from(n.max(1)),
            f1.join(" / ")
        );
    }
    out
}

/// Runs `scenes` scenes and scores every view.
pub fn evaluate(
    scenes: impl IntoIterator<Item = usize>,
    cfg: &SceneConfig,
    acfg: &MethodAConfig,
    classifier: &impl Classifier,
    mut progress: impl FnMut(),
) -> Score {
    let mut method = Box::new(MethodA::new());
    let mut score = Score::default();
    for i in scenes {
        run_scene(i, cfg, acfg, &mut method, classifier, |v| {
            score.add(v, acfg.dbscan.min_cluster_points)
        });
        progress();
    }
    score
}
