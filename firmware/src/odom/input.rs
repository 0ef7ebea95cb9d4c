//! Where the pose's samples come from, in step with the frames: an `--odom` file read up to
//! each frame's time, a live source's samples (the simulated robot, the device thread polling
//! the OpenCR and compass) queued until their frame, or a recording's samples made available
//! at the frames they were in the recorded run. Every sample goes through one [`PoseState`];
//! with `[pose] scan_match` each revolution is then laid on a keyframe's
//! (`perception::scan_match`) and the pose moved by what that finds.

use std::time::Instant;

use heapless::Deque;

use perception::cloud::Scan;
use perception::geometry::Pose2;
use perception::scan_match::{MatchOutcome, ScanMatcher};

use super::{OdomFile, OdomRecord, PoseState};
use crate::reader::{ClockMap, DeviceReader};

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
    /// Samples from a live source (the simulator, the device thread), waiting for their frame
    /// (the bound is in the type; when full, the oldest is fed to the filter at once).
    pub queue: Deque<OdomRecord, POSE_QUEUE>,
    /// The OpenCR and compass, polled by their own thread.
    pub devices: Option<DeviceReader>,
    /// Host time → LiDAR time, for the device thread's samples.
    pub clock: ClockMap,
    /// A recording's samples, each with the frame at which it became available
    /// ([`crate::recording`]), read at start-up.
    pub scheduled: Vec<(u64, OdomRecord)>,
    scheduled_next: usize,
    /// The scan matcher (`[pose] scan_match`), which lays each revolution on a keyframe's so
    /// that the pose does not drift with the wheels; `None`: odometry and compass alone.
    pub scan_match: Option<Box<ScanMatcher>>,
}

/// What the pose stage hands the frame: the pose at the first and the last ray, and the
/// input's fault counters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FramePose {
    /// The robot's pose at the revolution's first ray.
    pub start: Pose2,
    /// At its last ray.
    pub end: Pose2,
    /// Encoder faults: the filter's (implausible ticks) plus failed polls.
    pub encoder_errors: u64,
    /// Compass readings the filter rejected.
    pub compass_rejected: u64,
    /// Failed compass reads.
    pub compass_errors: u64,
}

impl FramePose {
    /// No pose input: the robot is assumed still at the origin.
    pub const STILL: FramePose = FramePose {
        start: Pose2::IDENTITY,
        end: Pose2::IDENTITY,
        encoder_errors: 0,
        compass_rejected: 0,
        compass_errors: 0,
    };
}

impl PoseInput {
    /// A pose input fed by `state` alone, with room reserved for queued samples.
    pub fn new(state: PoseState) -> Self {
        PoseInput {
            state,
            file: None,
            queue: Deque::new(),
            devices: None,
            clock: ClockMap::default(),
            scheduled: Vec::new(),
            scheduled_next: 0,
            scan_match: None,
        }
    }

    /// Lays the revolution (`ranges` by bin, metres, 0 for none; `mount`: the LiDAR on the
    /// robot) on the scan matcher's keyframe, if there is a matcher, and moves `pose` and the
    /// filter's pose by the correction it finds.
    pub fn match_scan(&mut self, ranges: &[f32], mount: Pose2, pose: &mut FramePose) {
        let Some(m) = self.scan_match.as_mut() else {
            return;
        };
        let scan = Scan {
            ranges,
            start: pose.start,
            end: pose.end,
            mount,
        };
        if let MatchOutcome::Matched { correction, .. } = m.update(&scan) {
            pose.start = correction.compose(&pose.start);
            pose.end = correction.compose(&pose.end);
            self.state.filter.correct(&correction);
        }
    }

    /// The pose over frame `frame`, whose first ray is at sensor time `t` and last at `t_end`
    /// (`start` is the run's host-clock origin, for the device thread's stamps).
    pub fn frame(&mut self, frame: u64, t: f64, t_end: f64, start: Instant) -> FramePose {
        self.take_scheduled(frame);
        self.take_device_samples(start, t);
        let first = self.advance(t);
        let end = self.advance(t_end);
        FramePose {
            start: first,
            end,
            encoder_errors: self.encoder_errors(),
            compass_rejected: u64::from(self.state.filter.compass_rejected()),
            compass_errors: self.compass_errors(),
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
        if self.queue.is_full()
            && let Some(old) = self.queue.pop_front()
        {
            self.state.feed(&old);
        }
        self.state.note_available(&r);
        // Room was just made: the push cannot fail.
        let _ = self.queue.push_back(r);
    }

    /// Lets `drain` hand samples to the queue (the simulator's, a log's), each noted for the
    /// recording.
    pub fn take_from(&mut self, drain: impl FnOnce(&mut dyn FnMut(OdomRecord))) {
        drain(&mut |r| self.enqueue(r));
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

    /// Samples the device thread dropped because its queue was full.
    pub fn odometry_dropped(&self) -> u64 {
        self.devices.as_ref().map_or(0, DeviceReader::dropped)
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
