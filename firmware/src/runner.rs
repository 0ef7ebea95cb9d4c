//! The frame loop as it stands: ingest → pose → Method A → Method B → output. One frame per
//! LiDAR revolution.
//!
//! `timing_ms.ingest` is the time spent decoding the frame's bytes (not waiting for them).
//! Bytes are read into one fixed buffer ([`READ_CHUNK`] bytes), fed to the LDS-01 stream,
//! and each finished revolution becomes a frame: a statistics line, a JSON line, or both.
//! The pose is taken at the revolution's first ray (the output line's pose) and at its last,
//! so Method A de-skews the scan. Method B keeps the last three revolutions' bins and the
//! pose at the middle of each: its raster is the three, its boxes are placed from the middle
//! revolution's pose (the pose the training labels used). A B detection within
//! [`AGREE_M`] of an A object of the same class makes that object `AB`; the others are
//! reported as `B`.

use std::io::Write;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use std::collections::VecDeque;

use drivers::lidar::LidarFaults;

use crate::frames::FrameStream;
use perception::cloud::Scan;
use perception::geometry::{Point2, Pose2};
use perception::method_a::{MethodA, MethodAConfig};
use perception::raster::{RasterConfig, SCAN_COLUMNS, encode_chw_f32};
use perception::yolo::{ANCHORS, DecodeConfig, DecodeScratch, Detection, MAX_DETECTIONS, decode};

#[cfg(feature = "method-b")]
use models::yolo::YoloModel;

/// Built without Method B (`--no-default-features`): no model can exist.
#[cfg(not(feature = "method-b"))]
#[derive(Debug)]
pub enum YoloModel {}

#[cfg(not(feature = "method-b"))]
impl YoloModel {
    fn input_mut(&mut self) -> &mut [f32] {
        match *self {}
    }
    fn run<R>(&mut self, _f: impl FnOnce(&[f32]) -> R) -> Result<R, String> {
        match *self {}
    }
}

use crate::reader::{ClockMap, DeviceReader};

#[cfg(feature = "viz")]
pub use crate::viz::VizLink;

/// Built without recording and live view (`viz` feature off): no link can exist.
#[cfg(not(feature = "viz"))]
#[derive(Debug)]
pub enum VizLink {}

#[cfg(not(feature = "viz"))]
impl VizLink {
    fn send(&mut self, _fill: impl FnOnce(&mut VizFrameStub)) -> bool {
        match *self {}
    }
    fn dropped(&self) -> u64 {
        match *self {}
    }
    fn finish(self) -> Result<(), String> {
        match self {}
    }
}

/// What a frame would carry to the viz thread (stub of `viz::VizFrame`).
#[cfg(not(feature = "viz"))]
struct VizFrameStub {
    frame: u64,
    t: f64,
    pose: Pose2,
    mount: Pose2,
    ranges: [f32; SCAN_COLUMNS],
    objects: heapless::Vec<ObjectOut, 1>,
    walls: heapless::Vec<WallOut, 1>,
    doors: heapless::Vec<DoorOut, 1>,
    raw: heapless::Vec<u8, 1>,
    odom: heapless::Vec<OdomRecord, 1>,
}

#[cfg(feature = "viz")]
use crate::viz::VizFrame as VizFrameStub;

use crate::odom::{OdomFile, OdomRecord, PoseState};

use crate::deadline::{
    Budgets, DeadlineRecord, FrameTimes, Policy, PowerVerdict, SHRINK_DROP_FRACTION,
};
use crate::output::{
    DoorOut, FaultsOut, LidarOut, ObjectOut, OutputLine, PoseOut, StatsLine, TimingOut, WallOut,
};
use crate::power::PowerMeter;
use crate::source::{LidarSource, Pacing, SourceRead};

/// Bytes read from the source at a time (~0.2 revolution; a capture is read in these too).
pub const READ_CHUNK: usize = 512;

/// When the `--seconds` limit is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SecondsClock {
    /// Wall-clock time since start (live sources).
    Wall,
    /// Sensor-clock time (replay).
    Sensor,
}

/// Loop options.
pub struct RunOptions {
    /// Stop after this many frames.
    pub frames: Option<u64>,
    /// Stop after this many seconds.
    pub seconds: Option<f64>,
    /// Which clock `seconds` uses.
    pub seconds_clock: SecondsClock,
    /// Pacing.
    pub pacing: Pacing,
    /// The deadline and the stage budgets.
    pub budgets: Budgets,
    /// Where the watts come from (`None`: no power figures).
    pub power: Option<PowerMeter>,
    /// The power budget, W.
    pub power_budget_w: f64,
    /// JSON lines go here.
    pub jsonl: Option<Box<dyn Write>>,
    /// Statistics lines go here (`None`: quiet).
    pub stats: Option<Box<dyn Write>>,
    /// Set from outside (Ctrl-C) to stop cleanly.
    pub stop: Arc<AtomicBool>,
    /// Pose input; `None`: no odometry, the robot is assumed still.
    pub pose: Option<PoseInput>,
    /// Method A settings and the LiDAR's pose on the robot; `None`: Method A off.
    pub method_a: Option<(MethodAConfig, Pose2)>,
    /// Method B's model and settings; `None`: Method B off.
    pub method_b: Option<MethodBSetup>,
    /// Recording / live view (`--record`, `--live`).
    pub viz: Option<VizLink>,
    /// Where to draw the last frame when the run ends (`--snapshot`).
    pub snapshot: Option<std::path::PathBuf>,
}

/// Method B at run time: the loaded model and how to read its boxes.
pub struct MethodBSetup {
    /// The network, loaded and optimised at start-up.
    pub model: YoloModel,
    /// Raster settings (must match the training data's).
    pub raster: RasterConfig,
    /// Thresholds and suppression.
    pub decode: DecodeConfig,
    /// The LiDAR's pose on the robot.
    pub mount: Pose2,
}

/// Revolutions Method B's raster is made of.
pub const METHOD_B_HISTORY: usize = perception::raster::RASTER_C;

/// A Method B box this close (m) to a Method A object of the same class is the same object.
pub const AGREE_M: f32 = 0.3;

/// What the loop keeps between frames, allocated once at start-up.
struct FrameState {
    method_a: Box<MethodA>,
    /// The last three revolutions' ranges by bin (0 = not drawn), slot `n % 3` for the n-th;
    /// Method A reads the newest, Method B all three.
    history: [[f32; SCAN_COLUMNS]; METHOD_B_HISTORY],
    /// The robot's map pose at the middle of each of those revolutions.
    history_pose: [Pose2; METHOD_B_HISTORY],
    /// Revolutions put into the history.
    revolutions: u64,
    detections: heapless::Vec<Detection, MAX_DETECTIONS>,
    decode_scratch: Box<DecodeScratch>,
    method_b_errors: u64,
    /// Host time spent in frames (taken off the link clock).
    busy: Duration,
    /// When the loop started.
    start: Instant,
    /// The overrun policy's memory.
    policy: Policy,
    /// Stage histograms and counters.
    record: DeadlineRecord,
    /// Time it took to write the previous frame's line, ms.
    last_output_ms: f64,
    /// The pose of the last frame.
    last_pose: Pose2,
    /// Sum, count and peak of the power figures.
    power_sum: f64,
    power_n: u64,
    power_peak: f64,
    objects: Vec<ObjectOut>,
    walls: Vec<WallOut>,
    doors: Vec<DoorOut>,
    /// While recording: the LiDAR bytes read since the last frame the recorder took.
    pending_raw: Option<Box<heapless::Vec<u8, RECORD_RAW_BYTES>>>,
    /// Bytes that did not fit `pending_raw` (missing from the recording).
    raw_dropped: u64,
}

/// LiDAR bytes held for the recording between two recorded frames (16 KiB, over six LDS-01
/// revolutions: room for a few frames the recorder had to drop).
pub const RECORD_RAW_BYTES: usize = 16 * 1024;

/// Output capacity reserved at start-up (so that the loop does not allocate).
const OUT_CAPACITY: usize =
    perception::method_a::MAX_CANDIDATES + perception::doors::MAX_DOORS + MAX_DETECTIONS;

/// Samples queued from a live source before the frame they belong to, at most (20 Hz encoders
/// over 2 s; older ones are fed at once rather than dropped).
pub const ODOM_QUEUE: usize = 40;

/// Room for samples waiting in the pose input's queue: a live source's backlog plus a full
/// device-thread queue drained at once. Reserved at start-up; a sample that would grow it is
/// fed at once instead.
pub const POSE_QUEUE: usize = ODOM_QUEUE + crate::reader::DEVICE_QUEUE + 1;

/// Where the pose comes from.
pub struct PoseInput {
    /// The filter and its fault counters.
    pub state: PoseState,
    /// An `--odom` file, read in step with the frames.
    pub file: Option<OdomFile>,
    /// Samples from a live source (the simulator, the device thread), waiting for their frame.
    pub queue: VecDeque<OdomRecord>,
    /// The OpenCR and compass, polled by their own thread.
    pub devices: Option<DeviceReader>,
    /// Host time → LiDAR time, for the device thread's samples.
    pub clock: ClockMap,
    /// A recording's samples, each with the frame at which it became available
    /// ([`crate::recording`]), read at start-up.
    pub scheduled: Vec<(u64, OdomRecord)>,
    scheduled_next: usize,
}

/// Reads the compass once; the error names the device. Runs on the device thread.
pub type CompassReader = Box<dyn FnMut() -> Result<[f32; 3], String> + Send>;

impl PoseInput {
    /// A pose input fed by `state` alone, with room reserved for queued samples.
    pub fn new(state: PoseState) -> Self {
        PoseInput {
            state,
            file: None,
            queue: VecDeque::with_capacity(POSE_QUEUE),
            devices: None,
            clock: ClockMap::default(),
            scheduled: Vec::new(),
            scheduled_next: 0,
        }
    }

    /// Moves the device thread's samples into the queue, stamped on the LiDAR's clock
    /// (`start` is the run's host-clock origin). Before the first revolution maps the clocks
    /// a sample is stamped at `fallback`.
    fn take_device_samples(&mut self, start: Instant, fallback: f64) {
        while let Some(s) = self.devices.as_ref().and_then(DeviceReader::try_next) {
            let host_s = s.host.saturating_duration_since(start).as_secs_f64();
            let t = self.clock.sensor_time(host_s).unwrap_or(fallback);
            let r = OdomRecord {
                t,
                left_ticks: s.ticks.map(|(l, _)| i64::from(l)),
                right_ticks: s.ticks.map(|(_, r)| i64::from(r)),
                mag_ut: s.mag_ut,
            };
            self.enqueue(r);
        }
    }

    /// Puts a sample in the queue (never growing it: when full, the oldest is fed at once)
    /// and notes it for the recording.
    fn enqueue(&mut self, r: OdomRecord) {
        if self.queue.len() >= self.queue.capacity()
            && let Some(old) = self.queue.pop_front()
        {
            self.state.feed(&old);
        }
        self.state.note_available(&r);
        self.queue.push_back(r);
    }

    /// Lets `drain` append samples to the queue (the simulator's, a log's) and notes each for
    /// the recording.
    fn take_from(&mut self, drain: impl FnOnce(&mut VecDeque<OdomRecord>)) {
        let before = self.queue.len();
        drain(&mut self.queue);
        for k in before..self.queue.len() {
            let r = self.queue[k];
            self.state.note_available(&r);
        }
    }

    /// Makes a recording's samples available at the frames they were in the recorded run.
    fn take_scheduled(&mut self, frame: u64) {
        while let Some(&(f, r)) = self.scheduled.get(self.scheduled_next) {
            if f > frame {
                break;
            }
            self.scheduled_next += 1;
            self.enqueue(r);
        }
    }

    /// Encoder faults: the filter's (implausible ticks) plus failed polls.
    fn encoder_errors(&self) -> u64 {
        self.state.encoder_errors
            + self
                .devices
                .as_ref()
                .map_or(0, DeviceReader::encoder_errors)
    }

    /// Failed compass reads.
    fn compass_errors(&self) -> u64 {
        self.devices
            .as_ref()
            .map_or(0, DeviceReader::compass_errors)
    }

    /// Feeds every file or queued sample up to sensor time `t` and returns the pose at `t`.
    fn advance(&mut self, t: f64) -> Pose2 {
        if let Some(f) = self.file.as_mut() {
            f.advance(t, &mut self.state);
        }
        while let Some(r) = self.queue.front().copied() {
            if r.t > t && self.queue.len() <= ODOM_QUEUE {
                break;
            }
            self.state.feed(&r);
            self.queue.pop_front();
        }
        // The frame's time lies between two samples: interpolate to it.
        let next = self
            .file
            .as_ref()
            .and_then(|f| f.peek())
            .or(self.queue.front())
            .copied();
        self.state.pose_at(t, next.as_ref())
    }
}

/// What a run did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Frames (revolutions) handed out.
    pub frames: u64,
    /// Complete revolutions among them.
    pub complete: u64,
    /// Bytes read.
    pub bytes: u64,
    /// Final fault counters.
    pub faults: LidarFaults,
    /// Readings marked invalid.
    pub invalid_readings: u64,
    /// Link losses and reopens.
    pub link: (u64, u64),
    /// Sensor time covered, s.
    pub sensor_seconds: f64,
    /// Wall time, s.
    pub wall_seconds: f64,
    /// Why the run stopped.
    pub stop_reason: &'static str,
    /// Stage histograms, misses, degraded frames.
    pub deadlines: DeadlineRecord,
    /// The deadline and stage budgets.
    pub budgets: Option<Budgets>,
    /// The power verdict.
    pub power: PowerVerdict,
    /// Frames the recording / live view dropped (its thread was behind).
    pub viz_dropped: u64,
}

impl Summary {
    /// The deadline and power table of `interfaces.md` §4.
    pub fn table(&self) -> String {
        match &self.budgets {
            Some(b) => crate::deadline::table(&self.deadlines, b, &self.power),
            None => String::new(),
        }
    }
}

/// Runs the loop until a limit, the end of the source, or the stop flag.
pub fn run<S: FrameStream>(
    source: &mut LidarSource,
    mut stream: S,
    mut opts: RunOptions,
) -> Result<Summary, std::io::Error> {
    let mut buf = [0u8; READ_CHUNK];
    let start = Instant::now();
    let mut summary = Summary::default();
    let mut ingest = Duration::ZERO;
    // Host time spent processing frames (taken off the link clock).
    let mut state = FrameState {
        method_a: Box::new(MethodA::new()),
        history: [[0.0; SCAN_COLUMNS]; METHOD_B_HISTORY],
        history_pose: [Pose2::IDENTITY; METHOD_B_HISTORY],
        revolutions: 0,
        detections: heapless::Vec::new(),
        decode_scratch: Box::new(DecodeScratch::new()),
        method_b_errors: 0,
        busy: Duration::ZERO,
        start,
        policy: Policy::default(),
        record: DeadlineRecord::default(),
        last_output_ms: 0.0,
        last_pose: Pose2::IDENTITY,
        power_sum: 0.0,
        power_n: 0,
        power_peak: 0.0,
        objects: Vec::with_capacity(OUT_CAPACITY),
        walls: Vec::with_capacity(perception::walls::MAX_SEGMENTS),
        doors: Vec::with_capacity(perception::doors::MAX_DOORS),
        pending_raw: opts.viz.is_some().then(|| Box::new(heapless::Vec::new())),
        raw_dropped: 0,
    };
    if opts.viz.is_some()
        && let Some(p) = opts.pose.as_mut()
    {
        p.state.journal = Some(heapless::Vec::new());
    }

    let mut watch = LinkWatch::default();
    let reason = 'outer: loop {
        if opts.stop.load(Ordering::Relaxed) {
            break 'outer "stopped by signal";
        }
        if let Some(s) = opts.seconds {
            let elapsed = match opts.seconds_clock {
                SecondsClock::Wall => start.elapsed().as_secs_f64(),
                SecondsClock::Sensor => stream.sensor_time_s(),
            };
            if elapsed >= s {
                break 'outer "time limit";
            }
        }
        // The link clock for staleness: host time spent waiting for bytes, not time spent
        // processing frames (a slow frame leaves bytes queued, not the sensor silent). Files
        // have no silence at all: no clock.
        let link_us = |busy: Duration| start.elapsed().saturating_sub(busy).as_micros() as u64;
        let n = match source.read(&mut buf) {
            SourceRead::Data(n) => n,
            SourceRead::Idle => {
                watch.idle(source, &stream);
                if !source.is_file()
                    && stream.poll(link_us(state.busy)).is_some()
                    && emit_frame(
                        &stream,
                        source,
                        &mut opts,
                        &mut summary,
                        &mut ingest,
                        &mut state,
                    )?
                {
                    break 'outer "frame limit";
                }
                continue;
            }
            SourceRead::End => {
                if stream.finish().is_some() {
                    emit_frame(
                        &stream,
                        source,
                        &mut opts,
                        &mut summary,
                        &mut ingest,
                        &mut state,
                    )?;
                }
                break 'outer "end of input";
            }
            SourceRead::Lost(msg) => {
                log::warn!("{msg}; reopening with back-off");
                stream.link_reset();
                if let Some(p) = opts.pose.as_mut() {
                    // A replugged LiDAR starts a new clock.
                    p.clock.reset();
                }
                continue;
            }
            SourceRead::Reopened => {
                log::info!("LiDAR link reopened");
                continue;
            }
        };
        summary.bytes += n as u64;
        watch.data();
        if let Some(p) = state.pending_raw.as_mut() {
            let take = n.min(p.capacity() - p.len());
            let _ = p.extend_from_slice(&buf[..take]);
            if take < n {
                if state.raw_dropped == 0 {
                    log::warn!(
                        "recording: the recorder is behind; LiDAR bytes dropped from the recording (counted)"
                    );
                }
                state.raw_dropped += (n - take) as u64;
            }
        }
        if let Some(p) = opts.pose.as_mut() {
            p.take_from(|q| source.drain_odometry(q));
        }
        let mut input = &buf[..n.min(READ_CHUNK)];
        let now = (!source.is_file()).then(|| link_us(state.busy));
        loop {
            let t_feed = Instant::now();
            let done = stream.next_revolution(&mut input, now);
            ingest += t_feed.elapsed();
            if let Some(p) = opts.pose.as_mut() {
                // A log's odometry lines, up to the frame's scan.
                p.take_from(|q| {
                    stream.drain_odometry(q);
                });
            }
            if !done {
                break;
            }
            if let (Some(p), Some(host)) = (opts.pose.as_mut(), source.last_read_host()) {
                let host_s = host.saturating_duration_since(start).as_secs_f64();
                p.clock.observe(host_s, stream.sensor_time_s());
            }
            let limit = emit_frame(
                &stream,
                source,
                &mut opts,
                &mut summary,
                &mut ingest,
                &mut state,
            )?;
            if limit {
                break 'outer "frame limit";
            }
        }
        watch.after_feed(&stream, summary.frames);
        if opts.pacing == Pacing::RealTime {
            let ahead = stream.sensor_time_s() - start.elapsed().as_secs_f64();
            if ahead > 0.0 {
                std::thread::sleep(Duration::from_secs_f64(ahead.min(1.0)));
            }
        }
    };
    summary.faults = stream.faults();
    summary.link = source.link_counts();
    summary.sensor_seconds = stream.sensor_time_s();
    summary.wall_seconds = start.elapsed().as_secs_f64();
    summary.stop_reason = reason;
    if let Some(path) = opts.snapshot.as_deref() {
        let cloud: Vec<Point2> = state.method_a.cloud().iter().copied().collect();
        let caption = format!(
            "umbra, frame {}, t {:.1} s: {} objects, {} walls, {} doors",
            summary.frames.saturating_sub(1),
            summary.sensor_seconds,
            state.objects.len(),
            state.walls.len(),
            state.doors.len()
        );
        let scene = crate::snapshot::Scene {
            cloud: &cloud,
            robot: state.last_pose,
            walls: &state.walls,
            doors: &state.doors,
            objects: &state.objects,
            caption: &caption,
        };
        if let Err(e) = crate::snapshot::write(path, &scene) {
            log::error!("{e}");
        }
    }
    if let Some(v) = opts.viz.take() {
        summary.viz_dropped = v.dropped();
        if let Err(e) = v.finish() {
            log::error!("{e}");
        }
    }
    summary.deadlines = state.record.clone();
    summary.budgets = Some(opts.budgets);
    summary.power = PowerVerdict {
        mean_w: (state.power_n > 0).then(|| state.power_sum / state.power_n as f64),
        peak_w: (state.power_n > 0).then_some(state.power_peak),
        budget_w: opts.power_budget_w,
        source: opts
            .power
            .as_ref()
            .map_or("none".to_owned(), |p| p.source().to_owned()),
    };
    if let Some(w) = opts.jsonl.as_mut() {
        w.flush()?;
    }
    if let Some(w) = opts.stats.as_mut() {
        w.flush()?;
    }
    Ok(summary)
}

/// Seconds without a byte from a live LiDAR before the loop says so.
pub const SILENT_WARN_S: f64 = 2.0;

/// Says (once per episode, in the log) when a live LiDAR falls silent or its motor stalls, and
/// when it comes back; the counts are in the output line's faults.
#[derive(Debug, Default)]
struct LinkWatch {
    last_data: Option<Instant>,
    silent: bool,
    stalled_seen: u64,
    stalled: bool,
    frames_at_stall: u64,
}

impl LinkWatch {
    fn data(&mut self) {
        self.last_data = Some(Instant::now());
        if self.silent {
            log::info!("LiDAR bytes again");
            self.silent = false;
        }
    }

    fn idle(&mut self, source: &LidarSource, stream: &impl FrameStream) {
        let since = self.last_data.get_or_insert_with(Instant::now).elapsed();
        if !self.silent && !source.is_file() && since.as_secs_f64() > SILENT_WARN_S {
            log::warn!(
                "no bytes from the LiDAR for {SILENT_WARN_S} s ({}): unplugged, unpowered or not spinning? Frames resume when it speaks",
                stream.what()
            );
            self.silent = true;
        }
    }

    fn after_feed(&mut self, stream: &impl FrameStream, frames: u64) {
        let stalled = stream.faults().stalled_packets;
        if stalled > self.stalled_seen {
            if !self.stalled {
                log::warn!(
                    "LiDAR motor stalled: its speed field reads below 60 rpm (faults.lidar_stalled_packets); frames wait for it to turn"
                );
                self.stalled = true;
                self.frames_at_stall = frames;
            }
            self.stalled_seen = stalled;
        } else if self.stalled && frames > self.frames_at_stall + 1 {
            log::info!("LiDAR motor turning again");
            self.stalled = false;
        }
    }
}

/// Whether the loop has fallen more than a revolution behind the LiDAR: bytes queued on a
/// port, or (simulated robot paced in real time) wall time ahead of the sensor clock.
fn behind_lidar(
    source: &LidarSource,
    backlog_bytes: Option<u32>,
    pacing: Pacing,
    stream: &impl FrameStream,
    start: &Instant,
    period_s: f64,
) -> bool {
    if let Some(queued) = backlog_bytes {
        return stream
            .bytes_per_revolution()
            .is_some_and(|per_rev| queued > per_rev);
    }
    source.is_simulated()
        && pacing == Pacing::RealTime
        && start.elapsed().as_secs_f64() - stream.sensor_time_s() > period_s
}

/// A Method A object of the output line; `id` is its place in the line.
fn object_a(
    id: usize,
    class: perception::class::ObjectClass,
    centre: Point2,
    score: f32,
) -> ObjectOut {
    ObjectOut {
        id: id as u32,
        class: class.as_str(),
        x: f64::from(centre.x),
        y: f64::from(centre.y),
        score: f64::from(score),
        source: "A",
        bbox: None,
    }
}

/// The pose halfway between two poses (heading along the shorter way round).
fn midway(a: &Pose2, b: &Pose2) -> Pose2 {
    Pose2::new(
        (a.x + b.x) / 2.0,
        (a.y + b.y) / 2.0,
        perception::geometry::wrap_angle(
            a.theta + perception::geometry::wrap_angle(b.theta - a.theta) / 2.0,
        ),
    )
}

/// Runs Method B on the last three revolutions and adds its objects (or marks Method A's as
/// agreed); `Err` carries the message of a failed frame.
fn method_b_frame(b: &mut MethodBSetup, state: &mut FrameState) -> Result<(), String> {
    let k = (state.revolutions - 1) as usize;
    let (newest, prev, oldest) = (k % 3, (k + 2) % 3, (k + 1) % 3);
    encode_chw_f32(
        b.model.input_mut(),
        [
            &state.history[newest],
            &state.history[prev],
            &state.history[oldest],
        ],
        &b.raster,
    )
    .map_err(|e| e.to_string())?;
    let (dets, scratch) = (&mut state.detections, &mut state.decode_scratch);
    b.model
        .run(|out| decode(out, ANCHORS, &b.decode, scratch, dets))
        .map_err(|e| e.to_string())?
        .map_err(|e| e.to_string())?;
    let lidar = state.history_pose[prev].compose(&b.mount);
    for d in state.detections.iter() {
        let centre = d.centre(&lidar, &b.raster);
        let bbox = Some([d.cx, d.cy, d.w, d.h].map(f64::from));
        let class = d.class.as_str();
        let agreed = state
            .objects
            .iter_mut()
            .filter(|o| o.source == "A" && o.class == class)
            .map(|o| {
                let dist = ((o.x - f64::from(centre.x)).powi(2)
                    + (o.y - f64::from(centre.y)).powi(2))
                .sqrt();
                (dist, o)
            })
            .filter(|(dist, _)| *dist <= f64::from(AGREE_M))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        match agreed {
            Some((_, o)) => {
                o.source = "AB";
                o.score = o.score.max(f64::from(d.score));
                o.bbox = bbox;
            }
            None => {
                let id = state.objects.len() as u32;
                state.objects.push(ObjectOut {
                    id,
                    class,
                    x: f64::from(centre.x),
                    y: f64::from(centre.y),
                    score: f64::from(d.score),
                    source: "B",
                    bbox,
                });
            }
        }
    }
    Ok(())
}

/// Writes the stream's last finished revolution as one frame; returns `true` when the frame
/// limit is reached.
fn emit_frame(
    stream: &impl FrameStream,
    source: &LidarSource,
    opts: &mut RunOptions,
    summary: &mut Summary,
    ingest: &mut Duration,
    state: &mut FrameState,
) -> std::io::Result<bool> {
    let Some(rev) = stream.last_revolution() else {
        return Ok(false);
    };
    let t_frame = Instant::now();
    let frame = summary.frames;
    let valid = rev.valid_count() as u32;
    summary.frames += 1;
    if rev.is_complete() {
        summary.complete += 1;
    }
    summary.invalid_readings += (u64::from(rev.packets)
        * drivers::lidar::revolution::BINS_PER_SECTOR as u64)
        .saturating_sub(u64::from(valid));

    if let Some(w) = opts.stats.as_mut() {
        writeln!(w, "{}", StatsLine { frame, rev })?;
    }
    let t = rev.first_ray_time_s().max(0.0);
    let t_pose = Instant::now();
    // The last ray comes 359/360 of a revolution after the first.
    let period = if rev.period_s.is_finite() && rev.period_s > 0.0 && rev.period_s < 2.0 {
        f64::from(rev.period_s)
    } else {
        0.2
    };
    let t_end = t + period * 359.0 / 360.0;
    let (pose, end, encoder_errors, compass_rejected, compass_errors) = match opts.pose.as_mut() {
        Some(p) => {
            p.take_scheduled(frame);
            p.take_device_samples(state.start, t);
            let start = p.advance(t);
            let end = p.advance(t_end);
            (
                start,
                end,
                p.encoder_errors(),
                u64::from(p.state.filter.compass_rejected()),
                p.compass_errors(),
            )
        }
        None => (Pose2::IDENTITY, Pose2::IDENTITY, 0, 0, 0),
    };
    let pose_ms = t_pose.elapsed().as_secs_f64() * 1e3;
    let t_a = Instant::now();
    state.objects.clear();
    state.walls.clear();
    state.doors.clear();
    let slot = (state.revolutions % METHOD_B_HISTORY as u64) as usize;
    for (r, reading) in state.history[slot].iter_mut().zip(rev.readings.iter()) {
        *r = if reading.valid { reading.range_m } else { 0.0 };
    }
    let shrink = opts.method_a.is_some() && state.policy.before_method_a(&opts.budgets);
    let method_a_ms = match opts.method_a.as_ref() {
        Some((cfg, mount)) => {
            // Overrun policy step 2: age more of the cloud so clustering sees fewer points.
            let mut shrunk;
            let cfg = if shrink {
                shrunk = *cfg;
                shrunk.cloud.drop_fraction = shrunk.cloud.drop_fraction.max(SHRINK_DROP_FRACTION);
                &shrunk
            } else {
                cfg
            };
            let m = &mut state.method_a;
            m.add_scan(
                &Scan {
                    ranges: &state.history[slot],
                    start: pose,
                    end,
                    mount: *mount,
                },
                cfg,
            );
            let sensor = end.compose(mount);
            m.run(
                Point2::new(sensor.x, sensor.y),
                cfg,
                models::forest::forest(),
            );
            for (class, c) in m.objects() {
                state
                    .objects
                    .push(object_a(state.objects.len(), class, c.centre, c.score));
            }
            for s in m.segments() {
                state.walls.push(WallOut {
                    x0: f64::from(s.a.x),
                    y0: f64::from(s.a.y),
                    x1: f64::from(s.b.x),
                    y1: f64::from(s.b.y),
                });
            }
            for d in m.doors() {
                state.doors.push(DoorOut {
                    x: f64::from(d.centre.x),
                    y: f64::from(d.centre.y),
                    width: f64::from(d.width),
                    score: f64::from(d.score),
                });
                state.objects.push(object_a(
                    state.objects.len(),
                    perception::class::ObjectClass::DoorFrame,
                    d.centre,
                    d.score,
                ));
            }
            let ms = t_a.elapsed().as_secs_f64() * 1e3;
            state.policy.method_a_took(ms);
            Some(ms)
        }
        None => None,
    };
    state.history_pose[slot] = midway(&pose, &end);
    state.revolutions += 1;
    let backlog_bytes = source.backlog_bytes();
    let behind = behind_lidar(
        source,
        backlog_bytes,
        opts.pacing,
        stream,
        &state.start,
        period,
    );
    let elapsed_ms = ingest.as_secs_f64() * 1e3 + t_frame.elapsed().as_secs_f64() * 1e3;
    // Overrun policy step 1: no room left for Method B, or decimated while behind.
    let run_b = opts.method_b.is_some() && state.revolutions >= 3;
    let skip_b = run_b
        && state
            .policy
            .before_method_b(&opts.budgets, elapsed_ms, behind);
    let method_b_ms = match opts.method_b.as_mut() {
        Some(b) if run_b && !skip_b => {
            let t_b = Instant::now();
            if let Err(e) = method_b_frame(b, state) {
                if state.method_b_errors == 0 {
                    log::warn!("Method B: {e}; frame goes on without it (counted)");
                }
                state.method_b_errors += 1;
            }
            let ms = t_b.elapsed().as_secs_f64() * 1e3;
            state.policy.method_b_took(ms);
            Some(ms)
        }
        _ => None,
    };
    let ingest_ms = ingest.as_secs_f64() * 1e3;
    let output_ms = state.last_output_ms;
    let total_ms = ingest_ms + t_frame.elapsed().as_secs_f64() * 1e3 + output_ms;
    let missed = total_ms > opts.budgets.deadline_ms;
    let degraded = skip_b || shrink;
    let rec = &mut state.record;
    rec.method_b_skipped += u64::from(skip_b);
    rec.cloud_shrunk += u64::from(shrink);
    rec.behind_lidar += u64::from(behind);
    let times = FrameTimes {
        ingest: ingest_ms,
        pose: pose_ms,
        method_a: method_a_ms,
        method_b: method_b_ms,
        output: output_ms,
        total: total_ms,
    };
    rec.record(&times, &opts.budgets, missed, degraded);
    let power_w = opts.power.as_mut().and_then(|p| p.watts());
    if let Some(w) = power_w {
        state.power_sum += w;
        state.power_n += 1;
        state.power_peak = state.power_peak.max(w);
    }
    let t_out = Instant::now();
    if let Some(w) = opts.jsonl.as_mut() {
        let line = OutputLine {
            frame,
            t,
            pose: PoseOut {
                x: f64::from(pose.x),
                y: f64::from(pose.y),
                theta: f64::from(pose.theta),
            },
            objects: &state.objects,
            walls: &state.walls,
            doors: &state.doors,
            timing_ms: TimingOut::from(times),
            deadline_ms: opts.budgets.deadline_ms,
            deadline_missed: missed,
            degraded,
            power_w,
            power_source: opts.power.as_ref().map_or("none", |p| p.source()),
            faults: FaultsOut {
                encoder_errors,
                compass_rejected,
                compass_errors,
                method_b_errors: state.method_b_errors,
                deadline_missed: rec.missed,
                degraded_frames: rec.degraded,
                method_b_skipped: rec.method_b_skipped,
                cloud_shrunk: rec.cloud_shrunk,
                behind_lidar: rec.behind_lidar,
                recording_bytes_dropped: state.raw_dropped,
                recording_samples_dropped: opts
                    .pose
                    .as_ref()
                    .map_or(0, |p| p.state.journal_dropped),
                odometry_dropped: opts
                    .pose
                    .as_ref()
                    .and_then(|p| p.devices.as_ref())
                    .map_or(0, DeviceReader::dropped),
                ..FaultsOut::new(
                    &stream.faults(),
                    summary.invalid_readings,
                    source.link_counts(),
                )
            },
            lidar: LidarOut {
                rpm: f64::from(rev.rpm),
                packets: rev.packets,
                valid,
                backlog_bytes,
                queue_chunks: source.queue_depth().map(|q| q.0),
                queue_chunks_max: source.queue_depth().map(|q| q.1),
            },
        };
        line.write_to(w)?;
    }
    state.last_output_ms = t_out.elapsed().as_secs_f64() * 1e3;
    state.last_pose = pose;
    let mount = match (&opts.method_a, &opts.method_b) {
        (Some((_, m)), _) => *m,
        (None, Some(b)) => b.mount,
        (None, None) => Pose2::IDENTITY,
    };
    let journal = opts.pose.as_mut().and_then(|p| p.state.journal.as_mut());
    if let Some(v) = opts.viz.as_mut() {
        let st = &*state;
        let journal_ref = journal.as_deref();
        let sent = v.send(|f: &mut VizFrameStub| {
            f.raw.clear();
            if let Some(raw) = st.pending_raw.as_deref() {
                let _ = f.raw.extend_from_slice(raw);
            }
            f.odom.clear();
            for r in journal_ref.into_iter().flatten() {
                let _ = f.odom.push(*r);
            }
            f.frame = frame;
            f.t = t;
            f.pose = pose;
            f.mount = mount;
            f.ranges.copy_from_slice(&st.history[slot]);
            f.objects.clear();
            f.walls.clear();
            f.doors.clear();
            for o in &st.objects {
                let _ = f.objects.push(o.clone());
            }
            for w in &st.walls {
                let _ = f.walls.push(w.clone());
            }
            for d in &st.doors {
                let _ = f.doors.push(d.clone());
            }
        });
        if sent {
            if let Some(raw) = state.pending_raw.as_mut() {
                raw.clear();
            }
            if let Some(j) = journal {
                j.clear();
            }
        }
    }
    *ingest = Duration::ZERO;
    // Output errors end the run, so only this path needs the frame's time.
    state.busy += t_frame.elapsed();
    Ok(opts.frames.is_some_and(|n| summary.frames >= n))
}
