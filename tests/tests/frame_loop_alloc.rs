//! The whole frame loop (`firmware::runner::run`: ingest → pose → Method A → Method B → JSON
//! line and statistics sinks, deadline histograms, overrun policy, power model) allocates nothing per frame after
//! warm-up, outside tract; with Method B on, the per-frame count is tract's constant. A counting
//! global allocator watches the loop's thread; the JSON sink marks the count at every line.

use std::io::Write;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use firmware::config::Config;
use firmware::odom::{PoseInput, PoseState};
use firmware::power::PowerMeter;
use firmware::runner::{self, MethodBSetup, RunOptions, Schedule, Seam, SecondsClock, Summary};
use firmware::sink::{FrameSink, JsonlSink, SceneSink, StatsSink};
use firmware::source::{LidarSource, Pacing};
use firmware::viz::{VizLink, VizSink};
use perception::scan_match::{ScanMatchConfig, ScanMatcher};
use umbra_tests::{allocations, counted};

#[global_allocator]
static ALLOC: umbra_tests::Counting = umbra_tests::Counting;

/// A JSON Lines sink that notes the allocation count at every line, in a buffer sized before.
struct Marks(Arc<std::sync::Mutex<Vec<u64>>>);

impl Write for Marks {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        if b.contains(&b'\n') {
            let mut m = self.0.lock().unwrap();
            assert!(m.len() < m.capacity(), "marks buffer too small");
            m.push(allocations());
        }
        Ok(b.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

const FRAMES: u64 = 40;
const WARM_UP: usize = 5;

fn per_frame(method_b: bool) -> Vec<u64> {
    per_frame_with(method_b.then_some(Schedule::Inline), None).0
}

fn per_frame_with(method_b: Option<Schedule>, viz: Option<VizLink>) -> (Vec<u64>, Summary) {
    per_frame_sim(method_b, false, Seam::Fixed, viz)
}

fn per_frame_sim(
    method_b: Option<Schedule>,
    mirror: bool,
    seam: Seam,
    viz: Option<VizLink>,
) -> (Vec<u64>, Summary) {
    let cfg = Config::default();
    let source = LidarSource::sim(3, 3);
    let cal = source.sim_calibration();
    let pose = PoseInput::new(PoseState::new(cfg.pose_filter(cal), cal.is_some()));
    per_frame_from(source, pose, method_b, mirror, seam, viz)
}

fn per_frame_from(
    mut source: LidarSource,
    pose: PoseInput,
    method_b: Option<Schedule>,
    mirror: bool,
    seam: Seam,
    viz: Option<VizLink>,
) -> (Vec<u64>, Summary) {
    let mut cfg = Config::default();
    // No frame may be degraded for time on a loaded host: a skipped stage would change the
    // counts, and a test that depends on timing is a bug.
    cfg.runtime.deadline_ms = firmware::config::MAX_DEADLINE_MS;
    let marks = Arc::new(std::sync::Mutex::new(Vec::with_capacity(
        FRAMES as usize + 8,
    )));
    let b = method_b.map(|schedule| MethodBSetup {
        model: Box::new(models::yolo::YoloModel::builtin(Default::default()).expect("model")),
        raster: cfg.method_b_raster(),
        decode: cfg.method_b_decode(),
        mount: cfg.lidar_mount(),
        schedule,
        every: 1,
        mirror,
        seam,
        deskew: false,
    });
    let mut sinks: Vec<Box<dyn FrameSink>> = vec![
        Box::new(JsonlSink(Box::new(Marks(marks.clone())))),
        Box::new(SceneSink(Box::new(std::io::sink()))),
        Box::new(StatsSink(Box::new(std::io::sink()))),
    ];
    if let Some(link) = viz {
        sinks.push(Box::new(VizSink::new(link)));
    }
    let opts = RunOptions {
        track_log: Default::default(),
        frames: Some(FRAMES),
        seconds: None,
        seconds_clock: SecondsClock::Wall,
        pacing: Pacing::Max,
        budgets: cfg.budgets(),
        power: Some(PowerMeter::model(&cfg.power, None)),
        power_budget_w: cfg.power.budget_w,
        sinks,
        stop: Arc::new(AtomicBool::new(false)),
        pose: Some(pose),
        method_a: Some((cfg.method_a(), cfg.lidar_mount())),
        method_b: b,
        world: Some(perception::tracks::TrackConfig::default()),
    };
    let mut summary = None;
    let stream = drivers::lidar::AnyLidar::new(source.model().expect("a LiDAR"), &cfg.lidar());
    counted(|| summary = Some(runner::run(&mut source, stream, opts).expect("run")));
    let summary = summary.unwrap();
    assert_eq!(summary.frames, FRAMES);
    let m = marks.lock().unwrap().clone();
    assert_eq!(m.len() as u64, FRAMES);
    (m.windows(2).map(|w| w[1] - w[0]).collect(), summary)
}

#[test]
fn frames_allocate_nothing_after_warm_up() {
    let d = per_frame(false);
    println!("allocations per frame, Method A only: {d:?}");
    assert!(
        d[WARM_UP..].iter().all(|&n| n == 0),
        "frames after warm-up allocated: {d:?}"
    );
}

#[test]
fn scan_matching_allocates_nothing_after_warm_up() {
    let cfg = Config::default();
    let source = LidarSource::sim(3, 3);
    let cal = source.sim_calibration();
    let mut pose = PoseInput::new(PoseState::new(cfg.pose_filter(cal), cal.is_some()));
    pose.scan_match = Some(Box::new(ScanMatcher::new(ScanMatchConfig::default())));
    let (d, _) = per_frame_from(source, pose, None, false, Seam::Fixed, None);
    println!("allocations per frame, Method A and scan matching: {d:?}");
    assert!(
        d[WARM_UP..].iter().all(|&n| n == 0),
        "frames after warm-up allocated: {d:?}"
    );
}

#[test]
fn with_method_b_only_tract_allocates_and_a_constant_amount() {
    let d = per_frame(true);
    println!("allocations per frame, Methods A and B: {d:?}");
    let steady = &d[WARM_UP..];
    assert!(
        steady.iter().all(|&n| n == steady[0]),
        "per-frame count not constant: {d:?}"
    );
    assert!(steady[0] > 0, "tract allocates per run");
}

#[test]
fn a_mirrored_second_look_allocates_only_a_second_run_of_tract() {
    let one = per_frame(true);
    let (two, _) = per_frame_sim(Some(Schedule::Inline), true, Seam::Fixed, None);
    println!("allocations per frame, Methods A and B with a mirrored second look: {two:?}");
    let steady = &two[WARM_UP..];
    assert!(
        steady.iter().all(|&n| n == steady[0]),
        "per-frame count not constant: {two:?}"
    );
    assert_eq!(
        steady[0],
        2 * one[WARM_UP],
        "one look: {one:?}, two: {two:?}"
    );
}

#[test]
fn the_quiet_seam_allocates_nothing_beyond_tract() {
    let one = per_frame(true);
    let (quiet, _) = per_frame_sim(Some(Schedule::Inline), false, Seam::Quiet, None);
    println!("allocations per frame, Methods A and B from the quiet seam: {quiet:?}");
    let steady = &quiet[WARM_UP..];
    assert!(
        steady.iter().all(|&n| n == one[WARM_UP]),
        "fixed seam: {one:?}, quiet: {quiet:?}"
    );
}

#[test]
fn with_method_b_on_its_own_thread_the_loop_allocates_nothing() {
    // A Pi 3's schedule: tract allocates on the worker's thread, the loop hands it one
    // pooled job buffer through one-slot channels.
    let (d, summary) = per_frame_with(Some(Schedule::Worker), None);
    println!(
        "allocations per frame, Method A + Method B on its thread ({} runs): {d:?}",
        summary.method_b_runs
    );
    assert!(
        d[WARM_UP..].iter().all(|&n| n == 0),
        "frames after warm-up allocated: {d:?}"
    );
    assert!(summary.method_b_worker);
    // However the threads interleave, the first three revolutions were handed over and the
    // run's end waits for what is in flight.
    assert!(summary.method_b_runs >= 1, "Method B ran on its thread");
    assert_eq!(summary.deadlines.method_b_skipped, 0);
}

#[test]
fn recording_costs_the_loop_no_allocation() {
    // The viz thread converts and writes (and allocates) on its own; the loop only fills
    // pooled frames (results, the raw LiDAR bytes and the odometry samples for replay).
    let path = std::env::temp_dir().join(format!("umbra-alloc-{}.mcap", std::process::id()));
    let link = VizLink::start(&firmware::viz::VizTargets {
        record: Some(path.clone()),
        live: None,
        meta: Default::default(),
    })
    .expect("recorder");
    let d = per_frame_with(None, Some(link)).0;
    println!("allocations per frame, Method A, recording: {d:?}");
    assert!(
        d[WARM_UP..].iter().all(|&n| n == 0),
        "frames after warm-up allocated: {d:?}"
    );
    assert!(
        std::fs::metadata(&path).unwrap().len() > 10_000,
        "frames were recorded"
    );
    std::fs::remove_file(&path).ok();
}

/// An LDS-01 on a pty, played at its real rate until `stop`.
fn play_lds01(mut master: serialport::TTYPort, stop: Arc<AtomicBool>) {
    use std::io::Write as _;
    let mut sim = sim::lds01::Lds01Sim::new(
        sim::world::World::random_room(5),
        sim::lds01::Lds01SimConfig::default(),
        5,
    );
    let start = std::time::Instant::now();
    let mut t = 0.0;
    let mut packet = [0u8; drivers::lds01::PACKET_LEN];
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        t += sim.slot_s();
        sim.emit_packet(&mut packet);
        let _ = master.write_all(&packet);
        let due = start + std::time::Duration::from_secs_f64(t);
        if let Some(wait) = due.checked_duration_since(std::time::Instant::now()) {
            std::thread::sleep(wait);
        }
    }
}

#[test]
fn serial_source_with_reader_threads_allocates_nothing_after_warm_up() {
    // The LiDAR's reader thread and the device thread (here a compass that always answers)
    // hand their data over through the fixed-capacity queues: the loop's thread allocates
    // nothing for them.
    let dir = std::env::temp_dir().join(format!("umbra-alloc-serial-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let link = dir.join("ttyLDS");
    let master = umbra_tests::plug_pty(&link, std::time::Duration::from_millis(5));
    let stop = Arc::new(AtomicBool::new(false));
    let player = {
        let stop = stop.clone();
        std::thread::spawn(move || play_lds01(master, stop))
    };
    let (source, _) = LidarSource::serial(
        link.to_str().unwrap(),
        Some(drivers::lidar::LidarModel::Lds01),
    )
    .expect("open the pty");
    let cfg = Config::default();
    let mut pose = PoseInput::new(PoseState::new(cfg.pose_filter(None), false));
    let compass: firmware::reader::CompassReader = Box::new(|| Ok([21.5, -3.2, 40.1]));
    pose.devices = Some(firmware::reader::DeviceReader::start(None, Some(compass)).unwrap());
    let d = per_frame_from(source, pose, None, false, Seam::Fixed, None).0;
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    player.join().unwrap();
    println!("allocations per frame, serial LDS-01 + device thread, Method A: {d:?}");
    assert!(
        d[WARM_UP..].iter().all(|&n| n == 0),
        "frames after warm-up allocated: {d:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
