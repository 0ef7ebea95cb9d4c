//! What the frame loop reads revolutions from: [`FrameStream`], bytes in, one
//! [`Revolution`] a frame out. Every LiDAR's decoder is one (through
//! [`drivers::lidar::LidarStream`]); so is the CARMEN log reader ([`crate::carmen`]), whose
//! text lines carry scans and odometry instead of a sensor's bytes.

use std::collections::VecDeque;

use drivers::lidar::{LidarFaults, LidarStream, Revolution};

use crate::odom::OdomRecord;

/// A decoder of some byte stream into revolutions (and, for logs, odometry samples).
pub trait FrameStream {
    /// Consumes bytes from the front of `input` until a revolution is finished (`true`; read
    /// it with [`FrameStream::last_revolution`]) or `input` is used up (`false`).
    fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool;
    /// The last revolution finished.
    fn last_revolution(&self) -> Option<&Revolution>;
    /// Hands out a partial revolution if no data arrived for the stale time.
    fn poll(&mut self, now_us: u64) -> Option<&Revolution>;
    /// Hands out what is left at the end of the stream.
    fn finish(&mut self) -> Option<&Revolution>;
    /// The link was lost: forget partial state.
    fn link_reset(&mut self);
    /// The stream's own clock, seconds.
    fn sensor_time_s(&self) -> f64;
    /// Fault counters.
    fn faults(&self) -> LidarFaults;
    /// Bytes of one revolution on the wire (the loop is behind when more wait); `None` when
    /// the stream has no such rate (a log file).
    fn bytes_per_revolution(&self) -> Option<u32>;
    /// Moves odometry samples decoded from the stream into `out` (logs only).
    fn drain_odometry(&mut self, _out: &mut VecDeque<OdomRecord>) -> usize {
        0
    }
    /// What the stream decodes, for messages.
    fn what(&self) -> &'static str;
}

impl<T: LidarStream> FrameStream for T {
    fn next_revolution(&mut self, input: &mut &[u8], host_us: Option<u64>) -> bool {
        LidarStream::next_revolution(self, input, host_us)
    }
    fn last_revolution(&self) -> Option<&Revolution> {
        LidarStream::last_revolution(self)
    }
    fn poll(&mut self, now_us: u64) -> Option<&Revolution> {
        LidarStream::poll(self, now_us)
    }
    fn finish(&mut self) -> Option<&Revolution> {
        LidarStream::finish(self)
    }
    fn link_reset(&mut self) {
        LidarStream::link_reset(self)
    }
    fn sensor_time_s(&self) -> f64 {
        LidarStream::sensor_time_s(self)
    }
    fn faults(&self) -> LidarFaults {
        LidarStream::faults(self)
    }
    fn bytes_per_revolution(&self) -> Option<u32> {
        Some(self.model().bytes_per_revolution())
    }
    fn what(&self) -> &'static str {
        self.model().display_name()
    }
}
