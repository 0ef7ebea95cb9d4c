//! One frame through the pipeline: the revolution's readings and the pose over it, Method A
//! on the global cloud, Method B on the last three revolutions (unless the overrun policy
//! sheds it), the fusion of both (`perception::fusion`), the stage times and the power, then
//! every sink. Everything here is allocated at start-up ([`FrameState::new`]).

use std::io;
use std::time::{Duration, Instant};

use perception::class::ObjectClass;
use perception::cloud::Scan;
use perception::fusion::{Evidence, FrameObjects, merge_b, push_a};
use perception::geometry::{Point2, Pose2};
use perception::legs::{LegConfig, legs_in_map};
use perception::map_doors::{Doorways, MapDoorConfig};
use perception::method_a::{MethodA, MethodAConfig};
use perception::outline::drop_round_boxes;
use perception::plausible::{drop_in_map_walls, drop_walled};
use perception::tracks::{Looked, PEOPLE_FRAMES, Tracks};
use perception::wall_map::WallMap;
use perception::wall_piece::drop_wall_pieces;

use super::FrameLoop;
use super::b_worker::BWorker;
use super::history::{RevolutionPose, ScanHistory};
use super::method_b::MethodBScratch;
use crate::deadline::{DeadlineRecord, FrameTimes, Policy, SHRINK_DROP_FRACTION};
use crate::odom::{FramePose, PoseInput};
use crate::output::{
    DoorOut, FaultsOut, LidarOut, ObjectOut, OutputLine, PersonOut, PoseOut, TimingOut, WallOut,
};
use crate::record_format::RECORD_RAW_BYTES;
use crate::sink::FrameView;
use drivers::lidar::RevolutionStream;

/// A Method B door frame this close to a door of Method A's is that door, m.
const DOOR_SAME_M: f64 = 0.5;

/// Adds a door unless the list is at its start-up capacity (the frame loop never grows it).
fn push_door(doors: &mut Vec<DoorOut>, d: DoorOut) {
    if doors.len() < doors.capacity() {
        doors.push(d);
    }
}

/// What the loop keeps between frames, allocated once at start-up.
pub(super) struct FrameState {
    pub(super) method_a: Box<MethodA>,
    /// The last three revolutions; Method A reads the newest, Method B all three.
    history: Box<ScanHistory>,
    b_scratch: MethodBScratch,
    /// This frame's objects from both methods.
    fused: Box<FrameObjects>,
    /// The world model: objects over frames, with stable ids.
    tracks: Box<Tracks>,
    /// Method B on its own thread (`Schedule::Worker`).
    pub(super) worker: Option<BWorker>,
    method_b_errors: u64,
    /// Method B runs finished (inline or on the worker).
    pub(super) method_b_runs: u64,
    /// Host time spent in frames (taken off the link clock).
    pub(super) busy: Duration,
    /// The overrun policy's memory.
    policy: Policy,
    /// Stage histograms and counters.
    pub(super) record: DeadlineRecord,
    /// Time it took the sinks to take the previous frame, ms.
    last_output_ms: f64,
    /// The pose of the last frame.
    pub(super) last_pose: Pose2,
    /// Sum, count and peak of the power figures.
    pub(super) power_sum: f64,
    pub(super) power_n: u64,
    pub(super) power_peak: f64,
    /// The confirmed tracks, as the line carries them (world model on).
    objects: Vec<ObjectOut>,
    /// This frame's detections, as the line carries them.
    detections: Vec<ObjectOut>,
    /// The walking people (world model on).
    people: Vec<PersonOut>,
    pub(super) walls: Vec<WallOut>,
    pub(super) doors: Vec<DoorOut>,
    /// Detections dropped for lying in or behind a wall (`perception::plausible`), in the
    /// band of a wall the map holds (`perception::wall_map`), on a piece of wall
    /// (`perception::wall_piece`), or as a "box" on an arc (`perception::outline`).
    pub(super) walled: u64,
    /// The map's wall lines, gathered from Method A's segments over the revolutions.
    wall_map: Box<WallMap>,
    /// While recording: the LiDAR bytes read since the recorder last took them.
    recording: Option<RecordingInput>,
    pub(super) track_log: super::track_log::TrackLog,
}

/// LiDAR bytes waiting for the recorder.
struct RecordingInput {
    raw: Box<heapless::Vec<u8, RECORD_RAW_BYTES>>,
    /// Bytes that did not fit (missing from the recording).
    dropped: u64,
}

impl FrameState {
    /// Everything the loop needs, allocated now; `recording`: keep the LiDAR's bytes for a
    /// recorder.
    pub(super) fn new(recording: bool) -> Self {
        FrameState {
            method_a: Box::new(MethodA::new()),
            history: Box::default(),
            b_scratch: MethodBScratch::default(),
            fused: Box::default(),
            tracks: Box::default(),
            worker: None,
            method_b_errors: 0,
            method_b_runs: 0,
            busy: Duration::ZERO,
            policy: Policy::default(),
            record: DeadlineRecord::default(),
            last_output_ms: 0.0,
            last_pose: Pose2::IDENTITY,
            power_sum: 0.0,
            power_n: 0,
            power_peak: 0.0,
            objects: Vec::with_capacity(perception::tracks::MAX_TRACKS),
            detections: Vec::with_capacity(perception::fusion::MAX_FRAME_OBJECTS),
            people: Vec::with_capacity(
                perception::tracks::MAX_TRACKS + perception::tracks::MAX_WALKERS,
            ),
            walls: Vec::with_capacity(perception::walls::MAX_SEGMENTS),
            doors: Vec::with_capacity(
                perception::doors::MAX_DOORS + perception::tracks::MAX_TRACKS,
            ),
            walled: 0,
            wall_map: Box::default(),
            recording: recording.then(|| RecordingInput {
                raw: Box::new(heapless::Vec::new()),
                dropped: 0,
            }),
            track_log: Default::default(),
        }
    }

    /// The line's `objects`: the confirmed tracks with the world model on, else this frame's
    /// detections.
    pub(super) fn reported(&self, world: bool) -> &[ObjectOut] {
        if world {
            &self.objects
        } else {
            &self.detections
        }
    }

    /// Keeps bytes just read for the recorder (counted when they do not fit).
    pub(super) fn note_raw(&mut self, bytes: &[u8]) {
        let Some(r) = self.recording.as_mut() else {
            return;
        };
        let n = bytes.len();
        let take = n.min(r.raw.capacity() - r.raw.len());
        let _ = r.raw.extend_from_slice(&bytes[..take]);
        if take < n {
            if r.dropped == 0 {
                log::warn!(
                    "recording: the recorder is behind; LiDAR bytes dropped from the recording (counted)"
                );
            }
            r.dropped += (n - take) as u64;
        }
    }

    /// Method A on the newest revolution: cloud, clusters, walls, doors, classes. Its objects
    /// and doors (as door frames) open the frame's object list.
    fn method_a(&mut self, cfg: &MethodAConfig, mount: &Pose2, shrink: bool, pose: &FramePose) {
        // Overrun policy step 2: age more of the cloud so clustering sees fewer points.
        let mut shrunk;
        let cfg = if shrink {
            shrunk = *cfg;
            shrunk.cloud.drop_fraction = shrunk.cloud.drop_fraction.max(SHRINK_DROP_FRACTION);
            &shrunk
        } else {
            cfg
        };
        let m = &mut self.method_a;
        m.add_scan(
            &Scan {
                ranges: self.history.pending(),
                start: pose.start,
                end: pose.end,
                mount: *mount,
            },
            cfg,
        );
        let sensor = pose.end.compose(mount);
        m.run(
            Point2::new(sensor.x, sensor.y),
            cfg,
            models::forest::forest(),
        );
        for (class, c) in m.objects() {
            push_a(&mut self.fused, class, c.centre, c.score);
        }
        for s in m.segments() {
            self.walls.push(WallOut {
                x0: f64::from(s.a.x),
                y0: f64::from(s.a.y),
                x1: f64::from(s.b.x),
                y1: f64::from(s.b.y),
            });
        }
        for d in m.doors() {
            self.doors.push(DoorOut {
                x: f64::from(d.centre.x),
                y: f64::from(d.centre.y),
                width: f64::from(d.width),
                score: f64::from(d.score),
            });
            if push_a(&mut self.fused, ObjectClass::DoorFrame, d.centre, d.score)
                && let Some(o) = self.fused.last_mut()
            {
                o.width_m = d.width;
            }
        }
    }

    /// Method B on the last three revolutions; its boxes join the frame's objects. A failed
    /// frame is counted (and said once) and the frame goes on without it.
    fn method_b(&mut self, b: &mut super::MethodBSetup) {
        let Some((scans, during)) = self.history.three() else {
            return;
        };
        let fused = &mut self.fused;
        if let Err(e) = b.frame(scans, during, &mut self.b_scratch, |placed| {
            merge_b(fused, &placed);
        }) {
            if self.method_b_errors == 0 {
                log::warn!("Method B: {e}; frame goes on without it (counted)");
            }
            self.method_b_errors += 1;
        }
        self.method_b_runs += 1;
    }

    /// Method B on its worker: the boxes of a finished run join this frame's objects (their
    /// time is returned), and the worker, when idle, gets the last three revolutions.
    fn method_b_worker(&mut self) -> Option<f64> {
        let worker = self.worker.as_mut()?;
        let mut ms = None;
        let (fused, errors) = (&mut self.fused, &mut self.method_b_errors);
        if worker.poll(|job| {
            for placed in &job.boxes {
                merge_b(fused, placed);
            }
            *errors += u64::from(job.failed);
            ms = Some(job.ms);
        }) {
            self.method_b_runs += 1;
        }
        if let Some((scans, during)) = self.history.three() {
            worker.offer(scans, during);
        }
        ms
    }

    /// The end of a run: waits for a run still on the worker (counted; its boxes come too
    /// late for any frame).
    pub(super) fn drain_worker(&mut self) {
        let errors = &mut self.method_b_errors;
        if let Some(w) = self.worker.as_mut()
            && w.wait(|job| *errors += u64::from(job.failed))
        {
            self.method_b_runs += 1;
        }
    }
}

impl<S: RevolutionStream> FrameLoop<'_, S> {
    /// Hands the stream's last finished revolution out as one frame; `true` when the frame
    /// limit is reached.
    pub(super) fn emit_frame(&mut self) -> io::Result<bool> {
        let FrameLoop {
            source,
            stream,
            opts,
            st,
            mount,
            summary,
            ingest,
            start,
        } = self;
        let mount = *mount;
        let Some(rev) = stream.last_revolution() else {
            return Ok(false);
        };
        super::make_room(opts);
        let t_frame = Instant::now();
        let frame = summary.frames;
        let valid = rev.valid_count() as u32;
        summary.frames += 1;
        if rev.is_complete() {
            summary.complete += 1;
        }
        summary.invalid_readings += (u64::from(rev.packets)
            * drivers::lidar::revolution::BINS_PER_SECTOR as u64)
            .saturating_sub(u64::from(valid));

        // Pose: at the first ray and at the last (359/360 of a revolution later).
        let t = rev.first_ray_time_s().max(0.0);
        let t_pose = Instant::now();
        let period = if rev.period_s.is_finite() && rev.period_s > 0.0 && rev.period_s < 2.0 {
            f64::from(rev.period_s)
        } else {
            0.2
        };
        let t_end = t + period * 359.0 / 360.0;
        for (r, reading) in st.history.next_mut().iter_mut().zip(rev.readings.iter()) {
            *r = if reading.valid { reading.range_m } else { 0.0 };
        }
        let pose = opts
            .pose
            .as_mut()
            .map_or(FramePose::STILL, |p: &mut PoseInput| {
                let mut pose = p.frame(frame, t, t_end, *start);
                p.match_scan(st.history.pending(), mount, &mut pose);
                pose
            });
        let pose_ms = t_pose.elapsed().as_secs_f64() * 1e3;

        // Method A.
        let t_a = Instant::now();
        st.fused.clear();
        st.walls.clear();
        st.doors.clear();
        let shrink = opts.method_a.is_some() && st.policy.before_method_a(&opts.budgets);
        let method_a_ms = opts.method_a.as_ref().map(|(cfg, mount)| {
            st.method_a(cfg, mount, shrink, &pose);
            let ms = t_a.elapsed().as_secs_f64() * 1e3;
            st.policy.method_a_took(ms);
            ms
        });
        st.history.commit(RevolutionPose::new(pose.start, pose.end));

        // Method B, unless the overrun policy sheds it (no room left, or decimated while
        // behind the LiDAR).
        let backlog_bytes = source.backlog_bytes();
        let behind = super::behind_lidar(source, backlog_bytes, opts.pacing, stream, start, period);
        let elapsed_ms = ingest.as_secs_f64() * 1e3 + t_frame.elapsed().as_secs_f64() * 1e3;
        let run_b = opts
            .method_b
            .as_ref()
            .is_some_and(|b| frame.is_multiple_of(u64::from(b.every.max(1))))
            && st.history.revolutions() >= 3;
        let skip_b = run_b && st.policy.before_method_b(&opts.budgets, elapsed_ms, behind);
        let method_b_ms = match opts.method_b.as_mut() {
            // On its own thread: never in the frame's way, so never skipped.
            None if st.worker.is_some() => st.method_b_worker(),
            Some(b) if run_b && !skip_b => {
                let t_b = Instant::now();
                st.method_b(b);
                let ms = t_b.elapsed().as_secs_f64() * 1e3;
                st.policy.method_b_took(ms);
                Some(ms)
            }
            _ => None,
        };

        // The world model, when on: this frame's detections update the tracks, seen from the
        // LiDAR's pose at the middle of the revolution; the confirmed tracks are the line's
        // objects. Off, the objects are the frame's detections.
        // Furniture in or behind a wall this revolution showed, or in the band of a wall the
        // map holds (one this revolution may show broken), is not furniture.
        if let Some((_, m)) = &opts.method_a {
            let sensor = pose.end.compose(m);
            let sensor = Point2::new(sensor.x, sensor.y);
            st.wall_map.update(frame, st.method_a.segments(), sensor);
            st.walled += u64::from(drop_walled(&mut st.fused, sensor, st.method_a.segments()));
            st.walled += u64::from(drop_in_map_walls(&mut st.fused, &st.wall_map));
        }
        // Nor is a detection whose returns lie on a line that goes on as a wall does.
        let lidar = pose.start.midway(&pose.end).compose(&mount);
        // Doorways in the map's walls that this revolution sees through are door frames too
        // (a door beside a short piece of wall, or in a wall one scan shows broken).
        let doorways = if opts.method_a.is_some() {
            perception::map_doors::observe(
                &st.wall_map,
                &lidar,
                st.history.newest(),
                &MapDoorConfig::default(),
                &mut st.fused,
            )
        } else {
            Doorways::new()
        };
        // The revolution as points, once, for this check and the next.
        let returns = perception::sight::returns(st.history.newest());
        st.walled += u64::from(drop_wall_pieces(&mut st.fused, &lidar, &returns));
        // A "box" whose returns lie on an arc is a bin or a round pillar.
        st.walled += u64::from(drop_round_boxes(&mut st.fused, &lidar, &returns));
        st.detections.clear();
        for (id, o) in st.fused.iter().enumerate() {
            st.detections.push(ObjectOut::new(id, o));
        }
        st.objects.clear();
        if let Some(cfg) = opts.world.as_ref() {
            let mid_s = t + period * 0.5;
            // The methods that looked: a track is not missed by a method that did not run.
            let looked = Looked {
                a: method_a_ms.is_some(),
                b: method_b_ms.is_some(),
            };
            let ranges = st.history.newest();
            st.tracks
                .update(frame, mid_s, &st.fused, &lidar, ranges, looked, cfg);
            // Door frames in a doorway of the map's walls are openings in a wall.
            st.tracks.anchor_doors(&doorways);
            // Nor is Method B's door frame at a corner of them, or at a wall's end with no jamb.
            st.tracks
                .mark_wall_doors(&st.wall_map, &lidar, ranges, cfg.max_range_m);
            // How wide the boxes look and whether they are round: a bin or a post is narrower
            // than any box, and a pillar's returns lie on an arc.
            st.tracks.measure_outlines(&lidar, &returns);
            // People: leg-sized blobs off the walls and not standing still; those that walk.
            if cfg.walkers {
                let leg_cfg = LegConfig::default();
                let mut legs = legs_in_map(st.history.newest(), &lidar, &leg_cfg);
                legs.retain(|p| !st.wall_map.holds(*p));
                st.tracks
                    .update_legs(frame, mid_s, &mut legs, &leg_cfg, cfg);
            }
            st.people.clear();
            for (id, w) in st.tracks.walkers().people(frame, PEOPLE_FRAMES) {
                st.people.push(PersonOut::walker(id, w));
            }
            for t in st.tracks.people(frame, cfg) {
                st.people.push(PersonOut::track(t));
            }
            // Doors are map entries like objects: the confirmed door-frame tracks, whichever
            // method found them.
            st.doors.clear();
            for t in st.tracks.confirmed() {
                // A track that the map's walls now hold is a piece of wall: no hit will come
                // (its detections are dropped above) and it fades; it is not reported meanwhile.
                if t.class() != ObjectClass::DoorFrame && st.wall_map.holds(t.centre) {
                    continue;
                }
                // A "box" never seen as wide as a box, or whose returns lie on an arc in most
                // revolutions, is a bin or a pillar.
                if t.too_narrow() || t.looks_round() {
                    continue;
                }
                st.track_log.write(frame, t);
                // Seen only in the ways the methods are mostly wrong, or a phantom by the model.
                if t.held_back(frame, cfg) {
                    continue;
                }
                let o = ObjectOut::track(t);
                if t.class() == ObjectClass::DoorFrame && t.width_m > 0.0 {
                    push_door(
                        &mut st.doors,
                        DoorOut {
                            x: o.x,
                            y: o.y,
                            width: f64::from(t.width_m),
                            score: o.score,
                        },
                    );
                }
                st.objects.push(o);
            }
        } else {
            // Door frames Method B found where Method A found none are doors too. The map's
            // doorways reach `doors` only through the world model (here they are objects and
            // detections only): on their own they found no door more.
            for o in st.fused.iter().filter(|o| {
                o.class == ObjectClass::DoorFrame && o.evidence == Evidence::B && o.width_m > 0.0
            }) {
                let (x, y) = (f64::from(o.centre.x), f64::from(o.centre.y));
                if st
                    .doors
                    .iter()
                    .all(|d| (d.x - x).hypot(d.y - y) > DOOR_SAME_M)
                {
                    push_door(
                        &mut st.doors,
                        DoorOut {
                            x,
                            y,
                            width: f64::from(o.width_m),
                            score: f64::from(o.score),
                        },
                    );
                }
            }
        }

        // Times, the deadline, the power.
        let ingest_ms = ingest.as_secs_f64() * 1e3;
        let output_ms = st.last_output_ms;
        let total_ms = ingest_ms + t_frame.elapsed().as_secs_f64() * 1e3 + output_ms;
        let missed = total_ms > opts.budgets.deadline_ms;
        let degraded = skip_b || shrink;
        let rec = &mut st.record;
        rec.method_b_skipped += u64::from(skip_b);
        rec.cloud_shrunk += u64::from(shrink);
        rec.behind_lidar += u64::from(behind);
        let times = FrameTimes {
            ingest: ingest_ms,
            pose: pose_ms,
            method_a: method_a_ms,
            method_b: method_b_ms,
            output: output_ms,
            total: total_ms,
        };
        rec.record(&times, &opts.budgets, missed, degraded);
        let power_w = opts.power.as_mut().and_then(|p| p.watts());
        if let Some(w) = power_w {
            st.power_sum += w;
            st.power_n += 1;
            st.power_peak = st.power_peak.max(w);
        }

        // Outputs.
        let t_out = Instant::now();
        let rec = &st.record;
        let journal = opts.pose.as_ref().and_then(|p| p.state.journal.as_ref());
        let view = FrameView {
            rev,
            mount,
            ranges: st.history.newest(),
            pose: pose.start,
            raw: st.recording.as_ref().map_or(&[], |r| &r.raw[..]),
            odom: journal.map_or(&[], |j| &j[..]),
            line: OutputLine {
                frame,
                t,
                pose: PoseOut {
                    x: f64::from(pose.start.x),
                    y: f64::from(pose.start.y),
                    theta: f64::from(pose.start.theta),
                },
                objects: st.reported(opts.world.is_some()),
                walls: &st.walls,
                doors: &st.doors,
                detections: opts.world.is_some().then_some(&st.detections[..]),
                people: opts.world.is_some().then_some(&st.people[..]),
                timing_ms: TimingOut::from(times),
                deadline_ms: opts.budgets.deadline_ms,
                deadline_missed: missed,
                degraded,
                power_w,
                power_source: opts.power.as_ref().map_or("none", |p| p.source()),
                faults: FaultsOut {
                    encoder_errors: pose.encoder_errors,
                    compass_rejected: pose.compass_rejected,
                    compass_errors: pose.compass_errors,
                    method_b_errors: st.method_b_errors,
                    deadline_missed: rec.missed,
                    degraded_frames: rec.degraded,
                    method_b_skipped: rec.method_b_skipped,
                    cloud_shrunk: rec.cloud_shrunk,
                    behind_lidar: rec.behind_lidar,
                    recording_bytes_dropped: st.recording.as_ref().map_or(0, |r| r.dropped),
                    recording_samples_dropped: opts
                        .pose
                        .as_ref()
                        .map_or(0, |p| p.state.journal_dropped),
                    odometry_dropped: opts.pose.as_ref().map_or(0, PoseInput::odometry_dropped),
                    ..FaultsOut::new(
                        &stream.faults(),
                        summary.invalid_readings,
                        source.link_counts(),
                    )
                },
                lidar: LidarOut {
                    rpm: f64::from(rev.rpm),
                    packets: rev.packets,
                    valid,
                    backlog_bytes,
                    queue_chunks: source.queue_depth().map(|q| q.0),
                    queue_chunks_max: source.queue_depth().map(|q| q.1),
                },
            },
        };
        let mut taken = false;
        for sink in opts.sinks.iter_mut() {
            taken |= sink.frame(&view)?;
        }
        st.last_output_ms = t_out.elapsed().as_secs_f64() * 1e3;
        st.last_pose = pose.start;
        if taken {
            if let Some(r) = st.recording.as_mut() {
                r.raw.clear();
            }
            if let Some(j) = opts.pose.as_mut().and_then(|p| p.state.journal.as_mut()) {
                j.clear();
            }
        }
        *ingest = Duration::ZERO;
        // Output errors end the run, so only this path needs the frame's time.
        st.busy += t_frame.elapsed();
        Ok(opts.frames.is_some_and(|n| summary.frames >= n))
    }
}
