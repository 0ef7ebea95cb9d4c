//! `umbra-sim`: the simulator's command line.
//!
//! * `umbra-sim dataset --out DIR [--scenarios 50] [--frames 200] [--seed 1] [--kinds rect,lshape,tworooms] [--clutter 3] [--varied 0.5] [--office-chairs 0.4] [--round-tables 0.4] [--test-only] [--seam fixed|quiet] [--deskew]`
//!   writes the datasets of `sim::dataset` with a progress bar.
//! * `umbra-sim speed [--scenarios 16] [--frames 200]` measures labelled frames per second
//!   with rasters and labels built in memory.
//! * `umbra-sim capture --out FILE [--revolutions N] [--seed S] [--corrupt] [--model M]` writes raw LiDAR
//!   bytes as a serial port delivers them (for `umbra replay`).
//! * `umbra-sim picture --out FILE [--seed S] [--tour]` draws a scene.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use perception::seam::SeamRule;
use sim::corrupt::{Corruption, corrupt};
use sim::dataset::{DatasetConfig, generate, in_memory, simulate};
use sim::lds01::Lds01SimConfig;
use sim::world::{RoomKind, World, WorldConfig};

#[derive(Parser)]
#[command(
    name = "umbra-sim",
    version,
    about = "umbra's simulator: sensor bytes and datasets"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, ValueEnum)]
enum Kind {
    Rect,
    Lshape,
    Tworooms,
    Notch,
}

#[derive(Clone, Copy, ValueEnum)]
enum Seam {
    Fixed,
    Quiet,
}

#[derive(Subcommand)]
enum Command {
    /// Write a dataset (Method B YOLO layout, Method A labels, recordings, pictures).
    Dataset {
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Scenarios.
        #[arg(long, default_value_t = 50)]
        scenarios: usize,
        /// Labelled frames per scenario.
        #[arg(long, default_value_t = 200)]
        frames: usize,
        /// Master seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Room layouts to draw from.
        #[arg(long, value_enum, value_delimiter = ',', default_values_t = [Kind::Rect, Kind::Lshape, Kind::Tworooms])]
        kinds: Vec<Kind>,
        /// Most clutter items per scene.
        #[arg(long, default_value_t = 3)]
        clutter: usize,
        /// Share of worlds drawn varied (0–1): other wall thicknesses and colours, doorways at
        /// corners, door leaves, partition stubs, furniture against walls, tucked chairs,
        /// shelves, radiators, square pillars, a LiDAR that reaches less far.
        #[arg(long, default_value_t = 0.0)]
        varied: f64,
        /// Share of a varied world's chairs drawn as office chairs on a five-star base (0–1).
        #[arg(long, default_value_t = 0.0)]
        office_chairs: f64,
        /// Share of a varied world's desks drawn as round tables on three or four legs (0–1).
        #[arg(long, default_value_t = 0.0)]
        round_tables: f64,
        /// Share of a varied world's boxes drawn with sides of their own, 0.3–0.9 × 0.25–0.6 m
        /// (0–1).
        #[arg(long, default_value_t = 0.0)]
        box_sizes: f64,
        /// Share of a varied world's boxes drawn dark, reflectivity 0.05–0.5 (0–1).
        #[arg(long, default_value_t = 0.0)]
        dark_boxes: f64,
        /// Share of office chairs whose base's arms lie in the scan plane, each seen whole
        /// (a LiDAR at the hub's height) (0–1).
        #[arg(long, default_value_t = 0.0)]
        office_spokes: f64,
        /// Skip Method B images and labels.
        #[arg(long)]
        no_images: bool,
        /// Skip Method A labels.
        #[arg(long)]
        no_method_a: bool,
        /// Skip recordings.
        #[arg(long)]
        no_recordings: bool,
        /// Pictures of the first N scenarios.
        #[arg(long, default_value_t = 3)]
        pictures: usize,
        /// Every scenario in the test split (a second test set from other room kinds).
        #[arg(long)]
        test_only: bool,
        /// People walking through each scenario, 0 to N (never labelled: what Method B must
        /// not take for furniture).
        #[arg(long, default_value_t = 0)]
        people: usize,
        /// Where each image starts: `fixed` (bin 0, the LiDAR's forward axis, first) or `quiet`
        /// (the middle of the longest unbroken surface first: `perception::seam`), as the
        /// runtime's `[method_b] seam` does.
        #[arg(long, value_enum, default_value_t = Seam::Fixed)]
        seam: Seam,
        /// Labels as the sweep read each footprint (each corner at the bearing and from the
        /// place of its read instant), as the runtime's `[method_b] deskew` decodes them; by
        /// default from the robot's pose at the middle of the revolution.
        #[arg(long)]
        deskew: bool,
        /// Share of scenarios whose LiDAR is a worn unit (0–1): returns that fade with range and
        /// mixed pixels at depth edges (`sim::wear`).
        #[arg(long, default_value_t = 0.0)]
        worn: f64,
        /// Share of scenarios whose LiDAR returns by the light it receives (0–1):
        /// reflectivity · cos(incidence) / range² against a threshold of its own (`sim::power`),
        /// instead of the additive dark and glancing dropouts.
        #[arg(long, default_value_t = 0.0)]
        power: f64,
    },
    /// Labelled frames per second, rasters and labels in memory.
    Speed {
        /// Scenarios.
        #[arg(long, default_value_t = 16)]
        scenarios: usize,
        /// Labelled frames per scenario.
        #[arg(long, default_value_t = 200)]
        frames: usize,
        /// Master seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Write a raw LDS-01 capture of a simulated robot in a random room.
    Capture {
        /// Output file.
        #[arg(long)]
        out: PathBuf,
        /// Revolutions to write (5 per second of sensor time).
        #[arg(long, default_value_t = 50)]
        revolutions: usize,
        /// Seed of the sensor noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Seed of the room.
        #[arg(long, default_value_t = 1)]
        room_seed: u64,
        /// Send the bytes through a noisy line (1e-3 bit flips, inserted/dropped bytes, bursts).
        #[arg(long)]
        corrupt: bool,
        /// The LiDAR model whose bytes to write: lds01, lds02, ld06, ld19, rplidar-a1,
        /// rplidar-a2 (the same scene for each).
        #[arg(long, default_value = "lds01")]
        model: String,
    },
    /// Draw one scenario of a dataset seed as a PNG.
    Picture {
        /// Output PNG.
        #[arg(long)]
        out: PathBuf,
        /// Master seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Scenario index (odd indices drive waypoint tours).
        #[arg(long, default_value_t = 1)]
        scenario: usize,
        /// Frames to simulate (the path drawn; the last revolution's returns are shown).
        #[arg(long, default_value_t = 300)]
        frames: usize,
    },
}

fn kinds(k: &[Kind]) -> Vec<RoomKind> {
    k.iter()
        .map(|k| match k {
            Kind::Rect => RoomKind::Rect,
            Kind::Lshape => RoomKind::LShape,
            Kind::Tworooms => RoomKind::TwoRooms,
            Kind::Notch => RoomKind::Notch,
        })
        .collect()
}

fn main() -> ExitCode {
    match run(Cli::parse().command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("umbra-sim: {e}");
            ExitCode::from(1)
        }
    }
}

fn run(command: Command) -> Result<(), String> {
    match command {
        Command::Dataset {
            out,
            scenarios,
            frames,
            seed,
            kinds: k,
            clutter,
            varied,
            office_chairs,
            round_tables,
            box_sizes,
            dark_boxes,
            office_spokes,
            no_images,
            no_method_a,
            no_recordings,
            pictures,
            test_only,
            people,
            seam,
            deskew,
            worn,
            power,
        } => {
            let cfg = DatasetConfig {
                scenarios,
                frames,
                seed,
                world: WorldConfig {
                    kinds: kinds(&k),
                    max_clutter: clutter,
                    varied,
                    office_chairs,
                    round_tables,
                    box_sizes,
                    dark_boxes,
                    office_spokes,
                    ..WorldConfig::default()
                },
                method_b: !no_images,
                method_a: !no_method_a,
                recordings: !no_recordings,
                pictures,
                test_only,
                people,
                seam: match seam {
                    Seam::Fixed => SeamRule::Fixed,
                    Seam::Quiet => SeamRule::Quiet,
                },
                deskew,
                worn,
                power,
                ..DatasetConfig::default()
            };
            let bar = ProgressBar::new((scenarios * frames) as u64);
            bar.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {pos}/{len} frames ({per_sec}, eta {eta})",
                )
                .map_err(|e| e.to_string())?,
            );
            let report = generate(&cfg, &out, |n| bar.inc(n))?;
            bar.finish();
            println!(
                "wrote {} labelled frames from {scenarios} scenarios to {} in {:.1} s ({:.0} frames/s); no-return share {:.1} %",
                report.frames,
                out.display(),
                report.seconds,
                report.frames as f64 / report.seconds,
                report.no_return_share * 100.0
            );
            for (si, name) in ["train", "val", "test"].iter().enumerate() {
                let b = report.boxes[si];
                println!(
                    "  {name:5}: {:6} frames, boxes chair {} box {} desk {} door_frame {}",
                    report.frames_per_split[si], b[0], b[1], b[2], b[3]
                );
            }
            Ok(())
        }
        Command::Speed {
            scenarios,
            frames,
            seed,
        } => {
            let cfg = DatasetConfig {
                scenarios,
                frames,
                seed,
                ..DatasetConfig::default()
            };
            let start = Instant::now();
            let (n, digest) = in_memory(&cfg);
            let s = start.elapsed().as_secs_f64();
            println!(
                "{n} labelled frames in {s:.2} s: {:.0} frames/s on {} threads (digest {digest:016x})",
                n as f64 / s,
                rayon::current_num_threads()
            );
            Ok(())
        }
        Command::Capture {
            out,
            revolutions,
            seed,
            room_seed,
            corrupt: noisy,
            model,
        } => {
            let model = drivers::lidar::LidarModel::ALL
                .into_iter()
                .find(|m| m.cli_name() == model)
                .ok_or_else(|| format!("--model {model}: not a LiDAR model umbra knows"))?;
            let sc = sim::scenario::ScenarioConfig {
                lidar: Lds01SimConfig::default(),
                ..sim::scenario::ScenarioConfig::default()
            };
            let scenario =
                sim::scenario::Scenario::in_world(World::random_room(room_seed), seed, &sc);
            let mut sim = sim::wire::WireSim::new(scenario, model);
            let mut bytes = Vec::new();
            sim.emit_revolutions(revolutions, &mut bytes);
            if noisy {
                bytes = corrupt(bytes.chunks(sim.unit_len()), Corruption::ISSUE_MIX, seed).bytes;
            }
            std::fs::write(&out, &bytes)
                .map_err(|e| format!("cannot write {}: {e}", out.display()))?;
            println!(
                "wrote {} bytes ({revolutions} revolutions) to {}",
                bytes.len(),
                out.display()
            );
            Ok(())
        }
        Command::Picture {
            out,
            seed,
            scenario,
            frames,
        } => {
            let cfg = DatasetConfig {
                frames,
                seed,
                ..DatasetConfig::default()
            };
            let mut path = Vec::new();
            let mut last = None;
            let sc = simulate(
                scenario,
                &cfg,
                |_, f, _| {
                    path.push(perception::geometry::Point2::new(
                        f.pose_mid.x,
                        f.pose_mid.y,
                    ))
                },
                |_, s| last = Some(s.frame.clone()),
            );
            let file =
                std::fs::File::create(&out).map_err(|e| format!("{}: {e}", out.display()))?;
            sim::picture::write_png(
                &sc.world,
                &path,
                last.as_ref(),
                std::io::BufWriter::new(file),
            )
            .map_err(|e| format!("{}: {e}", out.display()))?;
            println!("{}: {}", out.display(), sc.world.describe());
            Ok(())
        }
    }
}
