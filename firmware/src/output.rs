//! The per-frame output: the JSON line of `docs/interfaces.md` §3 and the human-readable
//! per-revolution statistics line.

use std::io::{self, Write};

use drivers::lidar::{LidarFaults, Revolution};
use perception::class::ObjectClass;
use perception::fusion::{Evidence, FrameObject};
use perception::tracks::{Track, Walker};
use serde::{Serialize, Serializer};

/// Pose in the map frame.
#[derive(Debug, Clone, Copy, Serialize, Default, PartialEq)]
pub struct PoseOut {
    /// m
    pub x: f64,
    /// m
    pub y: f64,
    /// rad
    pub theta: f64,
}

/// A detected object.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ObjectOut {
    /// Track id.
    pub id: u32,
    /// `chair`, `box`, `desk` or `door_frame`.
    #[serde(serialize_with = "class_name")]
    pub class: ObjectClass,
    /// Map-frame centre, m.
    pub x: f64,
    /// Map-frame centre, m.
    pub y: f64,
    /// Confidence in [0, 1].
    pub score: f64,
    /// `A`, `B` or `AB`.
    #[serde(serialize_with = "evidence_name")]
    pub source: Evidence,
    /// Method B's box `[cx, cy, w, h]` in pixels of the 384 × 64 input (a frame's B and AB
    /// detections only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bbox: Option<[f64; 4]>,
    /// Frames that observed the object (tracks only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hits: Option<u32>,
    /// The last frame that observed it (tracks only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub last_seen: Option<u64>,
}

impl ObjectOut {
    /// A frame's object as the line carries it; `id` is its place in the frame's list.
    pub fn new(id: usize, o: &FrameObject) -> Self {
        ObjectOut {
            id: id as u32,
            class: o.class,
            x: f64::from(o.centre.x),
            y: f64::from(o.centre.y),
            score: f64::from(o.score),
            source: o.evidence,
            bbox: o.bbox.map(|b| b.map(f64::from)),
            hits: None,
            last_seen: None,
        }
    }

    /// A confirmed track of the world model: its stable id, its most likely class, and a
    /// score that is the belief it exists times the class's share of the evidence.
    pub fn track(t: &Track) -> Self {
        let exists = belief(t);
        ObjectOut {
            id: t.id,
            class: t.class(),
            x: f64::from(t.centre.x),
            y: f64::from(t.centre.y),
            score: exists * f64::from(t.class_score()),
            source: t.evidence(),
            bbox: None,
            hits: Some(t.hits),
            last_seen: Some(t.last_seen),
        }
    }
}

/// A track's existence as a probability in (0, 1) (the logistic of its log-odds).
fn belief(t: &Track) -> f64 {
    1.0 / (1.0 + (-f64::from(t.existence)).exp())
}

/// The wire name of a class (`perception::class`'s names are the contract's).
fn class_name<S: Serializer>(c: &ObjectClass, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(c.as_str())
}

/// The wire name of an object's evidence.
fn evidence_name<S: Serializer>(e: &Evidence, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(e.as_str())
}

/// A wall segment.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct WallOut {
    /// m
    pub x0: f64,
    /// m
    pub y0: f64,
    /// m
    pub x1: f64,
    /// m
    pub y1: f64,
}

/// A door.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct DoorOut {
    /// m
    pub x: f64,
    /// m
    pub y: f64,
    /// m
    pub width: f64,
    /// [0, 1]
    pub score: f64,
}

/// A walking person (the world model's moving tracks; never furniture).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct PersonOut {
    /// Track id (shared with objects' ids: never reused).
    pub id: u32,
    /// Map frame, m.
    pub x: f64,
    /// Map frame, m.
    pub y: f64,
    /// Velocity, map frame, m/s.
    pub vx: f64,
    /// Velocity, map frame, m/s.
    pub vy: f64,
    /// Confidence in [0, 1].
    pub score: f64,
}

impl PersonOut {
    /// From a moving track.
    pub fn track(t: &Track) -> Self {
        PersonOut {
            id: t.id,
            x: f64::from(t.centre.x),
            y: f64::from(t.centre.y),
            vx: f64::from(t.motion.vel.x),
            vy: f64::from(t.motion.vel.y),
            score: belief(t),
        }
    }

    /// From a walker of the leg detector that walks, listed as `id`.
    pub fn walker(id: u32, w: &Walker) -> Self {
        PersonOut {
            id,
            x: f64::from(w.motion.pos.x),
            y: f64::from(w.motion.pos.y),
            vx: f64::from(w.motion.vel.x),
            vy: f64::from(w.motion.vel.y),
            score: f64::from(w.score()),
        }
    }
}

/// Stage times, milliseconds. Stages that do not exist yet are absent, not zero.
#[derive(Debug, Clone, Copy, Serialize, Default, PartialEq)]
pub struct TimingOut {
    /// Reading and decoding the revolution's bytes.
    pub ingest: f64,
    /// Feeding odometry and compass to the pose filter.
    pub pose: f64,
    /// Method A, cloud update to labelled objects (absent when Method A is off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub method_a: Option<f64>,
    /// Method B, raster to decoded boxes (absent when off and for the first two
    /// revolutions, before the raster has its three).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub method_b: Option<f64>,
    /// Writing the previous frame's output line (a line cannot carry its own write time).
    pub output: f64,
    /// Whole frame: the stages above.
    pub total: f64,
}

impl From<crate::deadline::FrameTimes> for TimingOut {
    fn from(t: crate::deadline::FrameTimes) -> Self {
        TimingOut {
            ingest: t.ingest,
            pose: t.pose,
            method_a: t.method_a,
            method_b: t.method_b,
            output: t.output,
            total: t.total,
        }
    }
}

/// Cumulative fault counters (`docs/interfaces.md` names first, extra keys after).
#[derive(Debug, Clone, Copy, Serialize, Default, PartialEq, Eq)]
pub struct FaultsOut {
    /// Bytes not part of any packet passed on.
    pub lidar_bytes_skipped: u64,
    /// Packets (LDS-01) or frames (LDROBOT CRC-8) whose checksum failed.
    pub lidar_bad_checksum: u64,
    /// Packets (LDS-01) or 6° sectors (other models) missing from revolutions.
    pub lidar_missing_packets: u64,
    /// Wheel-encoder errors: bad odometry lines or samples.
    pub encoder_errors: u64,
    /// Compass readings the pose filter rejected (disturbance).
    pub compass_rejected: u64,
    /// Sync bytes followed by a bad index (LDS-01); nodes with an angle ≥ 360° (RPLIDAR).
    pub lidar_bad_index: u64,
    /// Packets received twice.
    pub lidar_repeated_packets: u64,
    /// Bad-checksum packets (kept under `count`) dropped for an out-of-sequence index.
    pub lidar_out_of_sequence_bad_packets: u64,
    /// Revolutions with packets missing.
    pub lidar_incomplete_revolutions: u64,
    /// Readings dropped as invalid (no return, or outside the range window), in received
    /// packets.
    pub lidar_invalid_readings: u64,
    /// LDROBOT frames with a good CRC dropped by the plausibility filter (or speed 0).
    pub lidar_implausible_frames: u64,
    /// Errors the LiDAR reported itself (LDROBOT health frames: blocked motor, occlusion;
    /// RPLIDAR health replies with status error).
    pub lidar_sensor_errors: u64,
    /// LDS-01 packets whose speed field says the motor is stalled (below 60 rpm).
    pub lidar_stalled_packets: u64,
    /// Partial revolutions not made into frames (LDROBOT, RPLIDAR): the lead-in before a
    /// stream's first sweep start and an unfinished last one.
    pub lidar_partial_revolutions_dropped: u64,
    /// Link losses (read errors, hang-ups).
    pub lidar_link_lost: u64,
    /// Link reopens.
    pub lidar_link_reopened: u64,
    /// Compass reads that failed (bus error, timeout).
    pub compass_errors: u64,
    /// Method B frames that failed (raster, inference or decoding error): no B objects.
    pub method_b_errors: u64,
    /// Frames over the deadline.
    pub deadline_missed: u64,
    /// Degraded frames (work shed by the overrun policy).
    pub degraded_frames: u64,
    /// Frames without Method B by the overrun policy (no room left, or decimated).
    pub method_b_skipped: u64,
    /// Frames whose cloud work was shrunk by the overrun policy.
    pub cloud_shrunk: u64,
    /// Encoder/compass samples the device thread dropped because its queue was full (the
    /// loop stalled for seconds).
    pub odometry_dropped: u64,
    /// LiDAR bytes missing from the `--record` file (the recorder was behind for too long).
    pub recording_bytes_dropped: u64,
    /// Odometry samples missing from the `--record` file.
    pub recording_samples_dropped: u64,
    /// Frames that ended with the loop behind the LiDAR (more than a revolution of bytes
    /// queued, or the simulated sensor ahead by more than a revolution).
    pub behind_lidar: u64,
}

impl FaultsOut {
    /// From the LiDAR stream's counters and the link's.
    pub fn new(f: &LidarFaults, invalid_readings: u64, link: (u64, u64)) -> Self {
        FaultsOut {
            lidar_bytes_skipped: f.bytes_skipped,
            lidar_bad_checksum: f.bad_checksum,
            lidar_missing_packets: f.missing_packets,
            encoder_errors: 0,
            compass_rejected: 0,
            lidar_bad_index: f.bad_index,
            lidar_repeated_packets: f.repeated_packets,
            lidar_out_of_sequence_bad_packets: f.out_of_sequence_bad_packets,
            lidar_incomplete_revolutions: f.incomplete_revolutions,
            lidar_invalid_readings: invalid_readings,
            lidar_implausible_frames: f.implausible_frames,
            lidar_sensor_errors: f.sensor_errors,
            lidar_stalled_packets: f.stalled_packets,
            lidar_partial_revolutions_dropped: f.partial_revolutions_dropped,
            lidar_link_lost: link.0,
            lidar_link_reopened: link.1,
            ..FaultsOut::default()
        }
    }
}

/// What this frame's LiDAR revolution looked like (an extra field).
#[derive(Debug, Clone, Copy, Serialize, Default, PartialEq)]
pub struct LidarOut {
    /// Mean motor speed, rpm.
    pub rpm: f64,
    /// Packets received of 60.
    pub packets: u8,
    /// Valid readings of 360.
    pub valid: u32,
    /// Bytes not yet decoded when the frame ended: in the reader thread's queue plus in the
    /// kernel's buffer (a real LiDAR's queue depth).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub backlog_bytes: Option<u32>,
    /// Chunks in the reader thread's queue when the frame ended (serial sources).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub queue_chunks: Option<usize>,
    /// The deepest that queue has been so far (serial sources).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub queue_chunks_max: Option<usize>,
}

/// One output line (`docs/interfaces.md` §3).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct OutputLine<'a> {
    /// Frame number since start.
    pub frame: u64,
    /// Sensor-clock time of the frame's first ray, s.
    pub t: f64,
    /// Robot pose in the map frame.
    pub pose: PoseOut,
    /// Recognised objects: this frame's detections, or with the world model on its confirmed
    /// tracks (stable ids, persistent across frames).
    pub objects: &'a [ObjectOut],
    /// Wall segments.
    pub walls: &'a [WallOut],
    /// Doors.
    pub doors: &'a [DoorOut],
    /// With the world model on (`[world] enabled`): this frame's detections from both methods
    /// (`id` is the place in this list), while `objects` are the confirmed tracks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detections: Option<&'a [ObjectOut]>,
    /// With the world model on: the walking people in view (moving tracks, never in
    /// `objects`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub people: Option<&'a [PersonOut]>,
    /// Stage times.
    pub timing_ms: TimingOut,
    /// The per-frame budget.
    pub deadline_ms: f64,
    /// `true` if the frame took longer than its budget.
    pub deadline_missed: bool,
    /// `true` if work was shed to stay within the budget.
    pub degraded: bool,
    /// Power draw, W (`null`: no power source yet).
    pub power_w: Option<f64>,
    /// Where `power_w` comes from.
    pub power_source: &'a str,
    /// Cumulative fault counters.
    pub faults: FaultsOut,
    /// The revolution behind this frame.
    pub lidar: LidarOut,
}

impl OutputLine<'_> {
    /// Writes the line and a newline.
    pub fn write_to(&self, w: &mut impl Write) -> io::Result<()> {
        serde_json::to_writer(&mut *w, self)?;
        w.write_all(b"\n")
    }
}

/// The human-readable per-revolution line (a `Display`: written straight to its sink, no
/// allocation).
pub struct StatsLine<'a> {
    /// Frame number.
    pub frame: u64,
    /// The revolution.
    pub rev: &'a Revolution,
}

impl core::fmt::Display for StatsLine<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let rev = self.rev;
        write!(
            f,
            "frame {:>6}  t {:>9.3} s  {:>5.1} rpm  packets {:>2}/60  valid {:>3}/360  no-return {:>3}  ",
            self.frame,
            rev.first_ray_time_s(),
            rev.rpm,
            rev.packets,
            rev.valid_count(),
            rev.no_return_count(),
        )?;
        match rev.range_stats() {
            Some((lo, mean, hi)) => write!(f, "range {lo:.2}–{hi:.2} m (mean {mean:.2})"),
            None => f.write_str("no valid range"),
        }
    }
}

#[cfg(test)]
mod test {
    use super::*;

    #[test]
    fn line_has_contract_fields() {
        let line = OutputLine {
            frame: 3,
            t: 0.6,
            pose: PoseOut::default(),
            objects: &[],
            walls: &[],
            doors: &[],
            detections: None,
            people: None,
            timing_ms: TimingOut {
                ingest: 0.1,
                pose: 0.0,
                method_a: None,
                method_b: None,
                output: 0.0,
                total: 0.2,
            },
            deadline_ms: 250.0,
            deadline_missed: false,
            degraded: false,
            power_w: None,
            power_source: "model",
            faults: FaultsOut::default(),
            lidar: LidarOut::default(),
        };
        let mut buf = Vec::new();
        line.write_to(&mut buf).unwrap();
        let v: serde_json::Value = serde_json::from_slice(&buf).unwrap();
        for key in [
            "frame",
            "t",
            "pose",
            "objects",
            "walls",
            "doors",
            "timing_ms",
            "deadline_ms",
            "deadline_missed",
            "degraded",
            "power_w",
            "faults",
        ] {
            assert!(v.get(key).is_some(), "missing {key}");
        }
        for key in [
            "lidar_bytes_skipped",
            "lidar_bad_checksum",
            "lidar_missing_packets",
            "encoder_errors",
            "compass_rejected",
        ] {
            assert!(v["faults"].get(key).is_some(), "missing faults.{key}");
        }
        assert!(buf.ends_with(b"}\n"));
    }
}
