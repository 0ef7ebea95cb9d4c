//! From a command line and a configuration to a running frame loop (`umbra run`, `umbra
//! replay`): the LiDAR source (a port, a file, the simulated robot), the pose input (the
//! OpenCR and compass on the device thread, an `--odom` file, a recording's samples, the
//! simulator's own), Method B's model, the frame sinks; then the end-of-run report.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use drivers::opencr::OpencrReader;
#[cfg(feature = "method-b")]
use models::yolo::{YoloModel, YoloOptions};
use perception::scan_match::{ScanMatchConfig, ScanMatcher};

use crate::cli::{Common, ReplayArgs, RunArgs, Speed};
pub use crate::cli::{EXIT_FAULT, EXIT_USAGE, Failure};
use crate::config::Config;
use crate::odom::{OdomFile, PoseInput, PoseState};
use crate::power::PowerMeter;
use crate::reader::open_compass;
use crate::runner::{self, MethodBSetup, RunOptions, SecondsClock, Summary};
use crate::sink::{FrameSink, JsonlSink, SceneSink, StatsSink};
use crate::source::{LidarSource, Pacing};

/// `umbra run`: a LiDAR port, or the built-in simulated robot when none is named.
pub fn run(args: RunArgs) -> Result<(), Failure> {
    let cfg = load_config(&args.common)?;
    let named = args.common.lidar_model.0;
    let mut source = match &args.lidar {
        Some(port) => {
            let (source, how) = LidarSource::serial(port, named).map_err(|m| (EXIT_FAULT, m))?;
            log::info!("LiDAR: {how}");
            source
        }
        None => simulated_robot(named, args.seed)?,
    };
    println!("umbra: {}", source.describe());
    let opencr = match &args.opencr {
        Some(p) => match OpencrReader::open(p, cfg.opencr()) {
            Ok(r) => Some(r),
            Err(e) => {
                log::warn!("{e}: no wheel encoders from that port");
                None
            }
        },
        None => {
            if args.lidar.is_some() {
                log::warn!("no --opencr named: no odometry, robot assumed still");
            }
            None
        }
    };
    let compass = args.compass.as_deref().and_then(open_compass);
    let compass_calibrated = cfg.compass.hard_iron_ut.is_some();
    if compass.is_some() && !compass_calibrated {
        log::warn!(
            "no [compass] hard_iron_ut in the configuration: compass readings ignored (run `umbra calibrate-compass`)"
        );
    }
    let pacing = match (source.is_simulated(), args.speed) {
        (true, Speed::RealTime) => Pacing::RealTime,
        (true, Speed::Max) => Pacing::Max,
        (false, speed) => {
            if speed == Speed::Max {
                log::warn!(
                    "--speed max applies to the simulated robot only: the port paces itself"
                );
            }
            Pacing::Max // the port paces itself
        }
    };
    let from_sim = opencr.is_none() && source.is_simulated();
    let pose = if from_sim {
        let cal = source.sim_calibration();
        match cal {
            Some((h, _)) => log::info!(
                "simulated compass calibrated by a two-turn spin: hard iron ({:.2}, {:.2}) µT",
                h[0],
                h[1]
            ),
            None => log::warn!("simulated compass calibration failed: heading from odometry only"),
        }
        let p = PoseInput::new(PoseState::new(cfg.pose_filter(cal), cal.is_some()));
        if let Some(c) = compass {
            // A real compass beside the simulated robot: it reads a real field, not
            // the simulated one, so it is left out.
            drop(c);
            log::warn!("--compass ignored: the simulated robot carries its own compass");
        }
        Some(p)
    } else if opencr.is_some() || compass.is_some() {
        // The OpenCR and/or compass, polled by the device thread.
        let use_compass = compass.is_some() && compass_calibrated;
        let mut p = PoseInput::new(PoseState::new(cfg.pose_filter(None), use_compass));
        p.devices =
            Some(crate::reader::DeviceReader::start(opencr, compass).map_err(|m| (EXIT_FAULT, m))?);
        Some(p)
    } else {
        None
    };
    run_loop(
        &mut source,
        &cfg,
        &args.common,
        pacing,
        SecondsClock::Wall,
        pose,
    )
}

/// `umbra replay`: a raw capture, an MCAP recording of ours or a CARMEN log.
pub fn replay(args: ReplayArgs) -> Result<(), Failure> {
    let cfg = load_config(&args.common)?;
    let named = args.common.lidar_model.0;
    let (mut source, how, recorded) = open_replay(&args.capture, named)?;
    log::info!("LiDAR: {how}");
    if source.model().is_none() && args.odom.is_some() {
        return Err((
            EXIT_USAGE,
            format!(
                "--odom: {} is a CARMEN log, which carries its own odometry",
                args.capture.display()
            ),
        ));
    }
    println!("umbra: {}", source.describe());
    let pose = match (&args.odom, recorded) {
        (None, Some((samples, bad, cal))) => {
            // The recording's own odometry, with the simulated compass's calibration if
            // it carried one, else the configuration's.
            let use_compass = cal.is_some() || cfg.compass.hard_iron_ut.is_some();
            log::info!(
                "odometry: {} samples recorded in {}",
                samples.len(),
                args.capture.display()
            );
            let mut p = PoseInput::new(PoseState::new(cfg.pose_filter(cal), use_compass));
            p.state.encoder_errors = bad;
            p.scheduled = samples;
            Some(p)
        }
        (Some(path), _) => {
            let file = OdomFile::open(path).map_err(|m| (EXIT_USAGE, m))?;
            let use_compass = cfg.compass.hard_iron_ut.is_some();
            if !use_compass {
                log::warn!(
                    "no [compass] hard_iron_ut in the configuration: compass readings ignored, heading from odometry only (run `umbra calibrate-compass`)"
                );
            }
            let mut p = PoseInput::new(PoseState::new(cfg.pose_filter(None), use_compass));
            p.file = Some(file);
            Some(p)
        }
        // A log's odometry comes from its own lines, through the frame loop.
        (None, None) if source.model().is_none() => {
            Some(PoseInput::new(PoseState::new(cfg.pose_filter(None), false)))
        }
        (None, None) => None,
    };
    let pacing = match args.speed {
        Speed::Max => Pacing::Max,
        Speed::RealTime => Pacing::RealTime,
    };
    run_loop(
        &mut source,
        &cfg,
        &args.common,
        pacing,
        SecondsClock::Sensor,
        pose,
    )
}

/// The built-in simulated robot (no `--lidar` named).
#[cfg(feature = "sim")]
fn simulated_robot(
    named: Option<drivers::lidar::LidarModel>,
    seed: u64,
) -> Result<LidarSource, Failure> {
    if named.is_some_and(|m| m != drivers::lidar::LidarModel::Lds01) {
        return Err((
            EXIT_USAGE,
            "--lidar-model: the built-in simulated robot carries an LDS-01 (emit other models with `umbra-sim capture --model`)".into(),
        ));
    }
    Ok(LidarSource::sim(seed, seed))
}

/// Built without the simulated robot: a LiDAR must be named.
#[cfg(not(feature = "sim"))]
fn simulated_robot(
    _named: Option<drivers::lidar::LidarModel>,
    _seed: u64,
) -> Result<LidarSource, Failure> {
    Err((
        EXIT_USAGE,
        "no --lidar named, and this umbra was built without the simulated robot (feature sim)"
            .into(),
    ))
}

/// Odometry lines and compass calibration a recording carried.
type Recorded = Option<(
    Vec<(u64, crate::odom::OdomRecord)>,
    u64,
    Option<([f32; 2], [f32; 2])>,
)>;

/// The replay source: an MCAP recording of umbra's (its LiDAR bytes, plus its odometry when it
/// has any) or a raw capture.
fn open_replay(
    path: &std::path::Path,
    named: Option<drivers::lidar::LidarModel>,
) -> Result<(LidarSource, String, Recorded), Failure> {
    #[cfg(feature = "viz")]
    if crate::recording::is_mcap(path) {
        let mut rec = crate::recording::read(path).map_err(|m| (EXIT_USAGE, m))?;
        if let Some(s) = &rec.source {
            log::info!("recording of: {s}");
        }
        let (source, how) = LidarSource::recorded(&mut rec, named).map_err(|m| (EXIT_USAGE, m))?;
        let mut odometry = std::mem::take(&mut rec.odometry);
        if source.model().is_none() {
            // A log's odometry lines are in the recorded text: the log reader makes them again.
            odometry.clear();
        }
        let recorded =
            (!odometry.is_empty()).then_some((odometry, rec.bad_odometry, rec.compass_calibration));
        return Ok((source, how, recorded));
    }
    #[cfg(not(feature = "viz"))]
    if path.extension().is_some_and(|e| e == "mcap") {
        log::warn!(
            "{}: this umbra was built without the viz feature and cannot read MCAP; replaying the file as raw bytes",
            path.display()
        );
    }
    if named.is_none() && is_carmen(path) {
        let text = crate::carmen::read_log(path).map_err(|m| (EXIT_USAGE, m))?;
        let source = LidarSource::log(path, text);
        return Ok((
            source,
            "a CARMEN log (FLASER scans, ODOM poses)".into(),
            None,
        ));
    }
    let (source, how) = LidarSource::capture(path, named).map_err(|m| (EXIT_USAGE, m))?;
    Ok((source, how, None))
}

/// Whether `path` holds a CARMEN log (gzip-compressed or not), from its first bytes.
fn is_carmen(path: &std::path::Path) -> bool {
    use std::io::Read as _;
    let Ok(file) = File::open(path) else {
        return false;
    };
    let mut head = Vec::with_capacity(4096);
    let mut raw = [0u8; 2];
    let gz = File::open(path)
        .and_then(|mut f| f.read_exact(&mut raw))
        .is_ok()
        && raw == [0x1F, 0x8B];
    let read = if gz {
        flate2::read::MultiGzDecoder::new(file)
            .take(4096)
            .read_to_end(&mut head)
    } else {
        file.take(4096).read_to_end(&mut head)
    };
    read.is_ok() && crate::carmen::looks_like_carmen(&head)
}

/// The configuration named by `--config`, or the defaults.
pub fn load_config(common: &Common) -> Result<Config, Failure> {
    match &common.config {
        Some(path) => Config::load(path).map_err(|e| (EXIT_USAGE, e.to_string())),
        None => Ok(Config::default()),
    }
}

/// Builds the frame loop's options from the configuration and the command line, runs it and
/// prints the report.
fn run_loop(
    source: &mut LidarSource,
    cfg: &Config,
    common: &Common,
    pacing: Pacing,
    seconds_clock: SecondsClock,
    pose: Option<PoseInput>,
) -> Result<(), Failure> {
    if let Some(s) = common.seconds
        && !(s.is_finite() && s > 0.0)
    {
        return Err((
            EXIT_USAGE,
            format!("--seconds {s}: must be a positive number"),
        ));
    }
    let jsonl_to_stdout = common.jsonl.as_deref() == Some("-");
    let jsonl: Option<Box<dyn Write>> = match common.jsonl.as_deref() {
        None => None,
        Some("-") => Some(Box::new(std::io::stdout())),
        Some(path) => Some(Box::new(BufWriter::new(File::create(path).map_err(
            |e| (EXIT_USAGE, format!("--jsonl {path}: cannot create: {e}")),
        )?))),
    };
    // The human lines go to stdout, or to stderr when the JSON lines take stdout.
    let human = || -> Option<Box<dyn Write>> {
        match (common.quiet, jsonl_to_stdout) {
            (true, _) => None,
            (false, true) => Some(Box::new(std::io::stderr())),
            (false, false) => Some(Box::new(std::io::stdout())),
        }
    };
    if common.view && jsonl_to_stdout {
        return Err((
            EXIT_USAGE,
            "--view draws on the terminal: send --jsonl to a file, not stdout".into(),
        ));
    }
    // The live map takes the terminal's place of the per-frame lines.
    let scene = if common.view { None } else { human() };
    let stats = if common.verbose && !common.view {
        human()
    } else {
        None
    };
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed)) {
        log::warn!("cannot install the Ctrl-C handler ({e}); Ctrl-C will stop without a summary");
    }
    let mount = source.mount().unwrap_or_else(|| cfg.lidar_mount());
    if let Some(m) = source.mount() {
        log::info!(
            "laser mount from the log: {:.3} m forward of the robot's centre",
            m.x
        );
    }
    // Frames at the LiDAR's pace: a port, or a simulation or replay in real time.
    let live = pacing == Pacing::RealTime || !(source.is_file() || source.is_simulated());
    let mut method_b = load_method_b(cfg, common, live)?;
    // The world model's likelihood default depends on it (`config::world`).
    let b_runs = method_b.is_some();
    if let Some(b) = method_b.as_mut() {
        b.mount = mount;
    }
    let power = PowerMeter::start(&cfg.power).map_err(|e| (EXIT_USAGE, e))?;
    log::info!("power: {}", power.source());
    let mut sinks: Vec<Box<dyn FrameSink>> = Vec::new();
    if let Some(w) = jsonl {
        sinks.push(Box::new(JsonlSink(w)));
    }
    if let Some(w) = scene {
        sinks.push(Box::new(SceneSink(w)));
    }
    if let Some(w) = stats {
        sinks.push(Box::new(StatsSink(w)));
    }
    if let Some(v) = start_viz(common, source)? {
        sinks.push(v);
    }
    if let Some(v) = start_view(common)? {
        sinks.push(v);
    }
    if let Some(p) = &common.snapshot {
        crate::snapshot::check_path(p).map_err(|m| (EXIT_USAGE, format!("--snapshot {m}")))?;
        sinks.push(Box::new(crate::snapshot::SnapshotSink(p.clone())));
    }
    let mut pose = pose;
    if let Some(p) = pose.as_mut().filter(|_| cfg.pose.scan_match) {
        // The matcher uses the returns the LiDAR is trusted with (`[lidar] max_range_m`).
        p.scan_match = Some(Box::new(ScanMatcher::new(ScanMatchConfig {
            max_range_m: cfg.lidar.max_range_m,
            ..ScanMatchConfig::default()
        })));
        log::info!("pose: scan matching on (each revolution laid on a keyframe's)");
    }
    let opts = RunOptions {
        frames: common.frames,
        seconds: common.seconds,
        seconds_clock,
        pacing,
        budgets: cfg.budgets(),
        power: Some(power),
        power_budget_w: cfg.power.budget_w,
        sinks,
        stop,
        pose,
        method_a: cfg.method_a.enabled.then(|| (cfg.method_a(), mount)),
        method_b,
        world: cfg.world.enabled.then(|| cfg.world.tracks(b_runs)),
        track_log: crate::runner::TrackLog::create(common.track_log.as_deref())
            .map_err(|e| (EXIT_USAGE, e.to_string()))?,
    };
    let scheduling = crate::realtime::apply(cfg.runtime.scheduling, cfg.runtime.fifo_priority);
    log::info!("frame loop: {scheduling}");
    let summary = match source.model() {
        Some(model) => {
            let stream = drivers::lidar::AnyLidar::new(model, &cfg.lidar());
            runner::run(source, stream, opts)
        }
        None => {
            let window = cfg.lidar();
            let stream = crate::carmen::CarmenStream::new(
                window.min_range_m.unwrap_or(0.12),
                window.max_range_m.unwrap_or(3.5),
                cfg.odometry(),
            );
            runner::run(source, stream, opts)
        }
    }
    .map_err(|e| (EXIT_FAULT, format!("cannot write output: {e}")))?;
    print_summary(&summary);
    eprintln!("frame loop scheduling: {scheduling}");
    Ok(())
}

/// Opens the MCAP file and/or the live server (`--record`, `--live`).
#[cfg(feature = "viz")]
fn start_viz(common: &Common, source: &LidarSource) -> Result<Option<Box<dyn FrameSink>>, Failure> {
    if common.record.is_none() && common.live.is_none() {
        return Ok(None);
    }
    if let Some(p) = &common.record {
        crate::snapshot::check_path(p).map_err(|m| (EXIT_USAGE, format!("--record {m}")))?;
    }
    let targets = crate::viz::VizTargets {
        record: common.record.clone(),
        live: common.live,
        meta: source.recording_meta(),
    };
    let link = crate::viz::VizLink::start(&targets).map_err(|m| (EXIT_USAGE, m))?;
    if let (Some(port), Some(addr)) = (link.live_port(), common.live) {
        // Always said (not only in the log): with `--live HOST:0` this is how a client learns
        // the port the server bound.
        eprintln!(
            "umbra: live view on ws://{}:{port} (Foxglove: Open connection; from another machine use this host's address)",
            addr.ip()
        );
    }
    if let Some(p) = &common.record {
        log::info!("recording to {}", p.display());
    }
    Ok(Some(Box::new(crate::viz::VizSink::new(link))))
}

/// `--view`: the live map in the terminal.
#[cfg(feature = "view")]
fn start_view(common: &Common) -> Result<Option<Box<dyn FrameSink>>, Failure> {
    if !common.view {
        return Ok(None);
    }
    let sink = crate::term_view::ViewSink::start().map_err(|m| (EXIT_USAGE, m))?;
    Ok(Some(Box::new(sink)))
}

/// Built without the `view` feature: `--view` is an error.
#[cfg(not(feature = "view"))]
fn start_view(common: &Common) -> Result<Option<Box<dyn FrameSink>>, Failure> {
    if common.view {
        return Err((
            EXIT_USAGE,
            "--view: this umbra was built without the view feature".into(),
        ));
    }
    Ok(None)
}

/// Built without the `viz` feature: `--record` and `--live` are errors.
#[cfg(not(feature = "viz"))]
fn start_viz(
    common: &Common,
    _source: &LidarSource,
) -> Result<Option<Box<dyn FrameSink>>, Failure> {
    if common.record.is_some() || common.live.is_some() {
        return Err((
            EXIT_USAGE,
            "--record/--live: this umbra was built without the viz feature".into(),
        ));
    }
    Ok(None)
}

/// Built without Method B: says so once and runs Method A only.
#[cfg(not(feature = "method-b"))]
fn load_method_b(
    cfg: &Config,
    _common: &Common,
    _live: bool,
) -> Result<Option<MethodBSetup>, Failure> {
    if cfg.method_b.enabled {
        log::warn!("this umbra was built without Method B (feature method-b): Method A only");
    }
    Ok(None)
}

/// Loads Method B's model (`--model`, else `[method_b] model`, else the compiled-in one); a
/// bad file is a start-up error naming it (exit 2). `live`: frames come at the LiDAR's pace
/// (the schedule's `auto` needs it).
#[cfg(feature = "method-b")]
fn load_method_b(
    cfg: &Config,
    common: &Common,
    live: bool,
) -> Result<Option<MethodBSetup>, Failure> {
    if !cfg.method_b.enabled {
        if common.model.is_some() {
            log::warn!("--model given but [method_b] enabled = false: Method B stays off");
        }
        return Ok(None);
    }
    let opts = YoloOptions {
        threads: cfg.method_b.threads,
    };
    let path = common.model.as_deref().or(cfg.method_b.model.as_deref());
    let board = crate::power::Board::this(
        cfg.power.board,
        crate::power::device_tree_model().as_deref(),
    )
    .unwrap_or(crate::power::Board::Pi5);
    let int8 = cfg.method_b.precision == runner::Precision::Int8;
    let model =
        YoloModel::load_or_builtin_as(path, int8, opts).map_err(|e| (EXIT_USAGE, e.to_string()))?;
    let schedule = cfg.method_b.schedule.resolve(board, live);
    log::info!(
        "Method B: {}, {}",
        model.name(),
        match schedule {
            runner::Schedule::Worker => "on its own thread (frames do not wait for it)",
            _ => "in the frame",
        }
    );
    let (seam, deskew) = runner::drawing(
        model.name(),
        model.conventions(),
        cfg.method_b.seam,
        cfg.method_b.deskew,
    );
    Ok(Some(MethodBSetup {
        model: Box::new(model),
        raster: cfg.method_b_raster(),
        decode: cfg.method_b_decode(),
        mount: cfg.lidar_mount(),
        schedule,
        every: cfg.method_b.every,
        mirror: cfg.method_b.mirror,
        seam,
        deskew,
    }))
}

/// The end-of-run report on stderr: counts, faults and the deadline and power table.
fn print_summary(s: &Summary) {
    let f = &s.faults;
    eprintln!(
        "umbra: {} frames ({} complete) in {:.1} s sensor time, {:.1} s wall; stopped: {}",
        s.frames, s.complete, s.sensor_seconds, s.wall_seconds, s.stop_reason
    );
    eprintln!(
        "umbra: faults: bytes skipped {}, bad checksum {}, bad index {}, missing packets {}, \
         repeated packets {}, out-of-sequence bad packets {}, incomplete revolutions {}, \
         invalid readings {}, link lost {}, reopened {}, deadline misses {}",
        f.bytes_skipped,
        f.bad_checksum,
        f.bad_index,
        f.missing_packets,
        f.repeated_packets,
        f.out_of_sequence_bad_packets,
        f.incomplete_revolutions,
        s.invalid_readings,
        s.link.0,
        s.link.1,
        s.deadlines.missed
    );
    if s.walled_detections > 0 {
        eprintln!(
            "umbra: {} detections that cannot be furniture dropped (in or behind a wall, a piece of a wall, a round \"box\")",
            s.walled_detections
        );
    }
    if s.viz_dropped > 0 {
        eprintln!(
            "umbra: recording/live view dropped {} frames (its thread was behind)",
            s.viz_dropped
        );
    }
    if s.method_b_worker {
        eprintln!(
            "umbra: Method B on its own thread: {} runs in {} frames",
            s.method_b_runs, s.frames
        );
    }
    eprint!("{}", s.table());
}
