//! `umbra-lab`: umbra's workbench (host only; never flashed to a robot).
//!
//! * `umbra-lab forest-data --out models/data/forest-train.csv [--seed 1] [--scenes 600]
//!   [--clutter 6] [--varied 0.5]` runs Method A on training scenes of the simulator (half of
//!   them varied worlds) and writes one labelled row per candidate (both feature frames).
//! * `umbra-lab forest-train [--data …] [--out models/src/forest_tables.rs] [--frame object]`
//!   fits the scaler and forest and writes the constant tables.
//! * `umbra-lab eval-a [--seed 2] [--scenes 200] [--confusion docs/method-a-confusion.png]`
//!   scores the compiled-in forest on held-out scenes (another seed: other worlds), with
//!   `--compare-frames` training both frames from `--data` in memory and scoring each, and
//!   `--merge-guards` scoring each merge guard alone.
//!
//! * `umbra-lab eval-b --data DATASET [--split test] [--model FILE] [--json OUT]` scores a
//!   YOLO model (default: the compiled-in one) on a simulator dataset split with the Rust
//!   evaluator (P, R, mAP50, mAP50-95 as Ultralytics computes them).
//!
//! * `umbra-lab pose-eval [--scenarios 3] [--minutes 10] [--seed 1]` prints the heading and
//!   position drift of odometry, the compass overwrite and our fusion (`docs/pose.md`).
//!
//! * `umbra-lab eval-world [--family sim|annex|both] [--runs 12] [--world on|off|both]`
//!   replays held-out runs of both scene families through the `umbra` binary and scores its
//!   world (`docs/world.md`).
//! * `umbra-lab compare BASE.json… [--with OTHER.json…]` sets two settings' `eval-world --json`
//!   results side by side, run by run, with a paired bootstrap interval for each difference.
//!
//! Regenerating the committed forest is the two commands `forest-data` and `forest-train` with
//! their defaults; both are deterministic.

#[path = "umbra-lab/variety.rs"]
mod variety;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use lab::eval_a::{self, Score, csv_header, rows_of};
use lab::scenes_a::{PoseSource, SceneConfig, run_scene};
use models::train::{TrainConfig, emit_rust, read_csv, train};
use perception::features::FeatureFrame;
use perception::method_a::{MethodA, MethodAConfig, Unclassified};

#[derive(Parser)]
#[command(
    name = "umbra-lab",
    version,
    about = "umbra's workbench: forest data and training, evaluators, pose drift"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum Frame {
    Object,
    Axis,
}

#[derive(Clone, Copy, ValueEnum)]
enum Pose {
    Odometry,
    Truth,
}

/// The regeneration command written into the tables' header.
const TRAIN_CMD: &str = "cargo run --release -p umbra-lab -- forest-data && cargo run --release -p umbra-lab -- forest-train";

#[derive(Subcommand)]
enum Command {
    /// Labelled candidates from training scenes, as CSV.
    ForestData {
        #[arg(long, default_value = "models/data/forest-train.csv")]
        out: PathBuf,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[arg(long, default_value_t = 600)]
        scenes: usize,
        #[arg(long, value_enum, default_value = "odometry")]
        pose: Pose,
        /// Most clutter items per scene.
        #[arg(long, default_value_t = 6)]
        clutter: usize,
        /// Share of worlds drawn varied (`umbra-sim dataset --varied`): the "none" class
        /// learns wall pieces of other thickness, reach and dropout, shelves and pillars.
        #[arg(long, default_value_t = 0.5)]
        varied: f64,
        #[command(flatten)]
        variety: variety::Variety,
    },
    /// Writes the detections' score calibration (`models/src/calibration_counts.rs`) from
    /// `eval-world --json` files: each file's families' detection counts by source, class and
    /// tenth of the score, summed. Fit it on tuning seeds only (`docs/world.md`).
    Calibrate {
        /// `eval-world --json` outputs.
        #[arg(required = true)]
        json: Vec<PathBuf>,
        #[arg(long, default_value = "models/src/calibration_counts.rs")]
        out: PathBuf,
        /// The command that made the JSON files, recorded in the table's header.
        #[arg(long, default_value = "")]
        made_by: String,
    },
    /// Trains the forest and writes its tables.
    ForestTrain {
        #[arg(long, default_value = "models/data/forest-train.csv")]
        data: PathBuf,
        #[arg(long, default_value = "models/src/forest_tables.rs")]
        out: PathBuf,
        #[arg(long, value_enum, default_value = "object")]
        frame: Frame,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Deepest split level.
        #[arg(long, default_value_t = TrainConfig::default().max_depth)]
        depth: usize,
        /// Trees.
        #[arg(long, default_value_t = TrainConfig::default().trees)]
        trees: usize,
    },
    /// Scores Method A on held-out scenes.
    EvalA {
        #[arg(long, default_value_t = 2)]
        seed: u64,
        #[arg(long, default_value_t = 200)]
        scenes: usize,
        #[arg(long, value_enum, default_value = "odometry")]
        pose: Pose,
        #[command(flatten)]
        worlds: Worlds,
        /// Write the confusion matrix here (PNG).
        #[arg(long)]
        confusion: Option<PathBuf>,
        /// Train both feature frames from this data in memory and score each.
        #[arg(long)]
        compare_frames: bool,
        /// Score with each merge guard alone and with none.
        #[arg(long)]
        merge_guards: bool,
        #[arg(long, default_value = "models/data/forest-train.csv")]
        data: PathBuf,
    },
    /// Scores a YOLO model on a dataset split (Method B).
    EvalB {
        /// Dataset folder written by `umbra-sim dataset`.
        #[arg(long)]
        data: PathBuf,
        #[arg(long, default_value = "test")]
        split: String,
        /// ONNX file (default: the compiled-in model).
        #[arg(long)]
        model: Option<PathBuf>,
        /// Threads for tract.
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Write the metrics here as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
        /// A second look at each image mirrored, the two looks' boxes fused (`[method_b]
        /// mirror`, `perception::mirror_look`).
        #[arg(long)]
        mirror: bool,
    },
    /// Heading/position drift of odometry, compass overwrite and fusion (Markdown table).
    PoseEval {
        /// Scenarios (each run with oscillation and with a tour).
        #[arg(long, default_value_t = 3)]
        scenarios: usize,
        /// Minutes per run.
        #[arg(long, default_value_t = 10.0)]
        minutes: f32,
        /// Master seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// The world as `umbra replay` reports it, scored on both scene families (world model on
    /// and off): final map, phantoms per frame, identity, moved pieces, doors, people.
    EvalWorld {
        /// Families to run.
        #[arg(long, value_enum, default_value = "both")]
        family: FamilyArg,
        /// Runs per family.
        #[arg(long, default_value_t = 12)]
        runs: usize,
        /// Seconds per run.
        #[arg(long, default_value_t = 30.0)]
        seconds: f64,
        /// Evaluation seed (held out: no training or tuning seed).
        #[arg(long, default_value_t = 9001)]
        seed: u64,
        /// World model settings to score.
        #[arg(long, value_enum, default_value = "both")]
        world: WorldArg,
        /// The `umbra` binary (default: the one beside this program).
        #[arg(long)]
        umbra: Option<PathBuf>,
        /// Where the runs (bytes, ticks, truth, output lines) are written and kept.
        #[arg(long, default_value = "target/eval-world")]
        dir: PathBuf,
        /// Write the counts here as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Draw the phantom rates as a bar chart here (PNG).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// A `[world]` setting for the world-on replays, e.g. `--world-set settle_s=0`
        /// (repeatable; for ablations).
        #[arg(long = "world-set", value_name = "KEY=VALUE")]
        world_set: Vec<String>,
        /// Keep each world-on replay's track log (`tracks.txt` beside its output lines), for
        /// `training/fit_report_model.py`.
        #[arg(long)]
        track_logs: bool,
    },
    /// Compares two settings' `eval-world --json` results run by run (the same seeds, in the
    /// same order): each figure's difference and its 95 % interval from a paired bootstrap
    /// over runs, and whether that is more than the runs' scatter. Without `--with`, each
    /// figure of the first set with its own interval.
    Compare {
        /// The base setting's `eval-world --json` files.
        #[arg(required = true)]
        base: Vec<PathBuf>,
        /// The other setting's files, one for each base file, in the same order.
        #[arg(long, num_args = 1..)]
        with: Vec<PathBuf>,
        /// Bootstrap draws.
        #[arg(long, default_value_t = 4000)]
        resamples: usize,
        /// Seed of the draws.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum FamilyArg {
    Sim,
    /// The simulator's varied worlds (what Method B now trains on), held-out seeds.
    Varied,
    /// The varied worlds seen by a worn LiDAR (returns fading with range, mixed pixels).
    Worn,
    Annex,
    /// sim and annex.
    Both,
    /// sim, varied and annex.
    All,
}

#[derive(Clone, Copy, ValueEnum)]
enum WorldArg {
    On,
    Off,
    Both,
}

fn bar(n: usize, what: &str) -> ProgressBar {
    let b = ProgressBar::new(n as u64);
    b.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message(what.to_string());
    b
}

fn feature_frame(object: bool) -> FeatureFrame {
    if object {
        FeatureFrame::Object
    } else {
        FeatureFrame::Axis
    }
}

/// Which simulator worlds a Method A command runs on.
#[derive(clap::Args, Clone, Copy)]
struct Worlds {
    /// Most clutter items per scene.
    #[arg(long, default_value_t = 3)]
    clutter: usize,
    /// Share of worlds drawn varied (`umbra-sim dataset --varied`).
    #[arg(long, default_value_t = 0.0)]
    varied: f64,
}

fn scene_cfg(seed: u64, pose: Pose, worlds: Worlds) -> SceneConfig {
    SceneConfig {
        seed,
        world: sim::world::WorldConfig {
            max_clutter: worlds.clutter,
            varied: worlds.varied,
            ..sim::world::WorldConfig::default()
        },
        pose: match pose {
            Pose::Odometry => PoseSource::Odometry,
            Pose::Truth => PoseSource::Truth,
        },
        ..SceneConfig::default()
    }
}

fn run(cli: Cli) -> Result<(), String> {
    match cli.command {
        Command::ForestData {
            out,
            seed,
            scenes,
            pose,
            clutter,
            varied,
            variety,
        } => {
            let mut cfg = scene_cfg(seed, pose, Worlds { clutter, varied });
            variety.apply(&mut cfg);
            let mut method = Box::new(MethodA::new());
            let mut text = csv_header();
            text.push('\n');
            let b = bar(scenes, "scenes");
            let mut counts = std::collections::BTreeMap::new();
            for i in 0..scenes {
                run_scene(
                    i,
                    &cfg,
                    &MethodAConfig::default(),
                    &mut method,
                    &Unclassified,
                    |v| {
                        for r in rows_of(v) {
                            *counts.entry(r.truth).or_insert(0usize) += 1;
                            text.push_str(&r.csv());
                            text.push('\n');
                        }
                    },
                );
                b.inc(1);
            }
            b.finish();
            if let Some(dir) = out.parent() {
                std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            }
            std::fs::write(&out, text).map_err(|e| format!("{}: {e}", out.display()))?;
            println!("{}: {counts:?}", out.display());
        }
        Command::Compare {
            base,
            with,
            resamples,
            seed,
        } => print!(
            "{}",
            lab::world_eval::compare::files(&base, &with, resamples, seed)?
        ),
        Command::Calibrate { json, out, made_by } => {
            let text = lab::world_eval::calibration_counts(&json, &made_by)?;
            std::fs::write(&out, text).map_err(|e| format!("{}: {e}", out.display()))?;
            println!("{}", out.display());
        }
        Command::ForestTrain {
            data,
            out,
            frame,
            seed,
            depth,
            trees,
        } => {
            let text =
                std::fs::read_to_string(&data).map_err(|e| format!("{}: {e}", data.display()))?;
            let object = frame == Frame::Object;
            let d = read_csv(&text, object).map_err(|e| format!("{}: {e}", data.display()))?;
            let t = train(
                &d,
                &TrainConfig {
                    seed,
                    object_frame: object,
                    max_depth: depth,
                    trees,
                    ..TrainConfig::default()
                },
            );
            std::fs::write(&out, emit_rust(&t, TRAIN_CMD))
                .map_err(|e| format!("{}: {e}", out.display()))?;
            println!(
                "{}: {} samples, {} trees, {} nodes",
                out.display(),
                d.x.len(),
                t.roots.len(),
                t.nodes.len()
            );
        }
        Command::EvalB {
            data,
            split,
            model,
            threads,
            json,
            mirror,
        } => {
            let opts = models::yolo::YoloOptions { threads };
            let mut m = models::yolo::YoloModel::load_or_builtin(model.as_deref(), opts)
                .map_err(|e| e.to_string())?;
            let n = lab::eval_b::split_images(&data, &split)?.len();
            let b = bar(n, "images");
            let stats = lab::eval_b::evaluate(&mut m, &data, &split, mirror, |_, _| b.inc(1))?;
            b.finish_and_clear();
            let report = lab::eval_b::Report {
                ours: stats.ours.metrics(),
                study_rule: stats.study.metrics(),
            };
            println!(
                "## Method B: {} on {} / {split}\n",
                m.name(),
                data.display()
            );
            print!("{}", lab::eval_b::table(&report.ours));
            println!(
                "\nThe study's ruler (its label rule: boxes + 20 px wide, + 12 px tall on both sides, clamped):\n"
            );
            print!("{}", lab::eval_b::table(&report.study_rule));
            if let Some(p) = json {
                let text = serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?;
                std::fs::write(&p, text).map_err(|e| format!("{}: {e}", p.display()))?;
            }
        }
        Command::EvalA {
            seed,
            scenes,
            pose,
            worlds,
            confusion,
            compare_frames,
            merge_guards,
            data,
        } => {
            let cfg = scene_cfg(seed, pose, worlds);
            let forest = models::forest::forest();
            let acfg = MethodAConfig {
                frame: feature_frame(forest.object_frame),
                ..MethodAConfig::default()
            };
            let go = |acfg: &MethodAConfig, c: &dyn Fn(&MethodAConfig, &ProgressBar) -> Score| {
                let b = bar(scenes, "scenes");
                let s = c(acfg, &b);
                b.finish_and_clear();
                s
            };
            let eval = |acfg: &MethodAConfig, classifier: &models::forest::ForestTables| {
                go(acfg, &|a, b| {
                    eval_a::evaluate(0..scenes, &cfg, a, classifier, || b.inc(1))
                })
            };
            let score = eval(&acfg, forest);
            println!(
                "## Method A, held-out scenes (seed {seed}, {scenes} scenes, {} views)\n",
                score.views
            );
            println!("{}", score.markdown());
            if let Some(p) = confusion {
                lab::confusion_png::write(&p, &score)
                    .map_err(|e| format!("{}: {e}", p.display()))?;
                println!("confusion matrix: {}", p.display());
            }
            if compare_frames {
                let text = std::fs::read_to_string(&data)
                    .map_err(|e| format!("{}: {e}", data.display()))?;
                for object in [true, false] {
                    let d =
                        read_csv(&text, object).map_err(|e| format!("{}: {e}", data.display()))?;
                    let f = train(
                        &d,
                        &TrainConfig {
                            object_frame: object,
                            ..TrainConfig::default()
                        },
                    )
                    .leak();
                    let a = MethodAConfig {
                        frame: feature_frame(object),
                        ..MethodAConfig::default()
                    };
                    let s = eval(&a, &f);
                    let (r, n) = s.object_accuracy();
                    let f1: Vec<String> = s.prf().iter().map(|x| format!("{:.4}", x.2)).collect();
                    println!(
                        "frame {}: object accuracy {r}/{n} = {:.2} %, F1 chair/box/desk {}",
                        if object { "object" } else { "axis" },
                        100.0 * f64::from(r) / f64::from(n.max(1)),
                        f1.join(" / ")
                    );
                }
            }
            if merge_guards {
                print!("{}", eval_a::merge_guard_table(&acfg, |a| eval(a, forest)));
            }
        }
        Command::PoseEval {
            scenarios,
            minutes,
            seed,
        } => {
            let rows = lab::pose_eval::table(seed, scenarios, minutes * 60.0);
            print!("{}", lab::pose_eval::markdown(&rows));
        }
        Command::EvalWorld {
            family,
            runs,
            seconds,
            seed,
            world,
            umbra,
            dir,
            json,
            plot,
            world_set,
            track_logs,
        } => {
            use lab::world_eval::{EvalConfig, Family, evaluate, report};
            let umbra = match umbra {
                Some(p) => p,
                None => std::env::current_exe()
                    .map_err(|e| e.to_string())?
                    .with_file_name("umbra"),
            };
            if !umbra.exists() {
                return Err(format!(
                    "{} not found: build it (`cargo build --release -p umbra-firmware`) or pass --umbra",
                    umbra.display()
                ));
            }
            let families = match family {
                FamilyArg::Sim => vec![Family::Sim],
                FamilyArg::Varied => vec![Family::Varied],
                FamilyArg::Worn => vec![Family::Worn],
                FamilyArg::Annex => vec![Family::Annex],
                FamilyArg::Both => vec![Family::Sim, Family::Annex],
                FamilyArg::All => vec![Family::Sim, Family::Varied, Family::Annex],
            };
            let world = match world {
                WorldArg::On => vec![true],
                WorldArg::Off => vec![false],
                WorldArg::Both => vec![false, true],
            };
            let cfg = EvalConfig {
                families,
                runs,
                seconds,
                seed,
                world,
                umbra,
                dir,
                world_set: world_set
                    .iter()
                    .map(|s| s.replacen('=', " = ", 1))
                    .collect(),
                track_logs,
            };
            let pb = bar(runs * cfg.families.len(), "runs");
            let out = evaluate(&cfg, |name| {
                pb.println(name);
                pb.inc(1);
            })?;
            pb.finish_and_clear();
            print!("{}", report(&out));
            if let Some(p) = json {
                let text = serde_json::to_string_pretty(&out).map_err(|e| e.to_string())?;
                std::fs::write(&p, text + "\n").map_err(|e| format!("{}: {e}", p.display()))?;
            }
            if let Some(p) = plot {
                lab::world_eval::picture::write_phantom_bars(&p, &out)
                    .map_err(|e| format!("{}: {e}", p.display()))?;
            }
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("umbra-lab: {e}");
            ExitCode::from(1)
        }
    }
}
