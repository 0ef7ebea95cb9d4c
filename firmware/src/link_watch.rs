//! Says (once per episode, in the log) when a live LiDAR falls silent or its motor stalls, and
//! when it comes back; the counts themselves are in the output line's faults.

use std::time::Instant;

use crate::source::LidarSource;
use drivers::lidar::RevolutionStream;

/// Seconds without a byte from a live LiDAR before the loop says so.
pub const SILENT_WARN_S: f64 = 2.0;

/// The log's memory of the link's episodes.
#[derive(Debug, Default)]
pub struct LinkWatch {
    last_data: Option<Instant>,
    silent: bool,
    stalled_seen: u64,
    stalled: bool,
    frames_at_stall: u64,
}

impl LinkWatch {
    /// Bytes arrived.
    pub fn data(&mut self) {
        self.last_data = Some(Instant::now());
        if self.silent {
            log::info!("LiDAR bytes again");
            self.silent = false;
        }
    }

    /// No bytes this time.
    pub fn idle(&mut self, source: &LidarSource, stream: &impl RevolutionStream) {
        let since = self.last_data.get_or_insert_with(Instant::now).elapsed();
        if !self.silent && !source.is_file() && since.as_secs_f64() > SILENT_WARN_S {
            log::warn!(
                "no bytes from the LiDAR for {SILENT_WARN_S} s ({}): unplugged, unpowered or not spinning? Frames resume when it speaks",
                stream.what()
            );
            self.silent = true;
        }
    }

    /// After bytes were fed: a stalled motor (LDS-01 speed field) starts or ends an episode.
    pub fn after_feed(&mut self, stream: &impl RevolutionStream, frames: u64) {
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
