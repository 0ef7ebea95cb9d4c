//! Datasets from many scenarios, in parallel (rayon), reproducibly (one seed; each scenario's
//! output depends only on the seed and its index, never on thread timing).
//!
//! Layout under the output folder:
//!
//! ```text
//! data.yaml                      Ultralytics dataset file (paths, 4 class names)
//! dataset.json                   manifest: settings, splits, counts per class, timing
//! images/{train,val,test}/sNNNN_fFFFF.png   Method B rasters (384×64 RGB, perception::raster)
//! labels/{train,val,test}/sNNNN_fFFFF.txt   YOLO boxes (sim::labels)
//! method_a/sNNNN.jsonl           line 1: the scene; then per frame: pose, ranges, hit codes
//! recordings/sNNNN/capture.bin   raw LDS-01 bytes (docs/interfaces.md §2)
//! recordings/sNNNN/odom.jsonl    encoder ticks + magnetometer on the capture's clock
//! recordings/sNNNN/truth.jsonl   per frame: pose and objects in the map frame
//! pictures/sNNNN.png             a picture of the scene (first few scenarios)
//! ```
//!
//! Splits are by whole scenario (85 / 10 / 5 %), never by frame. Scenarios alternate between
//! the study's oscillation in place (even indices) and waypoint tours (odd).
//!
//! The map frame of `truth.jsonl` is the robot's pose at the start (as in the output line of
//! `docs/interfaces.md` §3); `method_a` poses are in the map frame too.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use perception::class::ObjectClass;
use perception::geometry::{Point2, Pose2};
use perception::raster::{RASTER_H, RASTER_LEN, RASTER_W, RasterConfig, encode_hwc};
use perception::seam::{Rolled, SeamRule};
use rayon::prelude::*;
use serde_json::{Value, json};

use crate::labels::{PixelBox, hit_code, yolo_boxes};
use crate::robot::{Motion, RobotConfig};
use crate::scenario::{Frame, OdomSample, Scenario, ScenarioConfig};
use crate::world::WorldConfig;

/// Dataset settings.
#[derive(Debug, Clone)]
pub struct DatasetConfig {
    /// Scenarios (each a world, a robot, a motion).
    pub scenarios: usize,
    /// Labelled frames per scenario (two more revolutions are simulated first to fill the
    /// raster's history).
    pub frames: usize,
    /// Master seed.
    pub seed: u64,
    /// Worlds.
    pub world: WorldConfig,
    /// Raster settings.
    pub raster: RasterConfig,
    /// Write Method B images and labels.
    pub method_b: bool,
    /// Write Method A per-reading labels.
    pub method_a: bool,
    /// Write replay recordings.
    pub recordings: bool,
    /// Pictures of the first N scenarios.
    pub pictures: usize,
    /// Put every scenario in the test split (a second test set, e.g. of room kinds a model
    /// was not trained on).
    pub test_only: bool,
    /// People walking through each scenario: 0 to this many (`crate::people`), never labelled.
    pub people: usize,
    /// Where each image starts (`perception::seam`); its labels follow.
    pub seam: SeamRule,
    /// Labels drawn as the sweep read each footprint (`sim::labels::swept_box`), not from the
    /// pose at the middle of the revolution.
    pub deskew: bool,
    /// Share of scenarios whose LiDAR is a worn unit (`sim::wear`: returns fading with range,
    /// mixed pixels at depth edges); 0 leaves every scenario as it was.
    pub worn: f64,
    /// Share of scenarios whose LiDAR returns by the light it receives (`sim::power`); 0
    /// leaves every scenario as it was.
    pub power: f64,
}

impl Default for DatasetConfig {
    fn default() -> Self {
        DatasetConfig {
            scenarios: 50,
            frames: 200,
            seed: 1,
            world: WorldConfig::default(),
            raster: RasterConfig::default(),
            method_b: true,
            method_a: true,
            recordings: true,
            pictures: 3,
            test_only: false,
            people: 0,
            seam: SeamRule::Fixed,
            deskew: false,
            worn: 0.0,
            power: 0.0,
        }
    }
}

pub use crate::split::{Split, scenario_seed, splits};

/// The scenario settings of index `i`: `world`'s rooms, even indices turning in place and odd
/// ones touring, a share `worn` of the units worn (`ScenarioConfig::worn`; 0 = every unit fresh).
pub fn scenario_config(i: usize, world: &WorldConfig, worn: f64) -> ScenarioConfig {
    let motion = if i.is_multiple_of(2) {
        RobotConfig::default().motion
    } else {
        Motion::Tour { speed_m_s: 0.15 }
    };
    ScenarioConfig {
        world: world.clone(),
        robot: RobotConfig {
            motion,
            ..RobotConfig::default()
        },
        worn,
        ..ScenarioConfig::standard()
    }
}

/// One labelled sample as the simulator hands it out.
pub struct Sample<'a> {
    /// Index of the labelled frame within its scenario (0-based).
    pub index: usize,
    /// The raster of revolutions t, t−1, t−2.
    pub raster: &'a [u8],
    /// Its boxes.
    pub boxes: &'a [PixelBox],
    /// Revolution t with its truth.
    pub frame: &'a Frame,
}

/// Simulates scenario `i`: every revolution (warm-up included) goes to `on_frame` with the
/// odometry samples that fell in it; every labelled one to `on_sample`.
pub fn simulate(
    i: usize,
    cfg: &DatasetConfig,
    mut on_frame: impl FnMut(&Scenario, &Frame, &[OdomSample]),
    mut on_sample: impl FnMut(&Scenario, Sample<'_>),
) -> Scenario {
    let sc = ScenarioConfig {
        power: cfg.power,
        ..scenario_config(i, &cfg.world, cfg.worn)
    };
    let mut scenario = Scenario::new(scenario_seed(cfg.seed, i), &sc);
    if cfg.people > 0 {
        scenario.add_people(scenario_seed(cfg.seed, i), cfg.people);
    }
    let mut ring: [Box<Frame>; 3] = Default::default();
    let mut ranges = [[0.0f32; 360]; 3];
    let mut raster = vec![0u8; RASTER_LEN];
    let mut boxes = Vec::new();
    let mut odom = Vec::new();
    for n in 0..cfg.frames + 2 {
        let slot = n % 3;
        odom.clear();
        scenario.next_frame(&mut ring[slot], &mut odom);
        ranges[slot] = ring[slot].ranges_m();
        on_frame(&scenario, &ring[slot], &odom);
        if n < 2 {
            continue;
        }
        let (t, t1, t2) = (slot, (slot + 2) % 3, (slot + 1) % 3);
        // The raster cannot fail: the buffer has the right length and the config is checked
        // by the caller (`generate`); an error here would only skip the sample.
        let seam = cfg
            .seam
            .seam([&ranges[t], &ranges[t1], &ranges[t2]], &cfg.raster);
        let rolled = |k: usize| Rolled {
            scan: &ranges[k],
            seam,
        };
        if encode_hwc(
            &mut raster,
            [&rolled(t), &rolled(t1), &rolled(t2)],
            &cfg.raster,
        )
        .is_err()
        {
            continue;
        }
        boxes.clear();
        yolo_boxes(
            &scenario.world,
            [&ring[t], &ring[t1], &ring[t2]],
            &cfg.raster,
            seam,
            cfg.deskew,
            &mut boxes,
        );
        on_sample(
            &scenario,
            Sample {
                index: n - 2,
                raster: &raster,
                boxes: &boxes,
                frame: &ring[t],
            },
        );
    }
    scenario
}

/// What a run produced.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Labelled frames.
    pub frames: usize,
    /// Boxes per class (chair, box, desk, door_frame) per split (train, val, test).
    pub boxes: [[usize; 4]; 3],
    /// Frames per split.
    pub frames_per_split: [usize; 3],
    /// Wall time, s.
    pub seconds: f64,
    /// Share of readings with no return, in the recordings written.
    pub no_return_share: f64,
}

fn split_index(s: Split) -> usize {
    match s {
        Split::Train => 0,
        Split::Val => 1,
        Split::Test => 2,
    }
}

/// Labelled frames simulated in memory (rasters and labels built, nothing written): the speed
/// figure. Returns (frames, a digest of every raster and label line, for determinism checks).
pub fn in_memory(cfg: &DatasetConfig) -> (usize, u64) {
    let per: Vec<(usize, u64)> = (0..cfg.scenarios)
        .into_par_iter()
        .map(|i| {
            let (mut n, mut h) = (0usize, FNV_OFFSET);
            let mut line = String::new();
            simulate(
                i,
                cfg,
                |_, _, _| {},
                |_, s| {
                    n += 1;
                    h = fnv(h, s.raster);
                    for b in s.boxes {
                        line.clear();
                        line.push_str(&b.yolo_line());
                        h = fnv(h, line.as_bytes());
                    }
                },
            );
            (n, h)
        })
        .collect();
    let frames = per.iter().map(|p| p.0).sum();
    let digest = per
        .iter()
        .fold(FNV_OFFSET, |h, p| fnv(h, &p.1.to_le_bytes()));
    (frames, digest)
}

/// FNV-1a offset basis: the starting value of [`fnv`].
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// FNV-1a of `bytes`, continuing from `h` (start with [`FNV_OFFSET`]): the digest used for
/// determinism checks.
pub fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h = (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
    }
    h
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> String {
    format!("{}: {e}", path.display())
}

fn create(path: &Path) -> Result<BufWriter<fs::File>, String> {
    if let Some(dir) = path.parent() {
        fs::create_dir_all(dir).map_err(|e| io_err(dir, e))?;
    }
    fs::File::create(path)
        .map(BufWriter::new)
        .map_err(|e| io_err(path, e))
}

fn write_raster_png(path: &Path, raster: &[u8]) -> Result<(), String> {
    let w = create(path)?;
    let mut enc = png::Encoder::new(w, RASTER_W as u32, RASTER_H as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Fast);
    let mut writer = enc.write_header().map_err(|e| io_err(path, e))?;
    writer
        .write_image_data(raster)
        .map_err(|e| io_err(path, e))?;
    writer.finish().map_err(|e| io_err(path, e))
}

fn pose_json(p: &Pose2) -> Value {
    json!({"x": round4(p.x), "y": round4(p.y), "theta": round4(p.theta)})
}

fn round4(v: f32) -> f64 {
    (f64::from(v) * 1e4).round() / 1e4
}

fn pt(p: Point2) -> Value {
    json!([round4(p.x), round4(p.y)])
}

fn scene_json(i: usize, s: &Scenario, split: Split) -> Value {
    let w = &s.world;
    json!({
        "scenario": i,
        "split": split.name(),
        "kind": w.kind.name(),
        "description": w.describe(),
        "robot_start": pose_json(&s.robot_start_pose()),
        "objects": w.objects.iter().enumerate().map(|(n, o)| json!({
            "id": n, "class": o.class.as_str(), "centre": pt(o.centre), "yaw": round4(o.yaw),
            "footprint": o.footprint.iter().map(|p| pt(*p)).collect::<Vec<_>>()})).collect::<Vec<_>>(),
        "doors": w.doors.iter().enumerate().map(|(n, d)| json!({
            "id": n, "centre": pt(d.centre), "width": round4(d.width),
            "footprint": d.footprint.iter().map(|p| pt(*p)).collect::<Vec<_>>()})).collect::<Vec<_>>(),
        "clutter": w.clutter.iter().enumerate().map(|(n, c)| json!({
            "id": n, "kind": c.kind, "centre": pt(c.centre)})).collect::<Vec<_>>(),
        "hit_codes": "-1 no return, 0 wall, 1+n furniture n, 10000+n door frame n, 20000+n clutter n, 30000+n walking person n",
        "frame": "world; poses in method_a and truth.jsonl are in the map frame = robot_start",
    })
}

/// Writes a dataset; `progress` is called with the number of labelled frames just finished.
pub fn generate(
    cfg: &DatasetConfig,
    out: &Path,
    progress: impl Fn(u64) + Sync,
) -> Result<Report, String> {
    if !(cfg.raster.max_range_m.is_finite() && cfg.raster.max_range_m > 0.0) {
        return Err("raster max range must be a positive number".into());
    }
    fs::create_dir_all(out).map_err(|e| io_err(out, e))?;
    let start = Instant::now();
    let split_of = if cfg.test_only {
        vec![Split::Test; cfg.scenarios]
    } else {
        splits(cfg.scenarios, cfg.seed)
    };
    let results: Vec<Result<ScenarioResult, String>> = (0..cfg.scenarios)
        .into_par_iter()
        .map(|i| scenario_to_disk(i, split_of[i], cfg, out, &progress))
        .collect();
    let mut report = Report::default();
    let (mut zeros, mut readings) = (0u64, 0u64);
    for r in results {
        let (split, per_class, frames, (z, n)) = r?;
        let si = split_index(split);
        report.frames += frames;
        report.frames_per_split[si] += frames;
        for (total, n) in report.boxes[si].iter_mut().zip(per_class) {
            *total += n;
        }
        zeros += z;
        readings += n;
    }
    report.seconds = start.elapsed().as_secs_f64();
    report.no_return_share = if readings > 0 {
        zeros as f64 / readings as f64
    } else {
        0.0
    };
    if cfg.method_b {
        // Ultralytics resolves a relative `path` against its working directory, not the
        // yaml's folder: write the folder's absolute path.
        let root = fs::canonicalize(out).map_err(|e| io_err(out, e))?;
        let yaml = format!(
            "# umbra simulator dataset, seed {}, {} scenarios × {} frames; splits by scenario\npath: {}\ntrain: images/train\nval: images/val\ntest: images/test\nnames:\n  0: chair\n  1: box\n  2: desk\n  3: door_frame\n",
            cfg.seed,
            cfg.scenarios,
            cfg.frames,
            root.display()
        );
        let p = out.join("data.yaml");
        fs::write(&p, yaml).map_err(|e| io_err(&p, e))?;
    }
    let boxes: serde_json::Map<String, Value> = ["train", "val", "test"]
        .iter()
        .enumerate()
        .map(|(si, name)| {
            let per: serde_json::Map<String, Value> = ObjectClass::ALL
                .iter()
                .enumerate()
                .map(|(c, cl)| (cl.as_str().to_string(), json!(report.boxes[si][c])))
                .collect();
            (name.to_string(), Value::Object(per))
        })
        .collect();
    let manifest = json!({
        "seed": cfg.seed, "scenarios": cfg.scenarios, "frames_per_scenario": cfg.frames,
        "raster_max_range_m": cfg.raster.max_range_m,
        // How the images and labels were drawn (`training/export.py --data` reads them).
        "seam": cfg.seam.name(), "deskew": cfg.deskew,
        "splits": {"train": split_of.iter().filter(|s| **s == Split::Train).count(),
                   "val": split_of.iter().filter(|s| **s == Split::Val).count(),
                   "test": split_of.iter().filter(|s| **s == Split::Test).count()},
        "frames": {"train": report.frames_per_split[0], "val": report.frames_per_split[1], "test": report.frames_per_split[2]},
        "boxes": boxes,
        "no_return_share": (report.no_return_share * 1e4).round() / 1e4,
    });
    let p = out.join("dataset.json");
    fs::write(
        &p,
        serde_json::to_string_pretty(&manifest).unwrap_or_default() + "\n",
    )
    .map_err(|e| io_err(&p, e))?;
    Ok(report)
}

type ScenarioResult = (Split, [usize; 4], usize, (u64, u64));

fn scenario_to_disk(
    i: usize,
    split: Split,
    cfg: &DatasetConfig,
    out: &Path,
    progress: &(impl Fn(u64) + Sync),
) -> Result<ScenarioResult, String> {
    let name = format!("s{i:04}");
    let rec_dir: PathBuf = out.join("recordings").join(&name);
    let mut capture = None;
    let mut odom_w = None;
    let mut truth_w = None;
    let mut method_a = None;
    if cfg.recordings {
        capture = Some(create(&rec_dir.join("capture.bin"))?);
        odom_w = Some(create(&rec_dir.join("odom.jsonl"))?);
        truth_w = Some(create(&rec_dir.join("truth.jsonl"))?);
    }
    if cfg.method_a {
        method_a = Some(create(&out.join("method_a").join(format!("{name}.jsonl")))?);
    }
    let mut per_class = [0usize; 4];
    let mut frames = 0usize;
    let (mut zeros, mut readings) = (0u64, 0u64);
    let err: std::cell::RefCell<Option<String>> = std::cell::RefCell::new(None);
    let mut bytes = Vec::with_capacity(2520);
    let mut header_done = false;
    let mut path = Vec::new();
    let mut last_frame: Option<Box<Frame>> = None;
    // The first I/O error of the scenario is kept and returned; simulation carries on.
    let keep = |r: Result<(), String>| {
        if let Err(e) = r {
            err.borrow_mut().get_or_insert(e);
        }
    };
    let scenario = simulate(
        i,
        cfg,
        |s, frame, odom| {
            let map = s.robot_start_pose().inverse();
            if !header_done {
                header_done = true;
                if let Some(w) = method_a.as_mut() {
                    let line = scene_json(i, s, split).to_string() + "\n";
                    keep(w.write_all(line.as_bytes()).map_err(|e| e.to_string()));
                }
            }
            path.push(Point2::new(frame.pose_mid.x, frame.pose_mid.y));
            zeros += frame
                .readings
                .iter()
                .filter(|r| r.raw.range_mm == 0)
                .count() as u64;
            readings += 360;
            if let Some(c) = capture.as_mut() {
                bytes.clear();
                frame.emit(&mut bytes);
                keep(c.write_all(&bytes).map_err(|e| e.to_string()));
            }
            if let Some(w) = odom_w.as_mut() {
                for o in odom {
                    let line = json!({"t": (o.t * 1e6).round() / 1e6, "left_ticks": o.left_ticks,
                        "right_ticks": o.right_ticks,
                        "mag_ut": [round4(o.mag_ut[0]), round4(o.mag_ut[1]), round4(o.mag_ut[2])]});
                    keep(writeln!(w, "{line}").map_err(|e| e.to_string()));
                }
            }
            if let Some(w) = truth_w.as_mut() {
                let to_map = |p: Point2| map.transform(p);
                let line = json!({
                    "frame": frame.seq, "t": (frame.t_start_s * 1e6).round() / 1e6,
                    "pose": pose_json(&map.compose(&frame.pose_start)),
                    "pose_end": pose_json(&map.compose(&frame.pose_end)),
                    "objects": s.world.objects.iter().enumerate().map(|(n, o)| json!({
                        "id": n, "class": o.class.as_str(), "x": round4(to_map(o.centre).x), "y": round4(to_map(o.centre).y),
                        "footprint": o.footprint.iter().map(|p| pt(to_map(*p))).collect::<Vec<_>>()})).collect::<Vec<_>>(),
                    "doors": s.world.doors.iter().map(|d| json!({
                        "x": round4(to_map(d.centre).x), "y": round4(to_map(d.centre).y), "width": round4(d.width)})).collect::<Vec<_>>(),
                });
                keep(writeln!(w, "{line}").map_err(|e| e.to_string()));
            }
            if let Some(w) = method_a.as_mut() {
                let line = json!({
                    "frame": frame.seq, "t": (frame.t_start_s * 1e6).round() / 1e6,
                    "pose_start": pose_json(&map.compose(&frame.pose_start)),
                    "pose_mid": pose_json(&map.compose(&frame.pose_mid)),
                    "pose_end": pose_json(&map.compose(&frame.pose_end)),
                    "ranges_mm": frame.readings.iter().map(|r| r.raw.range_mm).collect::<Vec<_>>(),
                    "hit": (0..360).map(|d| hit_code(frame, d)).collect::<Vec<_>>(),
                });
                keep(writeln!(w, "{line}").map_err(|e| e.to_string()));
            }
        },
        |_, sample| {
            frames += 1;
            for b in sample.boxes {
                per_class[b.class as usize] += 1;
            }
            if cfg.method_b {
                let stem = format!("{name}_f{:05}", sample.index);
                let img = out
                    .join("images")
                    .join(split.name())
                    .join(format!("{stem}.png"));
                keep(write_raster_png(&img, sample.raster));
                let lbl = out
                    .join("labels")
                    .join(split.name())
                    .join(format!("{stem}.txt"));
                let text: String = sample.boxes.iter().map(|b| b.yolo_line() + "\n").collect();
                if let Some(dir) = lbl.parent() {
                    keep(fs::create_dir_all(dir).map_err(|e| io_err(dir, e)));
                }
                keep(fs::write(&lbl, text).map_err(|e| io_err(&lbl, e)));
            }
            if i < cfg.pictures {
                last_frame = Some(Box::new(sample.frame.clone()));
            }
            progress(1);
        },
    );
    for w in [capture, odom_w, truth_w, method_a].into_iter().flatten() {
        let mut w = w;
        keep(w.flush().map_err(|e| e.to_string()));
    }
    if i < cfg.pictures {
        let p = out.join("pictures").join(format!("{name}.png"));
        let f = create(&p)?;
        keep(
            crate::picture::write_png(&scenario.world, &path, last_frame.as_deref(), f)
                .map_err(|e| io_err(&p, e)),
        );
    }
    match err.into_inner() {
        Some(e) => Err(e),
        None => Ok((split, per_class, frames, (zeros, readings))),
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn people_walk_through_a_dataset_unlabelled() {
        let cfg = |people| DatasetConfig {
            scenarios: 6,
            frames: 10,
            seed: 3,
            people,
            ..DatasetConfig::default()
        };
        let (mut on_people, mut boxes) = (0usize, [0usize; 2]);
        for (k, people) in [0, 2].into_iter().enumerate() {
            for i in 0..6 {
                simulate(
                    i,
                    &cfg(people),
                    |_, f, _| {
                        on_people += (0..360).filter(|&d| hit_code(f, d) >= 30_000).count();
                    },
                    |_, s| boxes[k] += s.boxes.len(),
                );
            }
            if people == 0 {
                assert_eq!(on_people, 0);
            }
        }
        // People were seen, and no box was drawn for them (legs hide some furniture, so
        // there may be fewer, never more).
        assert!(on_people > 0, "no return on a person");
        assert!(boxes[1] <= boxes[0], "{boxes:?}");
    }

    #[test]
    fn splits_are_by_scenario_and_sized() {
        let s = splits(50, 1);
        let count = |x| s.iter().filter(|v| **v == x).count();
        assert_eq!(
            (count(Split::Train), count(Split::Val), count(Split::Test)),
            (42, 5, 3)
        );
        assert_eq!(s, splits(50, 1));
        assert_ne!(s, splits(50, 2));
    }

    #[test]
    fn samples_have_boxes_of_every_class() {
        let cfg = DatasetConfig {
            scenarios: 6,
            frames: 20,
            ..DatasetConfig::default()
        };
        let mut per_class = [0usize; 4];
        for i in 0..cfg.scenarios {
            simulate(
                i,
                &cfg,
                |_, _, _| {},
                |_, s| {
                    assert_eq!(s.raster.len(), RASTER_LEN);
                    for b in s.boxes {
                        per_class[b.class as usize] += 1;
                        assert!(b.w > 0.0 && b.h > 0.0);
                        assert!(b.cx - b.w / 2.0 >= 0.0 && b.cx + b.w / 2.0 <= 360.0);
                        assert!(b.cy - b.h / 2.0 >= 0.0 && b.cy + b.h / 2.0 <= 64.0);
                    }
                },
            );
        }
        assert!(per_class.iter().all(|&n| n > 0), "{per_class:?}");
    }

    /// Boxes touching the image's left or right edge (cut by the seam), boxes with no drawn
    /// pixel inside, and all boxes, over a few scenarios drawn with `seam`.
    fn seam_counts(seam: SeamRule) -> (usize, usize, usize) {
        let cfg = DatasetConfig {
            scenarios: 8,
            frames: 10,
            seed: 5,
            seam,
            ..DatasetConfig::default()
        };
        let (mut cut, mut empty, mut all) = (0, 0, 0);
        for i in 0..cfg.scenarios {
            simulate(
                i,
                &cfg,
                |_, _, _| {},
                |_, s| {
                    for b in s.boxes {
                        all += 1;
                        let (c0, c1) = (b.cx - b.w / 2.0, b.cx + b.w / 2.0);
                        if c0 <= 0.5 || c1 >= 359.5 {
                            cut += 1;
                        }
                        let (r0, r1) = (b.cy - b.h / 2.0, b.cy + b.h / 2.0);
                        let drawn = (r0 as usize..(r1.ceil() as usize).min(RASTER_H)).any(|r| {
                            (c0 as usize..(c1.ceil() as usize).min(RASTER_W))
                                .any(|c| s.raster[(r * RASTER_W + c) * 3..][..3] != [0, 0, 0])
                        });
                        if !drawn {
                            empty += 1;
                        }
                    }
                },
            );
        }
        (cut, empty, all)
    }

    #[test]
    fn the_quiet_seam_cuts_fewer_boxes_and_its_labels_follow_the_image() {
        let (fixed_cut, fixed_empty, fixed_all) = seam_counts(SeamRule::Fixed);
        let (quiet_cut, quiet_empty, quiet_all) = seam_counts(SeamRule::Quiet);
        println!(
            "boxes on the seam: fixed {fixed_cut} of {fixed_all}, quiet {quiet_cut} of {quiet_all}; \
             with nothing drawn inside: {fixed_empty}, {quiet_empty}"
        );
        // The same objects are labelled; only where the image starts differs.
        assert_eq!(fixed_all, quiet_all);
        assert!(fixed_cut > 0, "the fixed seam cuts some boxes");
        assert!(2 * quiet_cut < fixed_cut, "{quiet_cut} vs {fixed_cut}");
        // Every object returned readings, so its box holds pixels: a box beside its
        // object (labels turned one way, the image the other) would not.
        assert_eq!(fixed_empty, 0);
        assert_eq!(quiet_empty, 0);
    }

    #[test]
    fn in_memory_is_deterministic() {
        let cfg = DatasetConfig {
            scenarios: 4,
            frames: 5,
            ..DatasetConfig::default()
        };
        assert_eq!(in_memory(&cfg), in_memory(&cfg));
        let other = DatasetConfig {
            seed: 2,
            ..cfg.clone()
        };
        assert_ne!(in_memory(&cfg).1, in_memory(&other).1);
    }
}
