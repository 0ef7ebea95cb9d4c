//! The replay channels of an umbra MCAP recording, shared by the writer ([`crate::viz`]) and
//! the reader ([`crate::recording`]): topic names, encodings, the odometry message and how
//! many LiDAR bytes the loop holds for the recorder between two recorded frames.

use crate::odom::OdomRecord;

/// Topic of the LiDAR's raw bytes.
pub const RAW_TOPIC: &str = "/umbra/lidar_raw";
/// Topic of the odometry samples.
pub const ODOM_TOPIC: &str = "/umbra/odometry";
/// Message encoding of the raw bytes.
pub const RAW_ENCODING: &str = "application/octet-stream";

/// LiDAR bytes held for the recording between two recorded frames (16 KiB, over six LDS-01
/// revolutions: room for a few frames the recorder had to drop).
pub const RECORD_RAW_BYTES: usize = 16 * 1024;

/// The JSON Schema of an `/umbra/odometry` message (the `--odom` line of
/// `docs/interfaces.md` §2 plus its frame).
pub const ODOM_SCHEMA: &str = r#"{"type":"object","required":["t","frame"],"properties":{"frame":{"type":"integer"},"t":{"type":"number"},"left_ticks":{"type":["integer","null"]},"right_ticks":{"type":["integer","null"]},"mag_ut":{"type":["array","null"],"items":{"type":"number"},"minItems":3,"maxItems":3}}}"#;

/// An `/umbra/odometry` message: the `--odom` object of `docs/interfaces.md` §2 plus the frame
/// at which the sample became available to the pose (replay makes it available at that frame).
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct RecordedSample {
    /// The frame.
    pub frame: u64,
    /// The sample.
    #[serde(flatten)]
    pub sample: OdomRecord,
}
