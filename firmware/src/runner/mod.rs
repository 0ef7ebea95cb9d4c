//! The frame loop: bytes in, one frame per LiDAR revolution out, through the pipeline
//! ingest → pose → Method A → Method B → fusion → outputs.
//!
//! | file          | owns                                                                   |
//! |---------------|------------------------------------------------------------------------|
//! | `mod.rs`      | the loop over the source's bytes: limits, link events, pacing, the end |
//! | `frame.rs`    | one frame through the pipeline, and its stage times                    |
//! | `history.rs`  | the last three revolutions and their poses                             |
//! | `method_b.rs` | Method B as a stage, over the [`Network`] trait                        |
//! | `b_worker.rs` | Method B on a thread of its own (a Pi 3's schedule)                    |
//! | `summary.rs`  | what a run did                                                         |
//!
//! `timing_ms.ingest` is the time spent decoding the frame's bytes (not waiting for them).
//! Bytes are read into one fixed buffer ([`READ_CHUNK`] bytes), fed to the stream, and each
//! finished revolution becomes a frame handed to every [`FrameSink`] (JSON line, statistics
//! line, recording, snapshot). The pose is taken at the revolution's first ray (the output
//! line's pose) and at its last, so Method A de-skews the scan. Method B reads the last three
//! revolutions; its boxes join Method A's objects in `perception::fusion`.

mod b_worker;
mod frame;
mod history;
mod method_b;
mod summary;
mod track_log;

use std::io;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use perception::geometry::Pose2;
use perception::method_a::MethodAConfig;
use perception::tracks::TrackConfig;

pub use b_worker::B_WORKER_JOB_BYTES;
pub use history::{METHOD_B_HISTORY, ScanHistory};
pub use method_b::{
    MethodBScratch, MethodBSetup, Network, Precision, Schedule, Seam, drawing, follow_model,
};
pub use summary::Summary;
pub use track_log::TrackLog;

use crate::deadline::{Budgets, PowerVerdict};
use crate::link_watch::LinkWatch;
use crate::odom::{OdomRecord, PoseInput};
use crate::power::PowerMeter;
use crate::sink::{FrameSink, RunEnd};
use crate::source::{LidarSource, Pacing, SourceRead};
use drivers::lidar::RevolutionStream;
use frame::FrameState;

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
    /// Where each frame goes, in this order (JSON lines, statistics, recording, snapshot).
    pub sinks: Vec<Box<dyn FrameSink>>,
    /// Set from outside (Ctrl-C) to stop cleanly.
    pub stop: Arc<AtomicBool>,
    /// Pose input; `None`: no odometry, the robot is assumed still.
    pub pose: Option<PoseInput>,
    /// Method A settings and the LiDAR's pose on the robot; `None`: Method A off.
    pub method_a: Option<(MethodAConfig, Pose2)>,
    /// Method B's model and settings; `None`: Method B off.
    pub method_b: Option<MethodBSetup>,
    /// The world model's settings; `None`: off (`objects` are the frame's detections).
    pub world: Option<TrackConfig>,
    /// Each frame's reportable tracks and their report features (`--track-log`), opened at
    /// start-up; the default writes nothing.
    pub track_log: TrackLog,
}

/// Method B's stage budget on its own thread, in deadlines (at least).
pub const WORKER_BUDGET_FRAMES: f64 = 3.0;

/// Runs the loop until a limit, the end of the source, or the stop flag.
pub fn run<S: RevolutionStream>(
    source: &mut LidarSource,
    stream: S,
    mut opts: RunOptions,
) -> Result<Summary, io::Error> {
    let start = Instant::now();
    let records = opts.sinks.iter().any(|s| s.records_input());
    let mut st = FrameState::new(records);
    st.track_log = std::mem::take(&mut opts.track_log);
    // The LiDAR's pose on the robot, from whichever method has it.
    let mount = match (&opts.method_a, &opts.method_b) {
        (Some((_, m)), _) => *m,
        (None, Some(b)) => b.mount,
        (None, None) => Pose2::IDENTITY,
    };
    if opts.method_b.as_ref().map(|b| b.schedule) == Some(Schedule::Worker)
        && let Some(b) = opts.method_b.take()
    {
        st.worker = Some(b_worker::BWorker::start(b)?);
        // Off the frame's path its budget is a cadence: a report at least every third frame
        // (a Pi 3's projected slow end, 530 ms, is inside 750).
        opts.budgets.method_b_ms = opts
            .budgets
            .method_b_ms
            .max(WORKER_BUDGET_FRAMES * opts.budgets.deadline_ms);
    }
    let mut lp = FrameLoop {
        source,
        stream,
        st,
        mount,
        opts,
        summary: Summary::default(),
        ingest: Duration::ZERO,
        start,
    };
    if records && let Some(p) = lp.opts.pose.as_mut() {
        p.state.journal = Some(heapless::Vec::new());
    }
    let reason = lp.bytes_to_frames()?;
    lp.end(reason)
}

/// The loop and everything it keeps between frames.
struct FrameLoop<'s, S> {
    source: &'s mut LidarSource,
    stream: S,
    opts: RunOptions,
    st: FrameState,
    /// The LiDAR's pose on the robot.
    mount: Pose2,
    summary: Summary,
    /// Time spent decoding since the last frame.
    ingest: Duration,
    /// When the loop started.
    start: Instant,
}

impl<S: RevolutionStream> FrameLoop<'_, S> {
    /// Reads, decodes and hands out frames until a limit, the end or the stop flag; returns
    /// why it stopped.
    fn bytes_to_frames(&mut self) -> io::Result<&'static str> {
        let mut buf = [0u8; READ_CHUNK];
        let start = self.start;
        let mut watch = LinkWatch::default();
        // The link clock for staleness: host time spent waiting for bytes, not time spent
        // processing frames (a slow frame leaves bytes queued, not the sensor silent). Files
        // have no silence at all: no clock.
        let link_us = |busy: Duration| start.elapsed().saturating_sub(busy).as_micros() as u64;
        loop {
            if self.opts.stop.load(Ordering::Relaxed) {
                return Ok("stopped by signal");
            }
            if let Some(s) = self.opts.seconds {
                let elapsed = match self.opts.seconds_clock {
                    SecondsClock::Wall => start.elapsed().as_secs_f64(),
                    SecondsClock::Sensor => self.stream.sensor_time_s(),
                };
                if elapsed >= s {
                    return Ok("time limit");
                }
            }
            let n = match self.source.read(&mut buf) {
                SourceRead::Data(n) => n,
                SourceRead::Idle => {
                    watch.idle(self.source, &self.stream);
                    if !self.source.is_file()
                        && self.stream.poll(link_us(self.st.busy)).is_some()
                        && self.emit_frame()?
                    {
                        return Ok("frame limit");
                    }
                    continue;
                }
                SourceRead::End => {
                    if self.stream.finish().is_some() {
                        self.emit_frame()?;
                    }
                    return Ok("end of input");
                }
                SourceRead::Lost(msg) => {
                    log::warn!("{msg}; reopening with back-off");
                    self.stream.link_reset();
                    if let Some(p) = self.opts.pose.as_mut() {
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
            self.summary.bytes += n as u64;
            watch.data();
            self.st.note_raw(&buf[..n]);
            if let Some(p) = self.opts.pose.as_mut() {
                let source = &mut *self.source;
                p.take_from(|q| source.drain_odometry(q));
            }
            let mut input = &buf[..n.min(READ_CHUNK)];
            let now = (!self.source.is_file()).then(|| link_us(self.st.busy));
            loop {
                let t_feed = Instant::now();
                let done = self.stream.next_revolution(&mut input, now);
                self.ingest += t_feed.elapsed();
                if let Some(p) = self.opts.pose.as_mut() {
                    // A log's odometry lines, up to the frame's scan.
                    let stream = &mut self.stream;
                    p.take_from(|q| {
                        stream.drain_odometry(&mut |w| q(OdomRecord::from(w)));
                    });
                }
                if !done {
                    break;
                }
                if let (Some(p), Some(host)) =
                    (self.opts.pose.as_mut(), self.source.last_read_host())
                {
                    let host_s = host.saturating_duration_since(start).as_secs_f64();
                    p.clock.observe(host_s, self.stream.sensor_time_s());
                }
                if self.emit_frame()? {
                    return Ok("frame limit");
                }
            }
            watch.after_feed(&self.stream, self.summary.frames);
            if self.opts.pacing == Pacing::RealTime {
                let ahead = self.stream.sensor_time_s() - start.elapsed().as_secs_f64();
                if ahead > 0.0 {
                    std::thread::sleep(Duration::from_secs_f64(ahead.min(1.0)));
                }
            }
        }
    }

    /// Closes the run: the sinks finish (flush, close, draw), the summary is filled in.
    fn end(mut self, reason: &'static str) -> io::Result<Summary> {
        self.st.drain_worker();
        let s = &mut self.summary;
        s.method_b_runs = self.st.method_b_runs;
        s.method_b_worker = self.st.worker.is_some();
        s.faults = self.stream.faults();
        s.link = self.source.link_counts();
        s.sensor_seconds = self.stream.sensor_time_s();
        s.wall_seconds = self.start.elapsed().as_secs_f64();
        s.stop_reason = reason;
        s.viz_dropped = self.opts.sinks.iter().map(|k| k.dropped()).sum();
        if let Some(m) = self.opts.pose.as_ref().and_then(|p| p.scan_match.as_ref()) {
            let st = m.stats();
            log::info!(
                "scan matching: {} revolutions matched, {} keyframes; refused: {} few pairs, {} residual, {} too far, {} one direction only",
                st.matched,
                st.keyframes,
                st.refused[0],
                st.refused[1],
                st.refused[2],
                st.refused[3]
            );
        }
        let cloud: Vec<_> = self.st.method_a.cloud().iter().copied().collect();
        let end = RunEnd {
            frames: s.frames,
            sensor_seconds: s.sensor_seconds,
            cloud: &cloud,
            robot: self.st.last_pose,
            objects: self.st.reported(self.opts.world.is_some()),
            walls: &self.st.walls,
            doors: &self.st.doors,
        };
        let mut result = Ok(());
        for sink in self.opts.sinks.iter_mut() {
            if let Err(e) = sink.finish(&end)
                && result.is_ok()
            {
                result = Err(e);
            }
        }
        s.deadlines = self.st.record.clone();
        s.walled_detections = self.st.walled;
        s.budgets = Some(self.opts.budgets);
        s.power = PowerVerdict {
            mean_w: (self.st.power_n > 0).then(|| self.st.power_sum / self.st.power_n as f64),
            peak_w: (self.st.power_n > 0).then_some(self.st.power_peak),
            budget_w: self.opts.power_budget_w,
            source: self
                .opts
                .power
                .as_ref()
                .map_or("none".to_owned(), |p| p.source().to_owned()),
        };
        result.map(|()| self.summary)
    }
}

/// Before a frame's clock starts: when nothing paces the source (`Pacing::Max`), the sinks
/// catch up ([`crate::sink::FrameSink::make_room`]), so such a run's recording is complete.
fn make_room(opts: &mut RunOptions) {
    if opts.pacing == Pacing::Max {
        for sink in opts.sinks.iter_mut() {
            sink.make_room();
        }
    }
}

/// Whether the loop has fallen more than a revolution behind the LiDAR: bytes queued on a
/// port, or (simulated robot paced in real time) wall time ahead of the sensor clock.
fn behind_lidar(
    source: &LidarSource,
    backlog_bytes: Option<u32>,
    pacing: Pacing,
    stream: &impl RevolutionStream,
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
