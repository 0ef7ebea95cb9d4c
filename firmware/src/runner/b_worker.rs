//! Method B on a thread of its own, off the frame's critical path: the schedule of a board
//! whose core runs the network slower than a frame (a Pi 3: 114–505 ms projected,
//! `docs/pi-budget.md`). The frame loop hands the worker the last three revolutions whenever
//! it is idle and merges its boxes into the frame in which they arrive; Method A, the world
//! model and the output keep every frame, and Method B reports as often as its core allows
//! (every other revolution at 300 ms on a 5 Hz LiDAR). Its boxes carry the pose of the
//! revolutions they came from, so a box that lands a frame later is still in its place in the
//! map.
//!
//! Nothing is allocated per frame on the loop's side: one job buffer (three revolutions in,
//! the decoded boxes out) goes back and forth through two one-slot channels. Timing decides
//! which frames get Method B's boxes, so a replay at `--speed max` runs Method B inline
//! instead (deterministic output); [`super::Schedule::resolve`] decides.

use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, TrySendError, sync_channel};
use std::thread::JoinHandle;
use std::time::Instant;

use perception::fusion::PlacedBox;
use perception::geometry::Pose2;
use perception::raster::SCAN_COLUMNS;
use perception::yolo::MAX_DETECTIONS;

use super::history::RevolutionPose;
use super::method_b::{MethodBScratch, MethodBSetup};

/// Bytes of the one job buffer that goes back and forth (`memory-budget.md`).
pub const B_WORKER_JOB_BYTES: usize = core::mem::size_of::<Job>();

/// One round trip: three revolutions in, Method B's boxes out.
pub(super) struct Job {
    /// The revolutions, newest first.
    scans: [[f32; SCAN_COLUMNS]; 3],
    /// The robot's poses during the previous revolution.
    during: RevolutionPose,
    /// The boxes, placed in the map.
    pub(super) boxes: heapless::Vec<PlacedBox, MAX_DETECTIONS>,
    /// How long the network and the decoding took, ms.
    pub(super) ms: f64,
    /// The run failed (the worker says why once, in the log).
    pub(super) failed: bool,
}

/// The loop's end of the worker.
pub(super) struct BWorker {
    to_worker: Option<SyncSender<Box<Job>>>,
    from_worker: Receiver<Box<Job>>,
    /// The job buffer while the worker is idle.
    spare: Option<Box<Job>>,
    thread: Option<JoinHandle<()>>,
}

impl BWorker {
    /// Starts the worker thread with the loaded model.
    pub(super) fn start(mut setup: MethodBSetup) -> std::io::Result<BWorker> {
        let (to_worker, jobs) = sync_channel::<Box<Job>>(1);
        let (done, from_worker) = sync_channel::<Box<Job>>(1);
        let thread = std::thread::Builder::new()
            .name("umbra-method-b".into())
            .spawn(move || {
                let mut scratch = MethodBScratch::default();
                let mut said = false;
                while let Ok(mut job) = jobs.recv() {
                    let t = Instant::now();
                    let Job {
                        scans,
                        during,
                        boxes,
                        ..
                    } = &mut *job;
                    boxes.clear();
                    let r = setup.frame(
                        [&scans[0], &scans[1], &scans[2]],
                        *during,
                        &mut scratch,
                        |p| {
                            // The decoder keeps at most MAX_DETECTIONS: this always fits.
                            let _ = boxes.push(p);
                        },
                    );
                    job.ms = t.elapsed().as_secs_f64() * 1e3;
                    job.failed = r.is_err();
                    if let Err(e) = r
                        && !said
                    {
                        log::warn!("Method B: {e}; frames go on without it (counted)");
                        said = true;
                    }
                    if done.send(job).is_err() {
                        break;
                    }
                }
            })?;
        Ok(BWorker {
            to_worker: Some(to_worker),
            from_worker,
            spare: Some(Box::new(Job {
                scans: [[0.0; SCAN_COLUMNS]; 3],
                during: RevolutionPose::still(Pose2::IDENTITY),
                boxes: heapless::Vec::new(),
                ms: 0.0,
                failed: false,
            })),
            thread: Some(thread),
        })
    }

    /// The finished job, if one is ready; `f` reads it before it becomes the spare again.
    pub(super) fn poll(&mut self, f: impl FnOnce(&Job)) -> bool {
        match self.from_worker.try_recv() {
            Ok(job) => self.take_back(job, f),
            Err(TryRecvError::Empty | TryRecvError::Disconnected) => false,
        }
    }

    /// `f` reads a finished job, which becomes the spare again.
    fn take_back(&mut self, job: Box<Job>, f: impl FnOnce(&Job)) -> bool {
        f(&job);
        self.spare = Some(job);
        true
    }

    /// Hands three revolutions (newest first) to the worker; `false` while it is still busy
    /// with the last ones (or gone).
    pub(super) fn offer(
        &mut self,
        scans: [&[f32; SCAN_COLUMNS]; 3],
        during: RevolutionPose,
    ) -> bool {
        let (Some(mut job), Some(tx)) = (self.spare.take(), self.to_worker.as_ref()) else {
            return false;
        };
        for (dst, src) in job.scans.iter_mut().zip(scans) {
            dst.copy_from_slice(src);
        }
        job.during = during;
        match tx.try_send(job) {
            Ok(()) => true,
            // Full cannot happen with one buffer in circulation; disconnected: the worker is
            // gone (the buffer is kept, nothing more is offered).
            Err(TrySendError::Full(job) | TrySendError::Disconnected(job)) => {
                self.spare = Some(job);
                false
            }
        }
    }

    /// Waits for a job in flight (the end of a run), then reads it like [`BWorker::poll`].
    pub(super) fn wait(&mut self, f: impl FnOnce(&Job)) -> bool {
        if self.spare.is_some() {
            return false;
        }
        match self.from_worker.recv() {
            Ok(job) => self.take_back(job, f),
            Err(_) => false,
        }
    }
}

impl Drop for BWorker {
    fn drop(&mut self) {
        // Closing the job channel ends the worker's loop once its run is done.
        self.to_worker = None;
        if let Some(t) = self.thread.take()
            && t.join().is_err()
        {
            log::error!("Method B's worker thread panicked");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runner::{Network, Schedule};
    use perception::geometry::Point2;
    use perception::raster::RasterConfig;
    use perception::yolo::{ANCHORS, DFL_BINS, DecodeConfig, LOGITS_LEN};
    use std::sync::{Arc, Barrier};

    /// A network whose output is two confident boxes (whatever its input), and that waits at
    /// a barrier before each run when given one.
    struct Fixed {
        input: Vec<f32>,
        output: Vec<f32>,
        gate: Option<Arc<Barrier>>,
    }

    impl Network for Fixed {
        fn name(&self) -> &str {
            "fixed"
        }
        fn input_mut(&mut self) -> &mut [f32] {
            &mut self.input
        }
        fn run_with(&mut self, f: &mut dyn FnMut(&[f32])) -> Result<(), String> {
            if let Some(g) = &self.gate {
                g.wait();
            }
            f(&self.output);
            Ok(())
        }
    }

    fn setup(gate: Option<Arc<Barrier>>) -> MethodBSetup {
        let mut output = vec![0.0; LOGITS_LEN];
        output[4 * DFL_BINS * ANCHORS..].fill(-10.0);
        // Class logits (rows 64..68): a chair at anchor 40, a desk at anchor 300.
        output[(4 * DFL_BINS) * ANCHORS + 40] = 4.0;
        output[(4 * DFL_BINS + 2) * ANCHORS + 300] = 3.0;
        MethodBSetup {
            model: Box::new(Fixed {
                input: vec![0.0; 3 * 64 * 384],
                output,
                gate,
            }),
            raster: RasterConfig::default(),
            decode: DecodeConfig::RUNTIME,
            mount: Pose2::new(-0.03, 0.0, 0.0),
            schedule: Schedule::Worker,
            every: 1,
            mirror: false,
            seam: crate::runner::Seam::Fixed,
            deskew: false,
        }
    }

    fn scans() -> [[f32; SCAN_COLUMNS]; 3] {
        [
            [1.5; SCAN_COLUMNS],
            [1.6; SCAN_COLUMNS],
            [1.7; SCAN_COLUMNS],
        ]
    }

    #[test]
    fn the_worker_gives_the_boxes_the_frame_would_and_refuses_work_while_busy() {
        let s = scans();
        let middle = RevolutionPose::still(Pose2::new(1.0, 2.0, 0.5));
        let mut inline = Vec::new();
        setup(None)
            .frame(
                [&s[0], &s[1], &s[2]],
                middle,
                &mut MethodBScratch::default(),
                |p| inline.push(p),
            )
            .unwrap();
        assert_eq!(inline.len(), 2, "the fixed network's two boxes");

        let gate = Arc::new(Barrier::new(2));
        let mut w = BWorker::start(setup(Some(gate.clone()))).unwrap();
        assert!(!w.poll(|_| ()), "nothing finished before any work");
        assert!(w.offer([&s[0], &s[1], &s[2]], middle));
        // The worker is held at the gate: busy, so the next revolutions are refused.
        assert!(!w.offer([&s[0], &s[1], &s[2]], middle));
        gate.wait();
        let mut got = Vec::new();
        assert!(w.wait(|job| {
            assert!(!job.failed);
            got.extend(job.boxes.iter().copied());
        }));
        assert_eq!(got, inline);
        // Idle again: it takes the next ones.
        assert!(w.offer([&s[0], &s[1], &s[2]], middle));
        gate.wait();
        drop(w); // joins the thread after its run
    }

    #[test]
    fn deskewed_boxes_are_placed_where_the_sweep_read_them() {
        let s = scans();
        let place = |deskew: bool, during: RevolutionPose| {
            let mut b = setup(None);
            b.deskew = deskew;
            let mut got = Vec::new();
            b.frame(
                [&s[0], &s[1], &s[2]],
                during,
                &mut MethodBScratch::default(),
                |p| got.push(p),
            )
            .unwrap();
            got
        };
        // Turning at 1.5 rad/s through one revolution.
        let turning = RevolutionPose {
            start: Pose2::new(1.0, 2.0, 0.2),
            end: Pose2::new(1.0, 2.0, 0.5),
        };
        let (mid, swept) = (place(false, turning), place(true, turning));
        let sweep = perception::sweep::Sweep {
            start: turning.start,
            end: turning.end,
            mount: Pose2::new(-0.03, 0.0, 0.0),
        };
        let lidar_mid = turning.middle().compose(&sweep.mount);
        for (m, w) in mid.iter().zip(&swept) {
            let range = m.centre.distance(Point2::new(lidar_mid.x, lidar_mid.y));
            let want = sweep.point(m.bbox[0] - 0.5, range);
            assert!(w.centre.distance(want) < 1e-3, "{w:?} vs {want:?}");
            // Read 0.1–0.4 of a revolution from the middle: 3–10 cm apart at 1.5 m.
            let apart = w.centre.distance(m.centre);
            let fraction = (359.0 - (m.bbox[0] - 0.5)) / 360.0;
            assert!(
                apart > 0.25 * (fraction - 0.5).abs() * range,
                "{apart} m apart at fraction {fraction}"
            );
        }
        // A robot standing still reads every bearing from one place: the same boxes.
        let still = RevolutionPose::still(Pose2::new(1.0, 2.0, 0.5));
        for (m, w) in place(false, still).iter().zip(&place(true, still)) {
            assert!(m.centre.distance(w.centre) < 1e-4);
        }
    }

    #[test]
    fn auto_puts_method_b_on_its_own_thread_only_on_a_pi_3_at_the_lidars_pace() {
        use crate::power::Board;
        for (board, live, want) in [
            (Board::Pi3b, true, Schedule::Worker),
            (Board::Pi3bPlus, true, Schedule::Worker),
            (Board::Pi3b, false, Schedule::Inline),
            (Board::Pi5, true, Schedule::Inline),
            (Board::Pi5, false, Schedule::Inline),
        ] {
            assert_eq!(
                Schedule::Auto.resolve(board, live),
                want,
                "{board:?} {live}"
            );
        }
        assert_eq!(
            Schedule::Worker.resolve(Board::Pi5, false),
            Schedule::Worker
        );
        assert_eq!(
            Schedule::Inline.resolve(Board::Pi3b, true),
            Schedule::Inline
        );
    }
}
