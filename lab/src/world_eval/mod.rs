//! `umbra-lab eval-world`: the world as `umbra` reports it, scored against the truth of
//! runs it has never seen, in its scene families: umbra's simulator on held-out seeds (its
//! own rooms, its varied worlds, those seen by a worn LiDAR), and the annex
//! ([`crate::annex`]), written apart and never trained or tuned on.
//!
//! Each run is written as a user would hand it over (LiDAR bytes, wheel ticks) and replayed
//! through the `umbra` binary itself (`umbra replay CAPTURE --odom TICKS --jsonl -`), with the
//! world model on or off; the output lines are scored by [`score`].

mod assignment;
pub mod compare;
pub mod confusion;
mod describe;
pub mod fates;
mod line;
pub mod picture;
mod places;
pub mod reliability;
pub mod score;
pub mod sim_family;
mod unrefuted;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::annex::{self, GeneratedRun};
pub use describe::{describe, describe_people};
use reliability::{RELIABILITY_LEN, SCORE_BINS};
use score::{CLASSES, Line, Tally, ratio, score_run};

/// A scene family.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// umbra's simulator, held-out seeds.
    Sim,
    /// umbra's simulator drawing only varied worlds (`WorldConfig::varied`), held-out seeds:
    /// the kind of world Method B has been trained on since 2026-11-30, not the study's.
    Varied,
    /// The varied worlds seen by a worn LiDAR (`sim::wear`: returns fading with range, mixed
    /// pixels at depth edges), held-out seeds: real scanners' effects in our own simulator.
    Worn,
    /// The annex: never trained or tuned on.
    Annex,
}

impl Family {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Family::Sim => "sim (held-out seeds)",
            Family::Varied => "sim, varied worlds (held-out seeds)",
            Family::Worn => "sim, varied worlds, worn LiDAR (held-out seeds)",
            Family::Annex => "annex (never tuned on)",
        }
    }
}

/// What to evaluate.
#[derive(Debug, Clone)]
pub struct EvalConfig {
    /// Families.
    pub families: Vec<Family>,
    /// Runs per family.
    pub runs: usize,
    /// Seconds per run.
    pub seconds: f64,
    /// Evaluation seed (never a training seed).
    pub seed: u64,
    /// World model settings to compare: `false` = off (objects are the frame's detections).
    pub world: Vec<bool>,
    /// The `umbra` binary.
    pub umbra: PathBuf,
    /// Where runs are written (and kept).
    pub dir: PathBuf,
    /// Extra `[world]` lines for the world-on replays (`key = value`), for ablations.
    pub world_set: Vec<String>,
    /// Have the world-on replays write their track logs (`tracks.txt`, `umbra --track-log`)
    /// and the scorer's phantom labels of what they reported (`labels.txt`).
    pub track_logs: bool,
}

/// One family × world setting's result.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Outcome {
    /// Family name.
    pub family: &'static str,
    /// World model on.
    pub world: bool,
    /// Summed counts.
    pub tally: Tally,
    /// Per run: name and its own tally.
    pub runs: Vec<(String, Tally)>,
}

/// Generates run `i` of `family`.
pub fn generate(family: Family, seed: u64, i: usize, seconds: f64) -> GeneratedRun {
    match family {
        Family::Sim => sim_family::generate(seed, i, seconds, 0.0, 0.0),
        Family::Varied => sim_family::generate(seed, i, seconds, 1.0, 0.0),
        Family::Worn => sim_family::generate(seed, i, seconds, 1.0, 1.0),
        Family::Annex => {
            let lidar = if i % 4 >= 2 {
                drivers::lidar::LidarModel::Lds02
            } else {
                drivers::lidar::LidarModel::Lds01
            };
            annex::generate(
                sim::dataset::scenario_seed(seed ^ 0xA11E, i),
                seconds,
                i % 2 == 1,
                lidar,
            )
        }
    }
}

/// The longest deadline `umbra` accepts (`firmware::config::MAX_DEADLINE_MS`; the lab runs
/// the binary and does not link it): under it no replayed frame is degraded for time.
const MAX_DEADLINE_MS: u32 = 10_000;

/// Writes `run` to `dir` and replays it through `umbra` with the world model `world`;
/// `track_log`: with the world model on, `umbra` writes its track log to `dir/tracks.txt`.
pub fn replay(
    umbra: &Path,
    dir: &Path,
    run: &GeneratedRun,
    world: bool,
    world_set: &[String],
    track_log: bool,
) -> Result<Vec<Line>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).map_err(|e| format!("{}: {e}", p.display()))?;
        Ok::<_, String>(p)
    };
    let capture = write("capture.bin", &run.capture)?;
    let odom = write("odom.jsonl", run.odom.as_bytes())?;
    let config = write(
        if world { "world-on.toml" } else { "world-off.toml" },
        format!(
            "# eval-world: no frame is skipped for time on a loaded host\n[runtime]\ndeadline_ms = {MAX_DEADLINE_MS}\n[world]\nenabled = {world}\n{}",
            if world {
                world_set.iter().map(|l| format!("{l}\n")).collect::<String>()
            } else {
                String::new()
            }
        )
        .as_bytes(),
    )?;
    let mut cmd = Command::new(umbra);
    cmd.arg("replay")
        .arg(&capture)
        .arg("--odom")
        .arg(&odom)
        .arg("--lidar-model")
        .arg(run.lidar.cli_name())
        .args(["--jsonl", "-", "--quiet", "--config"])
        .arg(&config);
    if world && track_log {
        cmd.arg("--track-log").arg(dir.join("tracks.txt"));
    }
    let out = cmd
        .output()
        .map_err(|e| format!("{}: {e}", umbra.display()))?;
    if !out.status.success() {
        return Err(format!(
            "umbra replay failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let lines: Vec<Line> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(Line::parse)
        .collect();
    std::fs::write(
        dir.join(if world {
            "out-world-on.jsonl"
        } else {
            "out-world-off.jsonl"
        }),
        &out.stdout,
    )
    .map_err(|e| e.to_string())?;
    Ok(lines)
}

/// Runs the whole evaluation; `progress` hears each finished run.
pub fn evaluate(cfg: &EvalConfig, mut progress: impl FnMut(&str)) -> Result<Vec<Outcome>, String> {
    let mut out = Vec::new();
    for &family in &cfg.families {
        let mut per: Vec<Outcome> = cfg
            .world
            .iter()
            .map(|&world| Outcome {
                family: family.name(),
                world,
                tally: Tally::default(),
                runs: Vec::new(),
            })
            .collect();
        for i in 0..cfg.runs {
            let run = generate(family, cfg.seed, i, cfg.seconds);
            let tag = match family {
                Family::Sim => "sim",
                Family::Varied => "varied",
                Family::Worn => "worn",
                Family::Annex => "annex",
            };
            let dir = cfg.dir.join(format!("{tag}-{i:03}"));
            std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
            std::fs::write(dir.join("truth.txt"), describe(&run.truth))
                .map_err(|e| e.to_string())?;
            let people = describe_people(&run.truth);
            if !people.is_empty() {
                std::fs::write(dir.join("people.txt"), people).map_err(|e| e.to_string())?;
            }
            for o in &mut per {
                let lines = replay(
                    &cfg.umbra,
                    &dir,
                    &run,
                    o.world,
                    &cfg.world_set,
                    cfg.track_logs,
                )?;
                let on = if o.world { "on" } else { "off" };
                picture::write(
                    &dir.join(format!("map-world-{on}.png")),
                    &format!("{} - world model {on}", run.truth.name),
                    &run.truth,
                    &lines,
                )
                .map_err(|e| e.to_string())?;
                let mut t = Tally::default();
                score_run(&run.truth, &lines, &mut t);
                if o.world && cfg.track_logs {
                    write_labels(&dir.join("labels.txt"), &t.object_labels)?;
                }
                o.tally.add(&t);
                o.runs.push((run.truth.name.clone(), t));
            }
            progress(&run.truth.name);
        }
        out.extend(per);
    }
    Ok(out)
}

/// `labels.txt` beside a run's track log: each reported piece of furniture's frame, id and
/// whether the scorer counted it a phantom (1) or not (0), for `training/fit_report_model.py`.
fn write_labels(path: &Path, labels: &[(u64, u64, bool)]) -> Result<(), String> {
    let mut s = String::from("# frame id phantom\n");
    for (frame, id, phantom) in labels {
        let _ = writeln!(s, "{frame} {id} {}", u8::from(*phantom));
    }
    std::fs::write(path, s).map_err(|e| format!("{}: {e}", path.display()))
}

/// Counts by `score::PHANTOM_PLACES`, named; per frame when `frames` is given.
fn places_of(counts: &[u32; 5], frames: Option<f64>) -> String {
    let named: Vec<String> = score::PHANTOM_PLACES
        .iter()
        .zip(counts)
        .map(|(name, &n)| match frames {
            Some(f) => format!("{name} {:.3}", f64::from(n) / f),
            None => format!("{name} {n}"),
        })
        .collect();
    named.join(", ")
}

fn pct(x: f64) -> String {
    if x.is_nan() {
        "  –  ".into()
    } else {
        format!("{x:.3}")
    }
}

/// The report: one block per family and world setting.
pub fn report(outcomes: &[Outcome]) -> String {
    let mut s = String::new();
    for o in outcomes {
        let t = &o.tally;
        let f = f64::from(t.frames.max(1));
        let _ = writeln!(
            s,
            "\n{} — world model {} — {} runs, {} frames",
            o.family,
            if o.world { "ON" } else { "off" },
            t.runs,
            t.frames
        );
        let _ = writeln!(s, "  final map      precision  recall   (found/visible)");
        for (c, name) in CLASSES.iter().enumerate() {
            let _ = writeln!(
                s,
                "    {name:6}         {}      {}    ({}/{}, {} reported)",
                pct(ratio(t.map_tp[c], t.map_reported[c])),
                pct(ratio(t.map_tp[c], t.map_visible[c])),
                t.map_tp[c],
                t.map_visible[c],
                t.map_reported[c]
            );
        }
        for (k, fate) in fates::FATES.iter().enumerate().skip(1) {
            let n = t.fates.map(|c| c[k]);
            let _ = writeln!(
                s,
                "    missed: {fate:40} chair {:3}  box {:3}  desk {:3}",
                n[0], n[1], n[2]
            );
        }
        let _ = writeln!(
            s,
            "    against a wall recall {} ({}/{}), in the open {} ({}/{})",
            pct(ratio(t.wall_found[0], t.wall_found[1])),
            t.wall_found[0],
            t.wall_found[1],
            pct(ratio(t.open_found[0], t.open_found[1])),
            t.open_found[0],
            t.open_found[1]
        );
        let _ = writeln!(
            s,
            "  doors (`doors`) precision {} recall {} ({}/{}, {} reported); as door_frame objects {}/{}",
            pct(ratio(t.doors[0], t.doors[1])),
            pct(ratio(t.doors[0], t.doors[2])),
            t.doors[0],
            t.doors[2],
            t.doors[1],
            t.door_frames_found,
            t.doors[2]
        );
        let ph = |p: &[u32; 3], fr: f64| {
            format!(
                "{:.3} (A {:.3}, B {:.3}, AB {:.3})",
                f64::from(p.iter().sum::<u32>()) / fr,
                f64::from(p[0]) / fr,
                f64::from(p[1]) / fr,
                f64::from(p[2]) / fr
            )
        };
        let _ = writeln!(
            s,
            "  phantoms/frame among objects {}; wrong class/frame {:.3}",
            ph(&t.phantoms, f),
            f64::from(t.wrong_class) / f
        );
        let _ = writeln!(
            s,
            "    phantom objects (distinct ids, each counted once) {:.2}/run",
            f64::from(t.phantom_objects) / f64::from(t.runs.max(1))
        );
        let _ = writeln!(
            s,
            "    of them within 0.15 m of a wall face {:.3}/frame; by class chair {:.3}, box {:.3}, desk {:.3}, door frame {:.3}",
            f64::from(t.phantoms_at_wall) / f,
            f64::from(t.phantoms_by_class[0]) / f,
            f64::from(t.phantoms_by_class[1]) / f,
            f64::from(t.phantoms_by_class[2]) / f,
            f64::from(t.phantoms_by_class[3]) / f
        );
        let _ = writeln!(
            s,
            "    where they lie: {}",
            places_of(&t.phantoms_where, Some(f))
        );
        if t.det_frames > 0 {
            let _ = writeln!(
                s,
                "  phantoms/frame among detections {}",
                ph(&t.det_phantoms, f64::from(t.det_frames))
            );
            reliability_lines(&mut s, &t.reliability);
            confusion::lines(&mut s, &t.confusion);
        }
        let _ = writeln!(
            s,
            "  identity: IDF1 {} ({} true of {} truth / {} reported), ID switches {}",
            pct(t.idf1()),
            t.idtp,
            t.id_gt,
            t.id_hyp,
            t.id_switches
        );
        let within2 = t.move_gone_s.iter().filter(|&&x| x <= 2.0).count();
        let _ = writeln!(
            s,
            "  moved pieces: {} seen empty; gone within 2 s {}, later {}, still on the map {}, never seen empty {}; reports at an old place not yet seen empty (no phantom) {:.3}/frame, {} in final maps",
            t.move_gone_s.len() + t.move_stuck as usize,
            within2,
            t.move_gone_s.len() - within2,
            t.move_stuck,
            t.move_unseen,
            f64::from(t.unrefuted) / f,
            t.map_unrefuted
        );
        let _ = writeln!(
            s,
            "  walking people: {} reports as furniture over {} frames with a person{}",
            t.people_as_furniture,
            t.people_frames,
            if t.people_found[0] > 0 || t.people_phantoms > 0 {
                format!(
                    "; `people` found {}/{} ({}/{} in view), {} people where nobody walks",
                    t.people_found[1],
                    t.people_found[0],
                    t.people_in_view_found[1],
                    t.people_in_view_found[0],
                    t.people_phantoms
                )
            } else {
                String::new()
            }
        );
        if t.people_found[0] > 0 || t.people_phantoms > 0 {
            let r = &t.people_in_view_by_range;
            let _ = writeln!(
                s,
                "    in view by range: under 1.5 m {}/{}, 1.5–2.5 m {}/{}, farther {}/{}; made up where: {}",
                r[0][1],
                r[0][0],
                r[1][1],
                r[1][0],
                r[2][1],
                r[2][0],
                places_of(&t.people_phantoms_where, None)
            );
        }
        if t.pose_frames > 0 {
            let e = &t.final_position_err_m;
            let _ = writeln!(
                s,
                "  pose against the truth: heading error mean {:.2}° (largest {:.1}°); position at a run's end mean {:.2} m (largest {:.2} m)",
                t.heading_err_sum_deg / f64::from(t.pose_frames),
                t.heading_err_max_deg,
                e.iter().sum::<f64>() / e.len().max(1) as f64,
                e.iter().copied().fold(0.0, f64::max)
            );
        }
        for (name, t) in o.runs.iter().filter(|(_, t)| !t.people_reports.is_empty()) {
            let _ = writeln!(
                s,
                "    on people in {name}: {}",
                t.people_reports.join("; ")
            );
        }
    }
    s
}

/// The detections' reliability: for each source and class with any, the share of each tenth
/// of the score that stood on a piece of its class (`true/n`), and the mean score against
/// that share over all of them (a calibrated score has the two equal).
fn reliability_lines(s: &mut String, rel: &[u32]) {
    if rel.len() < RELIABILITY_LEN {
        return;
    }
    let _ = writeln!(
        s,
        "  detections' scores against how often they came true (score tenth: true/n):"
    );
    for (src, name) in ["A", "B", "AB"].iter().enumerate() {
        for (c, class) in ["chair", "box", "desk", "door frame"].iter().enumerate() {
            let at = |bin: usize| perception::calibration::count_index(src, c, bin);
            let (n, ok): (u32, u32) =
                (0..SCORE_BINS).fold((0, 0), |(n, ok), b| (n + rel[at(b)], ok + rel[at(b) + 1]));
            if n == 0 {
                continue;
            }
            let bins: Vec<String> = (0..SCORE_BINS)
                .filter(|&b| rel[at(b)] > 0)
                .map(|b| format!("{:.1}: {}/{}", b as f64 / 10.0, rel[at(b) + 1], rel[at(b)]))
                .collect();
            let _ = writeln!(
                s,
                "    {name} {class}: {} true of {n}; {}",
                pct(ratio(ok, n)),
                bins.join(", ")
            );
        }
    }
}

/// The Rust source of `models/src/calibration_counts.rs` from `eval-world --json` files: the
/// sum of every family's detection reliability counts ([`Tally::reliability`]).
pub fn calibration_counts(files: &[PathBuf], made_by: &str) -> Result<String, String> {
    let mut sum = vec![0u32; RELIABILITY_LEN];
    let mut names = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
        let v: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| format!("{}: {e}", f.display()))?;
        let families = v
            .as_array()
            .ok_or_else(|| format!("{}: not an eval-world --json file", f.display()))?;
        for fam in families {
            let rel: Vec<u32> = fam
                .get("tally")
                .and_then(|t| t.get("reliability"))
                .and_then(|r| serde_json::from_value(r.clone()).ok())
                .unwrap_or_default();
            if rel.len() == sum.len() {
                for (a, b) in sum.iter_mut().zip(&rel) {
                    *a += b;
                }
            }
        }
        names.push(
            f.file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        );
    }
    if sum.iter().all(|&n| n == 0) {
        return Err(
            "no detection counts in those files (eval-world with the world model on writes them)"
                .into(),
        );
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        "//! Detection counts the score calibration is fitted from. Generated; do not edit."
    );
    let _ = writeln!(s, "//!");
    let _ = writeln!(
        s,
        "//! `umbra-lab calibrate {}` after `{}`.",
        names.join(" "),
        if made_by.is_empty() {
            "eval-world --json"
        } else {
            made_by
        }
    );
    let _ = writeln!(
        s,
        "//! Per source (A, B, AB), class (chair, box, desk, door frame) and tenth of the score:"
    );
    let _ = writeln!(s, "//! `[detections, on a piece of their class]`.");
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "/// The counts, laid out as `perception::calibration::COUNTS_LEN` says."
    );
    let _ = writeln!(s, "pub const COUNTS: [u32; {}] = [", sum.len());
    for row in sum.chunks(SCORE_BINS * 2) {
        let cells: Vec<String> = row.iter().map(u32::to_string).collect();
        let _ = writeln!(s, "    {},", cells.join(", "));
    }
    let _ = writeln!(s, "];");
    Ok(s)
}
