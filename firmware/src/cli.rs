//! Command-line interface (`docs/interfaces.md` §1).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use drivers::lidar::LidarModel;

/// Exit status for bad arguments or configuration.
pub const EXIT_USAGE: u8 = 2;
/// Exit status for an unrecoverable runtime fault.
pub const EXIT_FAULT: u8 = 1;

/// A command's failure: the exit status and the message.
pub type Failure = (u8, String);

/// `umbra --version`: the version, then what this binary was built with — its features, the
/// compiled-in models by SHA-256 (as `models/README.md` and `sha256sum models/yolo/*.onnx`
/// name them), and the machine it was built for. (`-V` prints the version alone.)
pub fn long_version() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(|| {
        let features: Vec<&str> = [
            ("method-b", cfg!(feature = "method-b")),
            ("viz", cfg!(feature = "viz")),
            ("sim", cfg!(feature = "sim")),
            ("view", cfg!(feature = "view")),
        ]
        .iter()
        .filter_map(|(name, on)| on.then_some(*name))
        .collect();
        #[cfg(feature = "method-b")]
        let model = format!(
            "model: umbra-yolov8n.onnx sha256 {}\nmodel: umbra-yolov8n-int8.onnx sha256 {}",
            models::yolo::BUILTIN_SHA256,
            models::yolo::BUILTIN_INT8_SHA256
        );
        #[cfg(not(feature = "method-b"))]
        let model = String::from("model: none (built without method-b: Method A only)");
        format!(
            "{}\nfeatures: {}\n{model}\nbuilt for: {}-{}",
            env!("CARGO_PKG_VERSION"),
            if features.is_empty() {
                "none".to_string()
            } else {
                features.join(" ")
            },
            std::env::consts::ARCH,
            std::env::consts::OS
        )
    })
}

/// umbra: camera-free perception for small indoor robots.
#[derive(Debug, Parser)]
#[command(name = "umbra", version, long_version = long_version(), about)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run on a robot, or on the built-in simulated robot when no hardware is named.
    Run(RunArgs),
    /// Run the same pipeline on a raw LiDAR capture file.
    Replay(ReplayArgs),
    /// Fit the compass's hard-iron offset from readings taken while the robot turns, and write
    /// it to the configuration.
    CalibrateCompass(CalibrateArgs),
    /// Print the deadline and power table of a finished run from its `--jsonl` output.
    Report(ReportArgs),
}

/// `umbra report`.
#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The run's JSON Lines (`--jsonl`).
    pub jsonl: PathBuf,
    /// The run's configuration, for its stage budgets (default: shares of the lines'
    /// deadline).
    #[arg(long, value_name = "PATH")]
    pub config: Option<PathBuf>,
}

/// `umbra calibrate-compass`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Odometry/compass JSON Lines recorded while the robot turned at least half a turn
    /// (`mag_ut` samples). Without it, the simulated robot's compass is calibrated.
    #[arg(long, value_name = "ODOM.jsonl")]
    pub odom: Option<PathBuf>,
    /// Record live from an LSM303AGR on this I²C bus (e.g. /dev/i2c-1) while the robot turns.
    #[arg(long, value_name = "BUS")]
    pub compass: Option<String>,
    /// How long to record live, s.
    #[arg(long, default_value_t = 30.0)]
    pub seconds: f64,
    /// Write `[compass] hard_iron_ut` into this TOML file (created if absent).
    #[arg(long, value_name = "PATH")]
    pub write: Option<PathBuf>,
    /// Seed of the simulated robot (without --odom).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// `--lidar-model`: `auto` (tell the model from the bytes: baud rates probed on a port,
/// framing in a capture) or one of the drivers' models by its command-line name
/// (`drivers::lidar::LidarModel::cli_name`).
fn lidar_model_parser() -> impl clap::builder::TypedValueParser<Value = Named> {
    use clap::builder::{PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(
        std::iter::once("auto").chain(LidarModel::ALL.iter().map(|m| m.cli_name())),
    )
    .map(|name| Named(LidarModel::ALL.into_iter().find(|m| m.cli_name() == name)))
}

/// The LiDAR model `--lidar-model` names (`None` for `auto`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Named(pub Option<LidarModel>);

/// Replay pacing (`--speed`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Speed {
    /// As fast as possible.
    Max,
    /// Paced by the sensor's own clock.
    #[value(name = "1")]
    RealTime,
}

/// Options shared by `run` and `replay`.
#[derive(Debug, Args)]
pub struct Common {
    /// Which LiDAR speaks on the port or in the capture.
    #[arg(long, value_name = "MODEL", default_value = "auto", value_parser = lidar_model_parser())]
    pub lidar_model: Named,
    /// Write one JSON line per frame here (`-` = stdout).
    #[arg(long, value_name = "PATH")]
    pub jsonl: Option<String>,
    /// Stop after N frames.
    #[arg(long, value_name = "N")]
    pub frames: Option<u64>,
    /// Stop after S seconds (wall clock for `run`, sensor clock for `replay`).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// TOML configuration file.
    #[arg(long, value_name = "PATH")]
    pub config: Option<PathBuf>,
    /// Method B's YOLO model (ONNX, 1×3×64×384 → Ultralytics' 1×8×504 or the head's logits,
    /// 1×68×504); default: the compiled-in one.
    #[arg(long, value_name = "MODEL.onnx")]
    pub model: Option<PathBuf>,
    /// No per-frame human-readable lines.
    #[arg(long, short)]
    pub quiet: bool,
    /// Also print each revolution's LiDAR statistics (rpm, packets, valid readings, ranges).
    #[arg(long, short)]
    pub verbose: bool,
    /// Record the run to this MCAP file (Foxglove schemas: scan, transforms, pose, scene).
    #[arg(long, value_name = "PATH.mcap")]
    pub record: Option<PathBuf>,
    /// Serve the same channels live over Foxglove's WebSocket protocol, e.g. 0.0.0.0:8765.
    #[arg(long, value_name = "HOST:PORT")]
    pub live: Option<std::net::SocketAddr>,
    /// When the run ends, draw the map, robot, walls, doors and objects to this SVG file.
    #[arg(long, value_name = "PATH.svg")]
    pub snapshot: Option<PathBuf>,
    /// A live map in this terminal instead of the per-frame lines: the scan, the robot, the
    /// objects labelled with class and id, doors and people, redrawn in place.
    #[arg(long)]
    pub view: bool,
    /// Write each frame's tracks that earned a report, with the features the report model
    /// reads, to this file (world model on; for `training/fit_report_model.py`).
    #[arg(long, value_name = "PATH")]
    pub track_log: Option<PathBuf>,
}

/// `umbra run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// LiDAR serial port, e.g. /dev/ttyUSB0. Without it the simulated robot runs.
    #[arg(long, value_name = "PORT")]
    pub lidar: Option<String>,
    /// OpenCR serial port for wheel encoders (e.g. /dev/ttyACM0).
    #[arg(long, value_name = "PORT")]
    pub opencr: Option<String>,
    /// Compass I2C bus (e.g. /dev/i2c-1).
    #[arg(long, value_name = "BUS")]
    pub compass: Option<String>,
    /// Seed of the simulated room (simulated robot only).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Simulated robot only: `1` runs at the sensor's pace (5 revolutions a second), `max`
    /// as fast as it can (soaks, deadline reports).
    #[arg(long, value_enum, default_value = "1")]
    pub speed: Speed,
    /// Shared options.
    #[command(flatten)]
    pub common: Common,
}

/// `umbra replay`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// Raw LiDAR capture (bytes as read from the serial port).
    pub capture: PathBuf,
    /// Odometry/compass JSON Lines on the capture's clock.
    #[arg(long, value_name = "ODOM.jsonl")]
    pub odom: Option<PathBuf>,
    /// `max` runs as fast as it can; `1` paces by the sensor's own clock.
    #[arg(long, value_enum, default_value = "max")]
    pub speed: Speed,
    /// Shared options.
    #[command(flatten)]
    pub common: Common,
}
