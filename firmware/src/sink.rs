//! Where a frame's results go: the [`FrameSink`] trait the frame loop hands every finished
//! frame to, and the sinks every build has — the JSON line of `docs/interfaces.md` §3
//! ([`JsonlSink`]), the human-readable line of what the robot sees ([`SceneSink`]) and the
//! LiDAR's statistics line of `--verbose` ([`StatsSink`]). Recording and
//! the live view (`crate::viz`, feature `viz`) and the end-of-run picture
//! ([`crate::snapshot::SnapshotSink`]) are sinks too.
//!
//! A sink runs on the loop's thread: it must not allocate per frame (the counting-allocator
//! test runs with the JSON, scene and stats sinks, and with the recorder).

use std::io::{self, Write};

use drivers::lidar::Revolution;
use perception::geometry::{Point2, Pose2};
use perception::raster::SCAN_COLUMNS;

use crate::odom::OdomRecord;
use crate::output::{DoorOut, ObjectOut, OutputLine, StatsLine, WallOut};
use crate::scene_line::SceneLine;

/// One finished frame, as the loop hands it to its sinks.
pub struct FrameView<'a> {
    /// The revolution behind the frame.
    pub rev: &'a Revolution,
    /// The LiDAR's pose on the robot.
    pub mount: Pose2,
    /// Ranges by 1° bin, m (0 = not drawn).
    pub ranges: &'a [f32; SCAN_COLUMNS],
    /// The output line (frame, time, pose, objects, walls, doors, timing, faults, LiDAR).
    pub line: OutputLine<'a>,
    /// The robot's pose in the map at the first ray.
    pub pose: Pose2,
    /// LiDAR bytes read since the recording last took them (empty unless recording).
    pub raw: &'a [u8],
    /// Samples the pose filter was fed since the recording last took them.
    pub odom: &'a [OdomRecord],
}

/// What the loop holds when the run ends.
pub struct RunEnd<'a> {
    /// Frames handed out.
    pub frames: u64,
    /// Sensor time covered, s.
    pub sensor_seconds: f64,
    /// Method A's global cloud, m.
    pub cloud: &'a [Point2],
    /// The robot's last pose.
    pub robot: Pose2,
    /// The last frame's objects.
    pub objects: &'a [ObjectOut],
    /// The last frame's walls.
    pub walls: &'a [WallOut],
    /// The last frame's doors.
    pub doors: &'a [DoorOut],
}

/// Takes every finished frame, and the run's end.
pub trait FrameSink {
    /// One frame. `Ok(true)` when the sink took the recording input (`raw`, `odom`): the loop
    /// then starts collecting anew. An error ends the run (an output that cannot be written).
    fn frame(&mut self, f: &FrameView<'_>) -> io::Result<bool>;
    /// The run ended: flush, close, draw. An error ends the run with it.
    fn finish(&mut self, _end: &RunEnd<'_>) -> io::Result<()> {
        Ok(())
    }
    /// Frames this sink had to drop (its thread was behind).
    fn dropped(&self) -> u64 {
        0
    }
    /// Whether the sink wants the recording input (the LiDAR's bytes, the odometry journal).
    fn records_input(&self) -> bool {
        false
    }
    /// Called between frames, outside the frame's time, only when the source does not pace
    /// itself (`--speed max`, a file): waits until the sink can take the next frame without
    /// dropping it. Nothing is lost by waiting for a simulation or a file, so such a run's
    /// recording is complete; a real sensor's run never waits here.
    fn make_room(&mut self) {}
}

/// One JSON line a frame (`--jsonl PATH|-`).
pub struct JsonlSink(pub Box<dyn Write>);

impl FrameSink for JsonlSink {
    fn frame(&mut self, f: &FrameView<'_>) -> io::Result<bool> {
        f.line.write_to(&mut self.0)?;
        Ok(false)
    }
    fn finish(&mut self, _end: &RunEnd<'_>) -> io::Result<()> {
        self.0.flush()
    }
}

/// One human-readable line a frame: what the robot sees ([`SceneLine`]).
pub struct SceneSink(pub Box<dyn Write>);

impl FrameSink for SceneSink {
    fn frame(&mut self, f: &FrameView<'_>) -> io::Result<bool> {
        writeln!(self.0, "{}", SceneLine(&f.line))?;
        Ok(false)
    }
    fn finish(&mut self, _end: &RunEnd<'_>) -> io::Result<()> {
        self.0.flush()
    }
}

/// One human-readable statistics line a revolution (`--verbose`).
pub struct StatsSink(pub Box<dyn Write>);

impl FrameSink for StatsSink {
    fn frame(&mut self, f: &FrameView<'_>) -> io::Result<bool> {
        writeln!(
            self.0,
            "{}",
            StatsLine {
                frame: f.line.frame,
                rev: f.rev
            }
        )?;
        Ok(false)
    }
    fn finish(&mut self, _end: &RunEnd<'_>) -> io::Result<()> {
        self.0.flush()
    }
}
