//! Recording and live view: the frame loop's results as Foxglove's well-known schemas, written
//! to an MCAP file (`--record PATH`) and/or served over Foxglove's WebSocket protocol
//! (`--live HOST:PORT`), through the Foxglove SDK (`foxglove` crate).
//!
//! Channels (one [`foxglove::Context`] a run):
//! * `/scan` `foxglove.LaserScan` in frame `lidar`: the revolution's 360 bins (no return = NaN);
//! * `/tf` `foxglove.FrameTransforms`: `map → base_link` (the pose at the first ray) and
//!   `base_link → lidar` (the mount);
//! * `/pose` `foxglove.PoseInFrame` in `map`;
//! * `/perception` `foxglove.SceneUpdate` in `map`: objects (a cube coloured by class and a
//!   label `class score source`), walls (a line list), doors (a thin cube);
//! * for replay (`umbra replay RUN.mcap`, [`crate::recording`]): `/umbra/lidar_raw`, the LiDAR's
//!   bytes exactly as read (message encoding `application/octet-stream`, no schema; channel
//!   metadata names the model and, for the simulated robot, its compass calibration), and
//!   `/umbra/odometry`, every encoder/compass sample as the `--odom` JSON object of
//!   `docs/interfaces.md` §2 plus the frame at which it became available to the pose (encoding
//!   `json`, a JSON Schema).
//!
//! The frame loop never allocates for this: it fills a [`VizFrame`] taken from a pool of
//! boxes made at start-up and hands it to the viz thread through a bounded channel; the thread
//! converts, logs and returns the box. When the thread falls behind a real sensor, frames are
//! dropped and counted ([`VizLink::dropped`]), never queued without bound; when the source
//! does not pace itself (`--speed max`, a file) the loop waits between frames for a free box
//! instead ([`VizLink::wait_for_room`]), so that run's recording is complete.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

use foxglove::schemas::{
    Color, CubePrimitive, FrameTransform, FrameTransforms, LaserScan, LinePrimitive, Point3, Pose,
    PoseInFrame, Quaternion, SceneEntity, SceneUpdate, TextPrimitive, Timestamp, Vector3,
    line_primitive,
};
use foxglove::{Channel, ChannelBuilder, Context, RawChannel, Schema};
use perception::class::ObjectClass;
use perception::geometry::Pose2;
use perception::raster::SCAN_COLUMNS;

use crate::odom::OdomRecord;
use crate::output::{DoorOut, ObjectOut, WallOut};
use crate::record_format::{
    ODOM_SCHEMA, ODOM_TOPIC, RAW_ENCODING, RAW_TOPIC, RECORD_RAW_BYTES, RecordedSample,
};
use crate::sink::{FrameSink, FrameView, RunEnd};

/// LiDAR bytes a frame carries to the recording ([`RECORD_RAW_BYTES`]), so a frame's bytes fit
/// even when the viz thread was behind for a few frames.
pub const RAW_BYTES: usize = RECORD_RAW_BYTES;
/// Encoder/compass samples a frame carries to the recording (20 Hz: 4 a frame).
pub const VIZ_ODOM: usize = crate::odom::JOURNAL_LEN;

/// Objects a frame carries to the viz thread.
pub const VIZ_OBJECTS: usize = 64;
/// Walls a frame carries.
pub const VIZ_WALLS: usize = perception::walls::MAX_SEGMENTS;
/// Doors a frame carries.
pub const VIZ_DOORS: usize = perception::doors::MAX_DOORS;
/// Frames in flight between the loop and the viz thread (the pool's size).
pub const VIZ_POOL: usize = 4;

/// One frame's results, copied out of the loop's buffers.
#[derive(Debug, Clone)]
pub struct VizFrame {
    /// Frame number.
    pub frame: u64,
    /// Sensor-clock time of the first ray, s.
    pub t: f64,
    /// Robot pose in the map at the first ray.
    pub pose: Pose2,
    /// The LiDAR's pose on the robot.
    pub mount: Pose2,
    /// Ranges by 1° bin, m (0 = no return).
    pub ranges: [f32; SCAN_COLUMNS],
    /// Objects.
    pub objects: heapless::Vec<ObjectOut, VIZ_OBJECTS>,
    /// Walls.
    pub walls: heapless::Vec<WallOut, VIZ_WALLS>,
    /// Doors.
    pub doors: heapless::Vec<DoorOut, VIZ_DOORS>,
    /// LiDAR bytes read since the last frame recorded.
    pub raw: heapless::Vec<u8, RAW_BYTES>,
    /// Samples fed to the pose filter since the last frame recorded.
    pub odom: heapless::Vec<OdomRecord, VIZ_ODOM>,
}

impl Default for VizFrame {
    fn default() -> Self {
        VizFrame {
            frame: 0,
            t: 0.0,
            pose: Pose2::IDENTITY,
            mount: Pose2::IDENTITY,
            ranges: [0.0; SCAN_COLUMNS],
            objects: heapless::Vec::new(),
            walls: heapless::Vec::new(),
            doors: heapless::Vec::new(),
            raw: heapless::Vec::new(),
            odom: heapless::Vec::new(),
        }
    }
}

/// Where the viz thread sends frames.
#[derive(Debug, Clone, Default)]
pub struct VizTargets {
    /// MCAP file to write.
    pub record: Option<PathBuf>,
    /// Address to serve the live view on.
    pub live: Option<SocketAddr>,
    /// What the source is (`model`, `source`, and the simulated compass's calibration),
    /// written as the raw channel's metadata for replay.
    pub meta: std::collections::BTreeMap<String, String>,
}

/// The loop's end of the viz thread.
pub struct VizLink {
    to_thread: Option<SyncSender<Box<VizFrame>>>,
    pool: Receiver<Box<VizFrame>>,
    thread: Option<JoinHandle<Result<(), String>>>,
    /// A free box taken by [`VizLink::wait_for_room`], used by the next [`VizLink::send`].
    spare: Option<Box<VizFrame>>,
    dropped: u64,
    sent: u64,
    live_port: Option<u16>,
}

impl std::fmt::Debug for VizLink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VizLink")
            .field("sent", &self.sent)
            .field("dropped", &self.dropped)
            .finish()
    }
}

impl VizLink {
    /// Opens the MCAP file and/or starts the live server, and the thread that feeds them.
    /// Errors name the file or address.
    pub fn start(targets: &VizTargets) -> Result<VizLink, String> {
        let ctx = Context::new();
        let mcap = match &targets.record {
            Some(path) => Some(
                foxglove::McapWriter::new()
                    .context(&ctx)
                    .create_new_buffered_file(path)
                    .map_err(|e| format!("--record {}: {e}", path.display()))?,
            ),
            None => None,
        };
        let (server, live_port) = match targets.live {
            Some(addr) => {
                let s = foxglove::WebSocketServer::new()
                    .name("umbra")
                    .context(&ctx)
                    .bind(addr.ip().to_string(), addr.port())
                    .start_blocking()
                    .map_err(|e| format!("--live {addr}: {e}"))?;
                let port = s.port();
                (Some(s), Some(port))
            }
            None => (None, None),
        };
        let channels = Channels::new(&ctx, &targets.meta)?;
        let (to_thread, from_loop) = sync_channel::<Box<VizFrame>>(VIZ_POOL);
        let (to_pool, pool) = sync_channel::<Box<VizFrame>>(VIZ_POOL);
        for _ in 0..VIZ_POOL {
            let _ = to_pool.try_send(Box::default());
        }
        let thread = std::thread::Builder::new()
            .name("umbra-viz".into())
            .spawn(move || {
                // Channels close when their context goes: the thread keeps it.
                let _ctx = ctx;
                for frame in from_loop.iter() {
                    channels.log(&frame);
                    let _ = to_pool.try_send(frame);
                }
                if let Some(s) = server {
                    s.stop().wait_blocking();
                }
                match mcap {
                    Some(w) => w.close().map(|_| ()).map_err(|e| format!("--record: {e}")),
                    None => Ok(()),
                }
            })
            .map_err(|e| format!("cannot start the viz thread: {e}"))?;
        Ok(VizLink {
            to_thread: Some(to_thread),
            pool,
            thread: Some(thread),
            spare: None,
            dropped: 0,
            sent: 0,
            live_port,
        })
    }

    /// The live server's port (useful with port 0).
    pub fn live_port(&self) -> Option<u16> {
        self.live_port
    }

    /// Hands one frame to the viz thread: `fill` writes it into a pooled box. Without a free
    /// box (the thread is behind) the frame is dropped and counted, and `false` returned (the
    /// caller keeps its raw bytes for the next frame). Allocates nothing.
    pub fn send(&mut self, fill: impl FnOnce(&mut VizFrame)) -> bool {
        let Some(mut frame) = self.spare.take().or_else(|| self.pool.try_recv().ok()) else {
            self.dropped += 1;
            return false;
        };
        fill(&mut frame);
        match self.to_thread.as_ref().map(|tx| tx.try_send(frame)) {
            Some(Ok(())) => {
                self.sent += 1;
                true
            }
            Some(Err(TrySendError::Full(_) | TrySendError::Disconnected(_))) | None => {
                self.dropped += 1;
                false
            }
        }
    }

    /// Blocks until a box is free (the viz thread has caught up by one frame), so the next
    /// [`VizLink::send`] cannot drop. Returns at once when a box is already held or the thread
    /// has ended (its end of the pool is gone). Allocates nothing.
    pub fn wait_for_room(&mut self) {
        if self.spare.is_none() {
            self.spare = self.pool.recv().ok();
        }
    }

    /// Frames dropped because the viz thread was behind.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Frames handed over.
    pub fn sent(&self) -> u64 {
        self.sent
    }

    /// Lets the thread finish what it has, closes the MCAP file and stops the server.
    pub fn finish(mut self) -> Result<(), String> {
        self.to_thread = None;
        match self.thread.take().map(|t| t.join()) {
            Some(Ok(r)) => r,
            Some(Err(_)) => Err("the viz thread panicked".into()),
            None => Ok(()),
        }
    }
}

/// Recording and the live view as a frame sink: each frame is copied into a pooled
/// [`VizFrame`] with the LiDAR bytes and odometry read since the last one it took.
pub struct VizSink(Option<VizLink>);

impl VizSink {
    /// A sink over a started link.
    pub fn new(link: VizLink) -> Self {
        VizSink(Some(link))
    }
}

impl FrameSink for VizSink {
    fn frame(&mut self, f: &FrameView<'_>) -> std::io::Result<bool> {
        let Some(link) = self.0.as_mut() else {
            return Ok(false);
        };
        Ok(link.send(|v| {
            v.raw.clear();
            let _ = v
                .raw
                .extend_from_slice(&f.raw[..f.raw.len().min(RAW_BYTES)]);
            v.odom.clear();
            for r in f.odom {
                let _ = v.odom.push(*r);
            }
            v.frame = f.line.frame;
            v.t = f.line.t;
            v.pose = f.pose;
            v.mount = f.mount;
            v.ranges.copy_from_slice(f.ranges);
            v.objects.clear();
            v.walls.clear();
            v.doors.clear();
            for o in f.line.objects {
                let _ = v.objects.push(o.clone());
            }
            for w in f.line.walls {
                let _ = v.walls.push(w.clone());
            }
            for d in f.line.doors {
                let _ = v.doors.push(d.clone());
            }
        }))
    }
    fn finish(&mut self, _end: &RunEnd<'_>) -> std::io::Result<()> {
        if let Some(link) = self.0.take()
            && let Err(e) = link.finish()
        {
            log::error!("{e}");
        }
        Ok(())
    }
    fn dropped(&self) -> u64 {
        self.0.as_ref().map_or(0, VizLink::dropped)
    }
    fn make_room(&mut self) {
        if let Some(link) = self.0.as_mut() {
            link.wait_for_room();
        }
    }
    fn records_input(&self) -> bool {
        self.0.is_some()
    }
}

impl Drop for VizLink {
    fn drop(&mut self) {
        self.to_thread = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

struct Channels {
    scan: Channel<LaserScan>,
    tf: Channel<FrameTransforms>,
    pose: Channel<PoseInFrame>,
    scene: Channel<SceneUpdate>,
    raw: Arc<RawChannel>,
    odom: Arc<RawChannel>,
}

fn ts(t: f64) -> Option<Timestamp> {
    Some(Timestamp::saturating_from_epoch_secs_f64(t.max(0.0)))
}

fn pose3(x: f64, y: f64, z: f64, theta: f64) -> Option<Pose> {
    Some(Pose {
        position: Some(Vector3 { x, y, z }),
        orientation: Some(yaw(theta)),
    })
}

fn yaw(theta: f64) -> Quaternion {
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: (theta / 2.0).sin(),
        w: (theta / 2.0).cos(),
    }
}

/// Colour of a class (Okabe–Ito, readable by colour-blind viewers).
fn colour(class: ObjectClass) -> Color {
    let (r, g, b) = match class {
        ObjectClass::Chair => (0.90, 0.62, 0.0),
        ObjectClass::Box => (0.34, 0.71, 0.91),
        ObjectClass::Desk => (0.0, 0.62, 0.45),
        ObjectClass::DoorFrame => (0.80, 0.47, 0.65),
    };
    Color { r, g, b, a: 0.8 }
}

impl Channels {
    fn new(
        ctx: &Arc<Context>,
        meta: &std::collections::BTreeMap<String, String>,
    ) -> Result<Self, String> {
        let raw = ChannelBuilder::new(RAW_TOPIC)
            .context(ctx)
            .message_encoding(RAW_ENCODING)
            .metadata(meta.clone())
            .build_raw()
            .map_err(|e| format!("{RAW_TOPIC}: {e}"))?;
        let odom = ChannelBuilder::new(ODOM_TOPIC)
            .context(ctx)
            .message_encoding("json")
            .schema(Schema::new(
                "umbra.Odometry",
                "jsonschema",
                ODOM_SCHEMA.as_bytes().to_vec(),
            ))
            .build_raw()
            .map_err(|e| format!("{ODOM_TOPIC}: {e}"))?;
        Ok(Channels {
            scan: ChannelBuilder::new("/scan").context(ctx).build(),
            tf: ChannelBuilder::new("/tf").context(ctx).build(),
            pose: ChannelBuilder::new("/pose").context(ctx).build(),
            scene: ChannelBuilder::new("/perception").context(ctx).build(),
            raw,
            odom,
        })
    }

    fn log(&self, f: &VizFrame) {
        // Replay inputs first: the samples and bytes that made this frame.
        for r in &f.odom {
            let msg = RecordedSample {
                frame: f.frame,
                sample: *r,
            };
            if let Ok(json) = serde_json::to_vec(&msg) {
                self.odom.log(&json);
            }
        }
        if !f.raw.is_empty() {
            self.raw.log(&f.raw);
        }
        let stamp = ts(f.t);
        self.scan.log(&LaserScan {
            timestamp: stamp,
            frame_id: "lidar".into(),
            pose: pose3(0.0, 0.0, 0.0, 0.0),
            start_angle: 0.0,
            end_angle: (SCAN_COLUMNS as f64 - 1.0).to_radians(),
            ranges: f
                .ranges
                .iter()
                .map(|&r| if r > 0.0 { f64::from(r) } else { f64::NAN })
                .collect(),
            intensities: Vec::new(),
        });
        let (p, m) = (&f.pose, &f.mount);
        self.tf.log(&FrameTransforms {
            transforms: vec![
                FrameTransform {
                    timestamp: stamp,
                    parent_frame_id: "map".into(),
                    child_frame_id: "base_link".into(),
                    translation: Some(Vector3 {
                        x: f64::from(p.x),
                        y: f64::from(p.y),
                        z: 0.0,
                    }),
                    rotation: Some(yaw(f64::from(p.theta))),
                },
                FrameTransform {
                    timestamp: stamp,
                    parent_frame_id: "base_link".into(),
                    child_frame_id: "lidar".into(),
                    translation: Some(Vector3 {
                        x: f64::from(m.x),
                        y: f64::from(m.y),
                        z: 0.17,
                    }),
                    rotation: Some(yaw(f64::from(m.theta))),
                },
            ],
        });
        self.pose.log(&PoseInFrame {
            timestamp: stamp,
            frame_id: "map".into(),
            pose: pose3(f64::from(p.x), f64::from(p.y), 0.0, f64::from(p.theta)),
        });
        let objects = SceneEntity {
            timestamp: stamp,
            frame_id: "map".into(),
            id: "objects".into(),
            cubes: f
                .objects
                .iter()
                .map(|o| CubePrimitive {
                    pose: pose3(o.x, o.y, 0.2, 0.0),
                    size: Some(Vector3 {
                        x: 0.4,
                        y: 0.4,
                        z: 0.4,
                    }),
                    color: Some(colour(o.class)),
                })
                .chain(f.doors.iter().map(|d| CubePrimitive {
                    pose: pose3(d.x, d.y, 1.0, 0.0),
                    size: Some(Vector3 {
                        x: 0.05,
                        y: d.width,
                        z: 2.0,
                    }),
                    color: Some(colour(ObjectClass::DoorFrame)),
                }))
                .collect(),
            texts: f
                .objects
                .iter()
                .map(|o| TextPrimitive {
                    pose: pose3(o.x, o.y, 0.6, 0.0),
                    billboard: true,
                    font_size: 14.0,
                    scale_invariant: true,
                    color: Some(Color {
                        r: 1.0,
                        g: 1.0,
                        b: 1.0,
                        a: 1.0,
                    }),
                    text: format!("{} {:.2} {}", o.class, o.score, o.source.as_str()),
                })
                .collect(),
            lines: vec![LinePrimitive {
                r#type: line_primitive::Type::LineList as i32,
                pose: pose3(0.0, 0.0, 0.0, 0.0),
                thickness: 0.03,
                scale_invariant: false,
                points: f
                    .walls
                    .iter()
                    .flat_map(|w| {
                        [
                            Point3 {
                                x: w.x0,
                                y: w.y0,
                                z: 0.0,
                            },
                            Point3 {
                                x: w.x1,
                                y: w.y1,
                                z: 0.0,
                            },
                        ]
                    })
                    .collect(),
                color: Some(Color {
                    r: 0.85,
                    g: 0.85,
                    b: 0.85,
                    a: 1.0,
                }),
                colors: Vec::new(),
                indices: Vec::new(),
            }],
            ..Default::default()
        };
        self.scene.log(&SceneUpdate {
            deletions: Vec::new(),
            entities: vec![objects],
        });
    }
}
