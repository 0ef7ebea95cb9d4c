//! Where LiDAR bytes come from: a serial port (read by its own thread, [`crate::reader`]), a
//! raw capture file, or the simulated robot. All three hand bytes to the same decoder.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[cfg(feature = "sim")]
use drivers::lds01::PACKET_LEN;
use drivers::lidar::LidarModel;
use drivers::lidar::detect::{Detector, Verdict};
use drivers::serial::{SerialConfig, SerialLink};
use embedded_io::Read as _;
use embedded_io_adapters::std::FromStd;
#[cfg(feature = "sim")]
use sim::lds01::Lds01Sim;
#[cfg(feature = "sim")]
use sim::scenario::{Scenario, ScenarioConfig};

use crate::odom::OdomRecord;
use crate::reader::{LidarEvent, LidarReader};

/// What one read gave.
#[derive(Debug)]
pub enum SourceRead {
    /// Bytes in the buffer.
    Data(usize),
    /// Nothing yet.
    Idle,
    /// The source ended (end of a capture file).
    End,
    /// The link was lost (it will be reopened); the message names the device.
    Lost(String),
    /// The link came back.
    Reopened,
}

/// Whether the loop paces itself by the sensor clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pacing {
    /// As fast as possible.
    Max,
    /// Wall time follows the sensor clock.
    RealTime,
}

/// A LiDAR byte source.
pub enum LidarSource {
    /// A serial port that reopens itself, read by its own thread, and the model on it.
    Serial {
        /// The reader thread's end.
        reader: LidarReader,
        /// The model on the port.
        model: LidarModel,
        /// When the last bytes handed out were read.
        last_host: Option<Instant>,
    },
    /// A raw capture file read through `embedded-io`.
    Capture {
        /// The file's path, for messages.
        path: PathBuf,
        /// The file.
        file: FromStd<File>,
        /// The model whose bytes it holds.
        model: LidarModel,
    },
    /// LiDAR bytes held in memory: the raw channel of an MCAP recording
    /// ([`crate::recording`]).
    Recorded {
        /// The recording's path, for messages.
        path: PathBuf,
        /// The bytes and the read position.
        bytes: std::io::Cursor<Vec<u8>>,
        /// The model whose bytes they are.
        model: LidarModel,
    },
    /// A CARMEN log's text, read (and gunzipped) at start-up ([`crate::carmen`]).
    Log {
        /// The log's path, for messages.
        path: PathBuf,
        /// The text and the read position.
        text: std::io::Cursor<Vec<u8>>,
        /// The laser's offset forward of the robot's centre (`robot_frontlaser_offset`), m.
        laser_offset_m: Option<f32>,
    },
    /// The built-in simulated robot (feature `sim`).
    #[cfg(feature = "sim")]
    Sim {
        /// The simulator.
        sim: Box<Lds01Sim>,
        /// Room seed, for messages.
        room_seed: u64,
        /// Hard iron and field reference from a calibration spin of the simulated compass.
        calibration: Option<([f32; 2], [f32; 2])>,
    },
}

/// How long the prober listens at each baud rate, ms (a few revolutions of any model).
pub const PROBE_LISTEN_MS: u64 = 1500;
/// Bytes of a capture read to recognise its model (several revolutions of any model).
pub const DETECT_BYTES: usize = 64 * 1024;

/// Recognises the model whose bytes `head` holds (a capture's or a recording's first
/// [`DETECT_BYTES`]); `what` names the file in messages. Frames with a high error rate are
/// used, with a warning; an RPLIDAR is taken for an A1 (an A2 sends the same bytes), with a
/// warning; no frames at all is an error.
fn recognise(head: &[u8], what: &str) -> Result<(LidarModel, String), String> {
    let mut det = Detector::new();
    det.feed(head);
    let verdict = det.verdict();
    let words = drivers::probe::describe(&verdict);
    if let Verdict::Found { model, .. } | Verdict::HighErrorRate { model, .. } = verdict
        && model.family() == drivers::lidar::Family::Rplidar
    {
        log::warn!(
            "{what}: an RPLIDAR A1 and A2 send the same bytes and nodes carry no time; the clock assumes the A1's 2 kHz (name --lidar-model rplidar-a2 for an A2)"
        );
    }
    match verdict {
        Verdict::Found { model, .. } => Ok((model, format!("recognised: {words}"))),
        Verdict::HighErrorRate { model, .. } => {
            log::warn!("{what}: {words}");
            Ok((model, format!("{model} recognised despite errors")))
        }
        _ => Err(format!(
            "{what}: no LiDAR recognised in its first {} bytes: {words}",
            head.len()
        )),
    }
}

/// How long a read of a serial source waits for the reader thread.
pub const SERIAL_WAIT: Duration = Duration::from_millis(20);

/// Packets the simulated source produces per read (a tenth of a revolution).
pub const SIM_PACKETS_PER_READ: usize = 6;

impl LidarSource {
    /// Opens a serial port for `model`, or (`None`) finds out which LiDAR is there
    /// ([`drivers::probe`]); the second value says what was found. A port where no LiDAR is
    /// recognised is an error naming the port and, per baud rate, what was seen.
    pub fn serial(path: &str, model: Option<LidarModel>) -> Result<(Self, String), String> {
        if let Some(model) = model {
            let link =
                SerialLink::open(path, SerialConfig::lidar(model)).map_err(|e| e.to_string())?;
            return Ok((
                LidarSource::threaded(link, model)?,
                format!("{model} named on {path}"),
            ));
        }
        let probe = drivers::probe::probe(
            path,
            &drivers::probe::PROBE_BAUDS,
            std::time::Duration::from_millis(PROBE_LISTEN_MS),
        )
        .map_err(|e| e.to_string())?;
        let summary = probe.summary();
        match probe.found {
            Some((model, baud, port)) => {
                let cfg = SerialConfig {
                    baud,
                    ..SerialConfig::lidar(model)
                };
                Ok((
                    LidarSource::threaded(SerialLink::from_open(path, cfg, port), model)?,
                    summary,
                ))
            }
            None => Err(summary),
        }
    }

    fn threaded(link: SerialLink, model: LidarModel) -> Result<Self, String> {
        Ok(LidarSource::Serial {
            reader: LidarReader::start(link)?,
            model,
            last_host: None,
        })
    }

    #[cfg(feature = "viz")]
    /// The LiDAR bytes of a recording, of `model` or (`None`) of the model the recording names,
    /// else recognised from the bytes.
    pub fn recorded(
        rec: &mut crate::recording::Recording,
        model: Option<LidarModel>,
    ) -> Result<(Self, String), String> {
        let shown = rec.path.display().to_string();
        if rec.format.as_deref() == Some("carmen") {
            let text = std::mem::take(&mut rec.bytes);
            return Ok((
                LidarSource::log(&rec.path, text),
                "a CARMEN log's text, as the recording says".into(),
            ));
        }
        let (model, how) = match (model, rec.model) {
            (Some(m), _) => (m, format!("{m} named")),
            (None, Some(m)) => (m, format!("{m}, as the recording says")),
            (None, None) => recognise(
                &rec.bytes[..rec.bytes.len().min(DETECT_BYTES)],
                &format!("recording {shown}"),
            )?,
        };
        Ok((
            LidarSource::Recorded {
                path: rec.path.clone(),
                bytes: std::io::Cursor::new(std::mem::take(&mut rec.bytes)),
                model,
            },
            how,
        ))
    }

    /// Opens a raw capture file of `model`, or (`None`) recognises the model from its first
    /// [`DETECT_BYTES`] bytes. A file in which no model's frames are found is an error.
    pub fn capture(path: &Path, model: Option<LidarModel>) -> Result<(Self, String), String> {
        use std::io::{Read as _, Seek as _};
        let mut file =
            File::open(path).map_err(|e| format!("cannot open capture {}: {e}", path.display()))?;
        let (model, how) = match model {
            Some(m) => (m, format!("{m} named")),
            None => {
                // Read the head, then rewind: the run decodes the capture from its first byte.
                let mut head = Vec::with_capacity(DETECT_BYTES);
                (&mut file)
                    .take(DETECT_BYTES as u64)
                    .read_to_end(&mut head)
                    .and_then(|_| file.rewind())
                    .map_err(|e| format!("cannot read capture {}: {e}", path.display()))?;
                recognise(&head, &format!("capture {}", path.display()))?
            }
        };
        Ok((
            LidarSource::Capture {
                path: path.to_owned(),
                file: FromStd::new(file),
                model,
            },
            how,
        ))
    }

    /// The model whose bytes this source gives (`None`: a log, not a LiDAR's bytes).
    pub fn model(&self) -> Option<LidarModel> {
        match self {
            LidarSource::Serial { model, .. } => Some(*model),
            LidarSource::Capture { model, .. } | LidarSource::Recorded { model, .. } => {
                Some(*model)
            }
            LidarSource::Log { .. } => None,
            #[cfg(feature = "sim")]
            LidarSource::Sim { .. } => Some(LidarModel::Lds01),
        }
    }

    /// A CARMEN log (its text in memory).
    pub fn log(path: &Path, text: Vec<u8>) -> Self {
        LidarSource::Log {
            path: path.to_owned(),
            laser_offset_m: crate::carmen::front_laser_offset(&text),
            text: std::io::Cursor::new(text),
        }
    }

    /// Where the laser sits on the robot when the source says so (a CARMEN log's
    /// `robot_frontlaser_offset`); `None`: the configuration's mount.
    pub fn mount(&self) -> Option<perception::geometry::Pose2> {
        match self {
            LidarSource::Log {
                laser_offset_m: Some(x),
                ..
            } => Some(perception::geometry::Pose2::new(*x, 0.0, 0.0)),
            _ => None,
        }
    }

    /// The simulated robot in a seeded random room (the study's oscillation in place), with
    /// encoders and a compass at 20 Hz; the compass is calibrated by a simulated two-turn spin,
    /// as `umbra calibrate-compass` would on a robot.
    #[cfg(feature = "sim")]
    pub fn sim(room_seed: u64, _noise_seed: u64) -> Self {
        let scenario = Scenario::new(room_seed, &ScenarioConfig::standard());
        let readings = scenario.compass_spin_readings();
        let calibration = crate::calibrate::fit(&readings).ok().map(|c| {
            (
                [c.hard_iron.x_ut, c.hard_iron.y_ut],
                [c.hard_iron.field_ut, c.vertical_ut],
            )
        });
        LidarSource::Sim {
            sim: Box::new(Lds01Sim::from_scenario(scenario)),
            room_seed,
            calibration,
        }
    }

    /// What a recording says of this source, for replay: `model` (its `--lidar-model` name),
    /// `source` (this source's description) and, for the simulator, its compass calibration
    /// (`compass_calibration`: hard iron x, y, field horizontal, vertical, µT).
    pub fn recording_meta(&self) -> std::collections::BTreeMap<String, String> {
        let mut m = std::collections::BTreeMap::new();
        match self.model() {
            Some(model) => m.insert("model".into(), model.cli_name().into()),
            None => m.insert("format".into(), "carmen".into()),
        };
        m.insert("source".into(), self.describe());
        if let Some((h, f)) = self.sim_calibration() {
            m.insert(
                "compass_calibration".into(),
                format!("{} {} {} {}", h[0], h[1], f[0], f[1]),
            );
        }
        m
    }

    /// The calibration (hard iron, field reference) of the simulated compass, if this is the
    /// simulator.
    pub fn sim_calibration(&self) -> Option<([f32; 2], [f32; 2])> {
        match self {
            #[cfg(feature = "sim")]
            LidarSource::Sim { calibration, .. } => *calibration,
            _ => None,
        }
    }

    /// Hands encoder/compass samples the source produced to `out` (the simulator only).
    #[cfg_attr(not(feature = "sim"), allow(unused_variables))]
    pub fn drain_odometry(&mut self, out: &mut dyn FnMut(OdomRecord)) {
        #[cfg(feature = "sim")]
        if let LidarSource::Sim { sim, .. } = self {
            for o in sim.drain_odometry() {
                out(OdomRecord {
                    t: o.t,
                    left_ticks: Some(i64::from(o.left_ticks)),
                    right_ticks: Some(i64::from(o.right_ticks)),
                    mag_ut: Some(o.mag_ut),
                });
            }
        }
    }

    /// One line saying what this source is.
    pub fn describe(&self) -> String {
        match self {
            LidarSource::Serial { reader, model, .. } => {
                format!("{model} on serial port {}", reader.path())
            }
            LidarSource::Capture { path, model, .. } => {
                format!("raw {model} capture {}", path.display())
            }
            LidarSource::Recorded { path, model, .. } => {
                format!("{model} bytes recorded in {}", path.display())
            }
            LidarSource::Log { path, .. } => format!("CARMEN log {}", path.display()),
            #[cfg(feature = "sim")]
            LidarSource::Sim { sim, room_seed, .. } => format!(
                "no hardware named: running on the built-in simulated robot (LDS-01; seed {room_seed}: {})",
                sim.world().describe()
            ),
        }
    }

    /// Default pacing: live sources are paced by the device itself (serial) or by the sensor
    /// clock (the simulator, so it behaves like the robot); files run as fast as possible.
    pub fn is_simulated(&self) -> bool {
        #[cfg(feature = "sim")]
        return matches!(self, LidarSource::Sim { .. });
        #[cfg(not(feature = "sim"))]
        false
    }

    /// A capture file: bytes with no timing of their own (no silence, so no staleness).
    pub fn is_file(&self) -> bool {
        matches!(
            self,
            LidarSource::Capture { .. } | LidarSource::Recorded { .. } | LidarSource::Log { .. }
        )
    }

    /// Bytes from a serial port not yet decoded: queued by the reader thread plus waiting in
    /// the kernel (`None` for other sources or a closed port).
    pub fn backlog_bytes(&self) -> Option<u32> {
        match self {
            LidarSource::Serial { reader, .. } => reader.backlog_bytes(),
            _ => None,
        }
    }

    /// The reader thread's queue: chunks waiting now, and the deepest it has been (`None` for
    /// sources without a thread).
    pub fn queue_depth(&self) -> Option<(usize, usize)> {
        match self {
            LidarSource::Serial { reader, .. } => {
                Some((reader.queue_depth(), reader.max_queue_depth()))
            }
            _ => None,
        }
    }

    /// When the bytes of the last read came off the port (serial sources only).
    pub fn last_read_host(&self) -> Option<Instant> {
        match self {
            LidarSource::Serial { last_host, .. } => *last_host,
            _ => None,
        }
    }

    /// Reads what is available into `buf`.
    pub fn read(&mut self, buf: &mut [u8]) -> SourceRead {
        match self {
            LidarSource::Serial {
                reader, last_host, ..
            } => match reader.next(SERIAL_WAIT) {
                Some(LidarEvent::Data(chunk)) => {
                    let n = chunk.len.min(buf.len());
                    buf[..n].copy_from_slice(&chunk.data[..n]);
                    *last_host = Some(chunk.host);
                    reader.recycle(chunk);
                    SourceRead::Data(n)
                }
                None => SourceRead::Idle,
                Some(LidarEvent::Lost(msg)) => SourceRead::Lost(msg),
                Some(LidarEvent::Reopened) => SourceRead::Reopened,
            },
            LidarSource::Capture { path, file, .. } => match file.read(buf) {
                Ok(0) => SourceRead::End,
                Ok(n) => SourceRead::Data(n),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => SourceRead::Idle,
                Err(e) => SourceRead::Lost(format!("capture {}: read error: {e}", path.display())),
            },
            LidarSource::Recorded { bytes, .. } | LidarSource::Log { text: bytes, .. } => {
                use std::io::Read as _;
                match bytes.read(buf) {
                    Ok(0) | Err(_) => SourceRead::End,
                    Ok(n) => SourceRead::Data(n),
                }
            }
            #[cfg(feature = "sim")]
            LidarSource::Sim { sim, .. } => {
                let mut n = 0;
                for chunk in buf.chunks_exact_mut(PACKET_LEN).take(SIM_PACKETS_PER_READ) {
                    let mut packet = [0u8; PACKET_LEN];
                    sim.emit_packet(&mut packet);
                    chunk.copy_from_slice(&packet);
                    n += PACKET_LEN;
                }
                SourceRead::Data(n)
            }
        }
    }

    /// Link counters of a serial source: (errors + EOFs, reopens).
    pub fn link_counts(&self) -> (u64, u64) {
        match self {
            LidarSource::Serial { reader, .. } => reader.link_counts(),
            _ => (0, 0),
        }
    }
}
