//! The TOML configuration (`--config PATH`): every setting has a default and is validated at
//! start-up; an error names the file and the field.
//!
//! ```toml
//! [lidar]
//! checksum = "verify"      # or "count": keep packets whose checksum fails, and count them
//! min_range_m = 0.12       # readings outside [min, max] are marked invalid
//! max_range_m = 3.5
//! stale_after_ms = 500     # hand out a partial revolution after this much silence
//!
//! [runtime]
//! deadline_ms = 250        # per-frame budget
//! scheduling = "normal"    # or "fifo": the frame loop real-time (needs CAP_SYS_NICE)
//! fifo_priority = 20       # 1–99, with "fifo"
//!
//! [runtime.budget_ms]      # per-stage budgets; each defaults to a share of the deadline
//! ingest = 10              # 4 %
//! pose = 20                # 8 %  (scan matching: up to 18 ms a frame on a Pi 3)
//! method_a = 65            # 26 %
//! method_b = 140           # 56 %
//! output = 15              # 6 %
//!
//! [power]
//! budget_w = 10.0
//! source = "auto"          # or "ina219", "pmic", "model"
//! board = "auto"           # the model's board: "pi5", "pi3b+", "pi3b"; auto: device tree
//! lidar_w = 2.0            # what the LiDAR adds in the model
//! ina219_bus = "/dev/i2c-1"
//! ina219_address = 0x40
//! shunt_ohm = 0.1
//!
//! [odometry]               # TurtleBot3 Burger defaults
//! wheel_radius_m = 0.033
//! wheel_separation_m = 0.160
//! ticks_per_rev = 4096
//!
//! [opencr]                 # DYNAMIXEL 2.0 on /dev/ttyACM0 at 1 Mbps
//! id = 200
//! left_addr = 136           # present position, i32; firmware versions differ
//! right_addr = 140
//! timeout_ms = 20
//!
//! [compass]
//! hard_iron_ut = [12.0, -3.5]  # from `umbra calibrate-compass`; absent: compass not used
//! field_reference_ut = [20.1, -41.3]  # clean field at calibration (horizontal, vertical)
//! offset_deg = 0.0             # magnetic declination + mount offset
//! field_tolerance = 0.08       # accepted deviation of the horizontal field strength
//!
//! [method_a]                   # the geometric pipeline (docs/method-a.md)
//! enabled = true
//! drop_fraction = 0.05         # oldest share of the cloud dropped every revolution
//! clear_margin_m = 0.15        # forget points the rays pass beyond by this + 3 % (0: never)
//! clear_beyond_rays = 4        # of the 4 rays round a point, how many pass beyond it (1–4)
//! eps_min_m = 0.08             # adaptive DBSCAN radius bounds
//! eps_max_m = 0.32
//! min_samples = 10
//! min_cluster_points = 20
//! merge_link_m = 1.3           # fragment centroid within this of its object's centroid
//! wall_area_m2 = 2.0
//! wall_aspect = 4.0
//! corner_min_deg = 35.0
//! door_max_angle_deg = 10.0
//! door_min_gap_m = 0.75
//! door_max_gap_m = 1.4
//! lidar_mount_x_m = -0.032     # LiDAR position on the robot (Burger)
//!
//! [method_b]                   # the learned pipeline (docs/method-b.md)
//! enabled = true
//! model = "/opt/umbra/other.onnx"  # absent: the compiled-in model (`--model` overrides)
//! precision = "fp32"          # which compiled-in model: "fp32" or "int8" (7 % fewer instructions
//!                              # on a Pi 3 with a 64-bit OS, slower elsewhere; docs/pi-budget.md)
//! conf = 0.25                  # class score a detection needs
//! iou = 0.7                    # suppression overlap
//! agnostic_nms = true          # one report per object whatever the classes
//! max_range_m = 4.0            # range of the raster's last row: must match the training data
//! threads = 1                  # tract worker threads
//! schedule = "auto"            # "inline" (in the frame), "worker" (its own thread); auto:
//!                              # worker on a Pi 3 when live, else inline (docs/pi-budget.md)
//! every = 1                    # in the frame: Method B in one frame of this many
//! mirror = false               # a second look at the mirrored raster, fused (twice the time)
//! seam = "fixed"               # the raster's first column: "fixed" (forward) or "quiet" (the
//!                              # longest unbroken wall); absent: what the model file declares
//!                              # (its `umbra.seam` metadata), else "fixed"
//! deskew = false               # boxes read where the sweep read them (models trained on
//!                              # `umbra-sim dataset --deskew` labels); false: the middle's pose;
//!                              # absent: the file's `umbra.deskew`, else false
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

use drivers::lds01::AssemblerConfig;
use drivers::opencr::OpencrConfig;
use perception::method_a::MethodAConfig;
use serde::Deserialize;

mod pose;
mod views;
mod world;

pub use pose::{CompassSettings, OdometrySettings, PoseSettings};
pub use world::WorldSettings;

/// Checksum policy as written in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ChecksumSetting {
    /// Drop bad packets.
    #[default]
    Verify,
    /// Keep and count bad packets.
    Count,
}

/// `[lidar]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LidarSettings {
    /// Checksum policy.
    pub checksum: ChecksumSetting,
    /// Shortest valid range, metres.
    pub min_range_m: f32,
    /// Longest valid range, metres.
    pub max_range_m: f32,
    /// Silence before a partial revolution is handed out, milliseconds.
    pub stale_after_ms: u64,
}

impl Default for LidarSettings {
    fn default() -> Self {
        let a = AssemblerConfig::default();
        LidarSettings {
            checksum: ChecksumSetting::Verify,
            min_range_m: a.min_range_m,
            max_range_m: a.max_range_m,
            stale_after_ms: a.stale_after_us / 1000,
        }
    }
}

/// The longest `[runtime] deadline_ms` accepted: no frame of a replay or a test is degraded for
/// time under it, whatever the host's load (`docs/runtime.md`, Replay).
pub const MAX_DEADLINE_MS: f64 = 10_000.0;

/// `[runtime]`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RuntimeSettings {
    /// Per-frame deadline, milliseconds.
    pub deadline_ms: f64,
    /// Per-stage budgets.
    pub budget_ms: StageBudgets,
    /// How the frame loop's thread is scheduled.
    pub scheduling: Scheduling,
    /// Its `SCHED_FIFO` priority (1–99) when `scheduling = "fifo"`.
    pub fifo_priority: u8,
}

impl Default for RuntimeSettings {
    fn default() -> Self {
        RuntimeSettings {
            deadline_ms: 250.0,
            budget_ms: StageBudgets::default(),
            scheduling: Scheduling::Normal,
            fifo_priority: 20,
        }
    }
}

/// `[runtime] scheduling`: the frame loop's thread under the kernel's default time sharing,
/// or real-time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Scheduling {
    /// Time shared with every other process (`SCHED_OTHER`).
    #[default]
    Normal,
    /// `SCHED_FIFO` at `fifo_priority`, memory locked: other load cannot delay a frame. Needs
    /// root, `CAP_SYS_NICE` or an RLIMIT_RTPRIO (the systemd unit sets it); without it the run goes on at
    /// normal priority and says so.
    Fifo,
}

/// `[runtime.budget_ms]`: each stage's budget, ms; unset ones are a share of the deadline.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct StageBudgets {
    /// Ingest (4 % of the deadline).
    pub ingest: Option<f64>,
    /// Pose (8 %: scan matching, projected up to 18 ms a frame on a Pi 3).
    pub pose: Option<f64>,
    /// Method A (26 %).
    pub method_a: Option<f64>,
    /// Method B (56 %).
    pub method_b: Option<f64>,
    /// Output (6 %).
    pub output: Option<f64>,
}

/// `[opencr]`: where the OpenCR firmware keeps the wheel positions (firmware versions differ).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OpencrSettings {
    /// DYNAMIXEL id of the board.
    pub id: u8,
    /// Control-table address of the left wheel's present position (i32).
    pub left_addr: u16,
    /// Control-table address of the right wheel's present position (i32).
    pub right_addr: u16,
    /// Longest wait for an answer, ms.
    pub timeout_ms: u64,
}

impl Default for OpencrSettings {
    fn default() -> Self {
        let d = OpencrConfig::default();
        OpencrSettings {
            id: d.id,
            left_addr: d.left_addr,
            right_addr: d.right_addr,
            timeout_ms: d.timeout.as_millis() as u64,
        }
    }
}

/// `[method_a]`: the geometric pipeline's main settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MethodASettings {
    /// Run Method A at all.
    pub enabled: bool,
    /// Share of the cloud dropped (oldest first) every revolution.
    pub drop_fraction: f32,
    /// Points the rays around their bearing pass beyond by this (plus 3 % of their range)
    /// are forgotten, m; 0: only aging forgets (`perception::cloud`).
    pub clear_margin_m: f32,
    /// Of the four rays around a point's bearing, how many must return from beyond it for it
    /// to be forgotten, the others returning nothing (1–4; 4: a ray that returned nothing says
    /// nothing; `perception::cloud`): legs that walked past a doorway are forgotten.
    pub clear_beyond_rays: u8,
    /// Smallest DBSCAN radius, m.
    pub eps_min_m: f32,
    /// Largest DBSCAN radius, m.
    pub eps_max_m: f32,
    /// Neighbours of a core point.
    pub min_samples: u16,
    /// Smallest cluster kept.
    pub min_cluster_points: u16,
    /// Fragment merge distance, m.
    pub merge_link_m: f32,
    /// Wall area threshold, m².
    pub wall_area_m2: f32,
    /// Wall aspect threshold.
    pub wall_aspect: f32,
    /// Corner angle, degrees.
    pub corner_min_deg: f32,
    /// Door: largest angle between the two wall segments, degrees.
    pub door_max_angle_deg: f32,
    /// Door: narrowest gap, m.
    pub door_min_gap_m: f32,
    /// Door: widest gap, m.
    pub door_max_gap_m: f32,
    /// LiDAR position on the robot, forward, m.
    pub lidar_mount_x_m: f32,
    /// LiDAR position on the robot, left, m.
    pub lidar_mount_y_m: f32,
}

impl Default for MethodASettings {
    fn default() -> Self {
        let d = MethodAConfig::default();
        MethodASettings {
            enabled: true,
            drop_fraction: d.cloud.drop_fraction,
            clear_margin_m: d.cloud.clear_margin_m,
            clear_beyond_rays: d.cloud.clear_beyond_rays,
            eps_min_m: d.dbscan.eps_min_m,
            eps_max_m: d.dbscan.eps_max_m,
            min_samples: d.dbscan.min_samples,
            min_cluster_points: d.dbscan.min_cluster_points,
            merge_link_m: d.merge.link_m,
            wall_area_m2: d.walls.wall_area_m2,
            wall_aspect: d.walls.wall_aspect,
            corner_min_deg: d.walls.corner_min_deg,
            door_max_angle_deg: d.doors.max_angle_deg,
            door_min_gap_m: d.doors.min_gap_m,
            door_max_gap_m: d.doors.max_gap_m,
            lidar_mount_x_m: -0.032,
            lidar_mount_y_m: 0.0,
        }
    }
}

/// `[method_b]`: the learned pipeline's settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MethodBSettings {
    /// Run Method B at all.
    pub enabled: bool,
    /// An ONNX file instead of the compiled-in model.
    pub model: Option<PathBuf>,
    /// Which compiled-in model when there is no file: fp32 or int8.
    pub precision: crate::runner::Precision,
    /// Score threshold.
    pub conf: f32,
    /// Suppression IoU.
    pub iou: f32,
    /// Class-agnostic suppression.
    pub agnostic_nms: bool,
    /// Range of the raster's last row, m.
    pub max_range_m: f32,
    /// tract worker threads.
    pub threads: usize,
    /// In the frame or on its own thread.
    pub schedule: crate::runner::Schedule,
    /// In the frame: Method B in one frame of this many (1: every frame).
    pub every: u32,
    /// A second look at the mirrored raster, its boxes fused with the first's
    /// (`perception::mirror_look`).
    pub mirror: bool,
    /// Where the raster starts (`perception::seam`): the rule the model was trained with.
    /// `None`: what the model file declares (`models::conventions`), else bin 0.
    pub seam: Option<crate::runner::Seam>,
    /// Boxes read as the sweep read them (`perception::sweep`): the rule the model's labels
    /// were drawn with. `None`: what the model file declares, else the middle's pose.
    pub deskew: Option<bool>,
}

impl Default for MethodBSettings {
    fn default() -> Self {
        let d = perception::yolo::DecodeConfig::RUNTIME;
        MethodBSettings {
            enabled: true,
            model: None,
            precision: crate::runner::Precision::Fp32,
            conf: d.conf,
            iou: d.iou,
            agnostic_nms: d.agnostic,
            max_range_m: perception::raster::RasterConfig::default().max_range_m,
            threads: 1,
            schedule: crate::runner::Schedule::Auto,
            every: 1,
            mirror: false,
            seam: None,
            deskew: None,
        }
    }
}

/// `Ok` when `v` is a finite number in `[lo, hi]`; else the message naming `section.name`.
fn within(section: &str, name: &str, v: f32, lo: f32, hi: f32) -> Result<(), String> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(format!(
            "{section}.{name} = {v}: must be within [{lo}, {hi}]"
        ))
    }
}

/// The whole configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    /// LiDAR settings.
    pub lidar: LidarSettings,
    /// Loop settings.
    pub runtime: RuntimeSettings,
    /// Wheel geometry.
    pub odometry: OdometrySettings,
    /// How the pose is kept.
    pub pose: PoseSettings,
    /// OpenCR control table.
    pub opencr: OpencrSettings,
    /// Compass calibration and gates.
    pub compass: CompassSettings,
    /// Method A.
    pub method_a: MethodASettings,
    /// Method B.
    pub method_b: MethodBSettings,
    /// Power budget and source.
    pub power: crate::power::PowerSettings,
    /// The world model.
    pub world: WorldSettings,
}

/// A configuration error, naming the file and field.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigError {
    /// The file (or `<defaults>`).
    pub file: PathBuf,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "configuration {}: {}", self.file.display(), self.message)
    }
}

impl std::error::Error for ConfigError {}

impl Config {
    /// Reads and validates `path`.
    pub fn load(path: &Path) -> Result<Config, ConfigError> {
        let err = |message: String| ConfigError {
            file: path.to_owned(),
            message,
        };
        let text = std::fs::read_to_string(path).map_err(|e| err(format!("cannot read: {e}")))?;
        let cfg: Config = toml::from_str(&text).map_err(|e| err(e.to_string()))?;
        cfg.validate().map_err(err)?;
        Ok(cfg)
    }

    /// Checks every setting; the message names the field.
    pub fn validate(&self) -> Result<(), String> {
        let l = &self.lidar;
        if !(l.min_range_m.is_finite() && l.min_range_m >= 0.0) {
            return Err(format!(
                "lidar.min_range_m = {}: must be ≥ 0",
                l.min_range_m
            ));
        }
        if !(l.max_range_m.is_finite() && l.max_range_m > l.min_range_m && l.max_range_m <= 65.535)
        {
            return Err(format!(
                "lidar.max_range_m = {}: must be above lidar.min_range_m ({}) and at most 65.535",
                l.max_range_m, l.min_range_m
            ));
        }
        if !(50..=10_000).contains(&l.stale_after_ms) {
            return Err(format!(
                "lidar.stale_after_ms = {}: must be within 50..=10000",
                l.stale_after_ms
            ));
        }
        if let Some(v) = self.world.phantom_threshold {
            within("world", "phantom_threshold", v, 0.0, 1.0)?;
        }
        if let Some(v) = self.world.min_likelihood {
            within("world", "min_likelihood", v, 0.0, 1.0)?;
        }
        within(
            "world",
            "desk_min_likelihood",
            self.world.desk_min_likelihood,
            0.0,
            1.0,
        )?;
        let a = &self.method_a;
        let within = |name: &str, v: f32, lo: f32, hi: f32| within("method_a", name, v, lo, hi);
        within("drop_fraction", a.drop_fraction, 0.0, 1.0)?;
        within("clear_margin_m", a.clear_margin_m, 0.0, 10.0)?;
        within(
            "clear_beyond_rays",
            f32::from(a.clear_beyond_rays),
            1.0,
            4.0,
        )?;
        within("eps_min_m", a.eps_min_m, 0.01, 2.0)?;
        within("eps_max_m", a.eps_max_m, a.eps_min_m, 2.0)?;
        within("merge_link_m", a.merge_link_m, 0.0, 5.0)?;
        within("wall_area_m2", a.wall_area_m2, 0.0, 100.0)?;
        within("wall_aspect", a.wall_aspect, 1.0, 1000.0)?;
        within("corner_min_deg", a.corner_min_deg, 0.0, 90.0)?;
        within("door_max_angle_deg", a.door_max_angle_deg, 0.0, 90.0)?;
        within("door_min_gap_m", a.door_min_gap_m, 0.0, 10.0)?;
        within("door_max_gap_m", a.door_max_gap_m, a.door_min_gap_m, 10.0)?;
        within("lidar_mount_x_m", a.lidar_mount_x_m, -1.0, 1.0)?;
        within("lidar_mount_y_m", a.lidar_mount_y_m, -1.0, 1.0)?;
        if !(1..=1000).contains(&a.min_samples) {
            return Err(format!(
                "method_a.min_samples = {}: must be within 1..=1000",
                a.min_samples
            ));
        }
        if !(1..=8192).contains(&a.min_cluster_points) {
            return Err(format!(
                "method_a.min_cluster_points = {}: must be within 1..=8192",
                a.min_cluster_points
            ));
        }
        let b = &self.method_b;
        let within_b = |name: &str, v: f32, lo: f32, hi: f32| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(format!(
                    "method_b.{name} = {v}: must be within [{lo}, {hi}]"
                ))
            }
        };
        within_b("conf", b.conf, 0.0, 1.0)?;
        within_b("iou", b.iou, 0.0, 1.0)?;
        within_b("max_range_m", b.max_range_m, 0.5, 65.0)?;
        if !(1..=10).contains(&b.every) {
            return Err(format!(
                "method_b.every = {}: must be within 1..=10",
                b.every
            ));
        }
        if !(1..=64).contains(&b.threads) {
            return Err(format!(
                "method_b.threads = {}: must be within 1..=64",
                b.threads
            ));
        }
        if !(1..=99).contains(&self.runtime.fifo_priority) {
            return Err(format!(
                "runtime.fifo_priority = {}: must be within 1..=99",
                self.runtime.fifo_priority
            ));
        }
        let d = self.runtime.deadline_ms;
        if !(d.is_finite() && d > 0.0 && d <= MAX_DEADLINE_MS) {
            return Err(format!(
                "runtime.deadline_ms = {d}: must be within (0, {MAX_DEADLINE_MS}]"
            ));
        }
        let b = self.budgets();
        let given = &self.runtime.budget_ms;
        for (name, v) in [
            ("ingest", given.ingest),
            ("pose", given.pose),
            ("method_a", given.method_a),
            ("method_b", given.method_b),
            ("output", given.output),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0 && v <= d)
            {
                return Err(format!(
                    "runtime.budget_ms.{name} = {v}: must be within (0, deadline_ms = {d}]"
                ));
            }
        }
        let sum = b.ingest_ms + b.pose_ms + b.method_a_ms + b.method_b_ms + b.output_ms;
        if sum > d * (1.0 + 1e-9) {
            return Err(format!(
                "runtime.budget_ms: the stage budgets add up to {sum} ms, over runtime.deadline_ms = {d}"
            ));
        }
        self.power.validate()?;
        Ok(())
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use drivers::lds01::Lds01Config;

    #[test]
    fn defaults_are_valid() {
        Config::default().validate().unwrap();
        assert_eq!(Config::default().lds01(), Lds01Config::default());
    }

    #[test]
    fn default_budgets_share_the_deadline_and_fit_a_pi_3() {
        let b = Config::default().budgets();
        let sum = b.ingest_ms + b.pose_ms + b.method_a_ms + b.method_b_ms + b.output_ms;
        assert!(
            (sum - b.deadline_ms).abs() < 1e-9,
            "{sum} of {}",
            b.deadline_ms
        );
        // docs/pi-budget.md: scan matching projects up to 18 ms a frame on a Pi 3 (32-bit),
        // Method A up to 23 ms: their defaults must hold the slow end.
        assert!(b.pose_ms >= 18.0 && b.method_a_ms >= 23.0, "{b:?}");
        // A share set in the file replaces the default; the others keep theirs.
        let c: Config = toml::from_str("[runtime.budget_ms]\npose = 7.0\n").unwrap();
        assert_eq!(c.budgets().pose_ms, 7.0);
        assert_eq!(c.budgets().method_a_ms, b.method_a_ms);
    }

    #[test]
    fn parse_and_reject() {
        let cfg: Config =
            toml::from_str("[lidar]\nchecksum = \"count\"\nmax_range_m = 4.2\n").unwrap();
        assert_eq!(cfg.lidar.checksum, ChecksumSetting::Count);
        cfg.validate().unwrap();
        assert!(toml::from_str::<Config>("[lidar]\nchecksum = \"maybe\"\n").is_err());
        assert!(toml::from_str::<Config>("[lidar]\nmax_rnage_m = 4.2\n").is_err());
        let bad: Config = toml::from_str("[lidar]\nmin_range_m = 5.0\n").unwrap();
        assert!(bad.validate().unwrap_err().contains("lidar.max_range_m"));
        let bad: Config = toml::from_str("[method_a]\ndoor_max_gap_m = 0.5\n").unwrap();
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("method_a.door_max_gap_m")
        );
        // How many of the rays round a cloud point must return from beyond it: 1–4.
        let a: Config = toml::from_str("[method_a]\nclear_beyond_rays = 2\n").unwrap();
        a.validate().unwrap();
        assert_eq!(a.method_a().cloud.clear_beyond_rays, 2);
        assert_eq!(Config::default().method_a().cloud.clear_beyond_rays, 4);
        let bad: Config = toml::from_str("[method_a]\nclear_beyond_rays = 0\n").unwrap();
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("method_a.clear_beyond_rays")
        );
        let bad: Config = toml::from_str("[world]\nmin_likelihood = 1.5\n").unwrap();
        assert!(bad.validate().unwrap_err().contains("world.min_likelihood"));
        // Set, it reaches the track table with the compiled-in calibration; unset, the
        // default holds back what is right less than half the time while Method B runs.
        let w: Config = toml::from_str("[world]\nmin_likelihood = 0.6\n").unwrap();
        let t = w.world.tracks(true);
        assert_eq!(t.min_likelihood, 0.6);
        assert_ne!(
            t.calibration,
            perception::calibration::Calibration::IDENTITY
        );
        assert_eq!(Config::default().world.tracks(true).min_likelihood, 0.5);
        // Method A alone: nothing held back unless asked for.
        assert_eq!(Config::default().world.tracks(false).min_likelihood, 0.0);
        let w: Config = toml::from_str("[world]\nmin_likelihood = 0\n").unwrap();
        assert_eq!(w.world.tracks(true).min_likelihood, 0.0);
        let w: Config = toml::from_str("[world]\nmin_likelihood = 0.7\n").unwrap();
        assert_eq!(w.world.tracks(false).min_likelihood, 0.7);
        assert_eq!(
            Config::default().world.tracks(true).min_desk_likelihood,
            0.6
        );
        assert_eq!(Config::default().world.tracks(true).door_hold_hits, 20);
        // The report model: off unless a threshold below 1 is set.
        let model = models::report_model::REPORT_MODEL;
        assert!(model.is_some(), "no report model compiled in");
        assert_eq!(Config::default().world.tracks(true).report_model, None);
        let off: Config = toml::from_str("[world]\nphantom_threshold = 1.0\n").unwrap();
        assert_eq!(off.world.tracks(true).report_model, None);
        let set: Config = toml::from_str("[world]\nphantom_threshold = 0.7\n").unwrap();
        let m = set.world.tracks(true).report_model.expect("on at 0.7");
        assert_eq!((m.threshold, m.weights), (0.7, model.unwrap().weights));
        let bad: Config = toml::from_str("[world]\nphantom_threshold = -0.1\n").unwrap();
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("world.phantom_threshold")
        );
        assert_eq!(Config::default().world.tracks(true).appeared_settle_s, 3.0);
        let w: Config = toml::from_str("[world]\nappeared_settle_s = 0\n").unwrap();
        assert_eq!(w.world.tracks(true).appeared_settle_s, 0.0);
        assert_eq!(Config::default().world.tracks(true).seen_through_revs, 2);
        let w: Config = toml::from_str("[world]\nseen_through_revs = 0\n").unwrap();
        assert_eq!(w.world.tracks(true).seen_through_revs, 0);
        assert!(toml::from_str::<Config>("[world]\nseen_through_revs = 300\n").is_err());
        assert_eq!(Config::default().world.tracks(true).miss_min_returns, 2);
        let w: Config = toml::from_str("[world]\nmiss_min_returns = 3\n").unwrap();
        assert_eq!(w.world.tracks(true).miss_min_returns, 3);
        let w: Config = toml::from_str("[world]\nmiss_min_returns = 0\n").unwrap();
        assert_eq!(
            w.world.tracks(true).miss_min_returns,
            1,
            "a miss needs a return"
        );
        assert_eq!(Config::default().world.tracks(true).empty_revs, 1);
        let w: Config = toml::from_str("[world]\nempty_revs = 2\n").unwrap();
        assert_eq!(w.world.tracks(true).empty_revs, 2);
        let w: Config = toml::from_str("[world]\nempty_revs = 0\n").unwrap();
        assert_eq!(w.world.tracks(true).empty_revs, 1, "an empty place counts");
        assert_eq!(Config::default().world.tracks(true).cross_merge_m, 0.0);
        let w: Config = toml::from_str("[world]\ncross_merge_m = 0.25\n").unwrap();
        assert_eq!(w.world.tracks(true).cross_merge_m, 0.25);
        let w: Config = toml::from_str("[world]\nsingle_method_hits = 0\n").unwrap();
        assert_eq!(
            w.world.tracks(true).single_method_hits,
            1,
            "a report needs a hit"
        );
        let w: Config = toml::from_str("[world]\nsingle_method_hits = 12\n").unwrap();
        assert_eq!(w.world.tracks(true).single_method_hits, 12);
        let w: Config = toml::from_str("[world]\ndoor_hold_hits = 0\n").unwrap();
        assert_eq!(w.world.tracks(true).door_hold_hits, 0);
        let bad: Config = toml::from_str("[method_b]\nconf = 1.5\n").unwrap();
        assert!(bad.validate().unwrap_err().contains("method_b.conf"));
        let bad: Config = toml::from_str("[method_b]\nthreads = 0\n").unwrap();
        assert!(bad.validate().unwrap_err().contains("method_b.threads"));
        let bad: Config = toml::from_str("[method_a]\neps_min_m = nan\n").unwrap();
        assert!(bad.validate().unwrap_err().contains("method_a.eps_min_m"));
        let bad: Config = toml::from_str("[runtime]\ndeadline_ms = -1.0\n").unwrap();
        assert!(bad.validate().unwrap_err().contains("runtime.deadline_ms"));
        let bad: Config = toml::from_str("[runtime]\nfifo_priority = 0\n").unwrap();
        assert!(
            bad.validate()
                .unwrap_err()
                .contains("runtime.fifo_priority")
        );
        let e = toml::from_str::<Config>("[runtime]\nscheduling = \"rr\"\n").unwrap_err();
        assert!(e.to_string().contains("scheduling"), "{e}");
        let ok: Config = toml::from_str("[runtime]\nscheduling = \"fifo\"\n").unwrap();
        assert_eq!(ok.runtime.scheduling, Scheduling::Fifo);
        ok.validate().unwrap();
    }
}
