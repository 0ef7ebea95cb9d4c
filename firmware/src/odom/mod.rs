//! Odometry and compass input for the pose: the `--odom` JSON Lines of `docs/interfaces.md` §2
//! (`{"t": …, "left_ticks": …, "right_ticks": …}` and/or `{"t": …, "mag_ut": [x, y, z]}`), read
//! in step with the LiDAR frames on the same clock, or samples handed over by the simulated
//! robot. Both feed one [`PoseFilter`].
//!
//! [`PoseInput`] (`input.rs`) feeds the filter in step with the frames from whichever source
//! the run has.
//!
//! A line that is not valid JSON, or a sample with fields of the wrong type, is counted as an
//! encoder error and skipped; the run goes on.

use std::fs::File;
use std::io::{BufRead, BufReader, Lines};
use std::path::{Path, PathBuf};

use perception::pose::PoseFilter;
use serde::{Deserialize, Serialize};

mod input;
pub use input::{FramePose, ODOM_QUEUE, POSE_QUEUE, PoseInput};

/// One sample.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
pub struct OdomRecord {
    /// Time, s, on the LiDAR's clock.
    pub t: f64,
    /// Left wheel ticks, cumulative.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_ticks: Option<i64>,
    /// Right wheel ticks, cumulative.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right_ticks: Option<i64>,
    /// Magnetometer, robot frame, µT.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mag_ut: Option<[f32; 3]>,
}

impl From<drivers::lidar::WheelTicks> for OdomRecord {
    fn from(w: drivers::lidar::WheelTicks) -> Self {
        OdomRecord {
            t: w.t,
            left_ticks: Some(w.left),
            right_ticks: Some(w.right),
            mag_ut: None,
        }
    }
}

/// Samples the pose state's journal holds between two recorded frames.
pub const JOURNAL_LEN: usize = 64;

/// Pose state of a run: the filter, and what went wrong.
#[derive(Debug, Clone)]
pub struct PoseState {
    /// The filter.
    pub filter: PoseFilter,
    /// Whether compass readings are used (a hard-iron calibration is configured).
    pub use_compass: bool,
    /// Bad odometry lines or samples.
    pub encoder_errors: u64,
    /// While recording: every sample that became available to the pose (entered the queue, or
    /// was read from the file) since the recorder last took them (full: the oldest are kept,
    /// later ones counted in `journal_dropped`). Replay makes each available at the same frame,
    /// so the poses come out the same.
    pub journal: Option<heapless::Vec<OdomRecord, JOURNAL_LEN>>,
    /// Samples that did not fit the journal (missing from the recording).
    pub journal_dropped: u64,
    last_t: Option<f64>,
}

impl PoseState {
    /// A pose state.
    pub fn new(filter: PoseFilter, use_compass: bool) -> Self {
        PoseState {
            filter,
            use_compass,
            encoder_errors: 0,
            journal: None,
            journal_dropped: 0,
            last_t: None,
        }
    }

    /// The pose at time `t`, between the last sample fed and `next` (a later one not yet fed):
    /// the encoder step to `next` is taken at constant wheel speed. Without a usable `next`, the
    /// pose after the last sample.
    pub fn pose_at(&self, t: f64, next: Option<&OdomRecord>) -> perception::geometry::Pose2 {
        let pose = self.filter.pose();
        let (Some(t0), Some(n)) = (self.last_t, next) else {
            return pose;
        };
        match (n.left_ticks, n.right_ticks) {
            (Some(l), Some(r)) if n.t > t0 && t > t0 => {
                let f = ((t - t0) / (n.t - t0)) as f32;
                self.filter.interpolate(l as i32, r as i32, f)
            }
            _ => pose,
        }
    }

    /// Notes that `r` became available (for the recording, when there is one).
    pub fn note_available(&mut self, r: &OdomRecord) {
        if let Some(j) = self.journal.as_mut()
            && j.push(*r).is_err()
        {
            self.journal_dropped += 1;
        }
    }

    /// Feeds one sample.
    pub fn feed(&mut self, r: &OdomRecord) {
        if !r.t.is_finite() {
            self.encoder_errors += 1;
            return;
        }
        if let (Some(l), Some(rt)) = (r.left_ticks, r.right_ticks) {
            let dt = self.last_t.map_or(0.0, |t0| (r.t - t0).max(0.0)) as f32;
            // Counters are i32 on the OpenCR; wider values are taken modulo 2³², which the
            // wrap-safe differencing handles.
            self.filter.encoders(l as i32, rt as i32, dt);
            self.last_t = Some(r.t);
        }
        if let (Some(m), true) = (r.mag_ut, self.use_compass) {
            if m.iter().all(|v| v.is_finite()) {
                self.filter.compass_3d(m[0], m[1], m[2]);
            } else {
                self.encoder_errors += 1;
            }
        }
    }
}

/// Reads an odometry JSON Lines file in time order.
pub struct OdomFile {
    path: PathBuf,
    lines: Lines<BufReader<File>>,
    pending: Option<OdomRecord>,
    line_no: u64,
}

impl OdomFile {
    /// Opens `path`.
    pub fn open(path: &Path) -> Result<Self, String> {
        let f =
            File::open(path).map_err(|e| format!("--odom {}: cannot open: {e}", path.display()))?;
        Ok(OdomFile {
            path: path.to_owned(),
            lines: BufReader::new(f).lines(),
            pending: None,
            line_no: 0,
        })
    }

    /// The next sample not yet fed (after [`OdomFile::advance`]: the first one past `until`).
    pub fn peek(&self) -> Option<&OdomRecord> {
        self.pending.as_ref()
    }

    /// Feeds every sample with `t ≤ until` to `state`.
    pub fn advance(&mut self, until: f64, state: &mut PoseState) {
        loop {
            if let Some(r) = self.pending {
                if r.t > until {
                    return;
                }
                state.feed(&r);
                self.pending = None;
            }
            match self.lines.next() {
                None => return,
                Some(Err(e)) => {
                    log::warn!("{}: read error: {e}", self.path.display());
                    state.encoder_errors += 1;
                    return;
                }
                Some(Ok(line)) => {
                    self.line_no += 1;
                    if line.trim().is_empty() {
                        continue;
                    }
                    match serde_json::from_str::<OdomRecord>(&line) {
                        Ok(r) => {
                            state.note_available(&r);
                            self.pending = Some(r);
                        }
                        Err(e) => {
                            if state.encoder_errors == 0 {
                                log::warn!(
                                    "{}:{}: skipped: {e}",
                                    self.path.display(),
                                    self.line_no
                                );
                            }
                            state.encoder_errors += 1;
                        }
                    }
                }
            }
        }
    }
}
