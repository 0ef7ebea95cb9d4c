//! What a run did, for the end-of-run report and the tests.

use drivers::lidar::LidarFaults;

use crate::deadline::{Budgets, DeadlineRecord, PowerVerdict};

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
    /// Detections dropped for lying in or behind a wall (`perception::plausible`).
    pub walled_detections: u64,
    /// Method B runs finished.
    pub method_b_runs: u64,
    /// Method B ran on its own thread (`[method_b] schedule`).
    pub method_b_worker: bool,
}

impl Summary {
    /// The deadline and power table of `docs/interfaces.md` §4.
    pub fn table(&self) -> String {
        match &self.budgets {
            Some(b) => crate::deadline::table(&self.deadlines, b, &self.power),
            None => String::new(),
        }
    }
}
