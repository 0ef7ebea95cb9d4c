//! Hardware-in-the-loop: the OpenCR encoder reader against an OpenCR emulator on a
//! pseudo-terminal. The emulator drives a simulated TurtleBot3 (waypoint tour, wheel slip) in
//! real time and answers DYNAMIXEL 2.0 READ requests from its control table (present positions
//! at 136/140). The reader polls at 20 Hz, the pose filter integrates the ticks, and the result
//! must follow the simulator's true pose; an unplug/replug (new pty behind the same symlink)
//! must be reported and survived.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

use drivers::opencr::{OpencrConfig, OpencrReader};
use perception::geometry::{Pose2, wrap_angle};
use perception::pose::{HeadingConfig, OdometryConfig, PoseFilter};
use serialport::TTYPort;
use sim::robot::{Motion, Robot, RobotConfig};
use sim::world::World;

fn plug(link: &Path) -> TTYPort {
    umbra_tests::plug_pty(link, Duration::from_millis(5))
}

/// Serves READs on `master` until `stop`, stepping `robot` in real time: the present
/// positions are the robot's encoder ticks at the moment of each request.
fn serve(master: &mut TTYPort, robot: &Mutex<(Robot, Instant)>, stop: &AtomicBool) -> u64 {
    sim::pty::serve_opencr(master, stop, || {
        let mut g = robot.lock().unwrap();
        let (r, last) = &mut *g;
        let now = Instant::now();
        let mut dt = (now - *last).as_secs_f32();
        while dt > 0.0 {
            let s = dt.min(0.002);
            r.step(s);
            dt -= s;
        }
        *last = now;
        r.ticks()
    })
}

#[test]
fn opencr_emulator_over_pty_gives_the_true_path_and_survives_unplug() {
    let dir = std::env::temp_dir().join(format!("umbra-opencr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let link: PathBuf = dir.join("ttyACM");
    let world = World::random_room(4);
    let robot = Robot::new(
        &world,
        RobotConfig {
            motion: Motion::Tour { speed_m_s: 0.15 },
            slip_sigma: 0.02,
        },
        4,
    );
    let start = robot.pose;
    let shared = Arc::new(Mutex::new((robot, Instant::now())));
    let stop = Arc::new(AtomicBool::new(false));
    let unplug = Arc::new(AtomicBool::new(false));

    let mut master = plug(&link);
    let (s2, st2, un2, link2) = (shared.clone(), stop.clone(), unplug.clone(), link.clone());
    let emulator = thread::spawn(move || {
        let mut answered = serve(&mut master, &s2, &un2);
        drop(master); // unplug
        thread::sleep(Duration::from_millis(400));
        let mut master = plug(&link2); // replug
        answered += serve(&mut master, &s2, &st2);
        answered
    });

    let mut reader =
        OpencrReader::open(link.to_str().unwrap(), OpencrConfig::default()).expect("open pty");
    let mut filter = PoseFilter::new(OdometryConfig::BURGER, HeadingConfig::default(), (0.0, 0.0));
    let (mut ok1, mut ok2, mut failed) = (0, 0, 0);
    let t0 = Instant::now();
    let mut last_poll = t0;
    while t0.elapsed() < Duration::from_secs(5) {
        let phase2 = t0.elapsed() > Duration::from_millis(2500);
        if phase2 && !unplug.load(Ordering::Relaxed) {
            unplug.store(true, Ordering::Relaxed);
        }
        match reader.poll() {
            Ok((l, r)) => {
                let now = Instant::now();
                filter.encoders(l, r, (now - last_poll).as_secs_f32());
                last_poll = now;
                if unplug.load(Ordering::Relaxed) {
                    ok2 += 1
                } else {
                    ok1 += 1
                }
            }
            Err(e) => {
                if failed == 0 {
                    println!("first error: {e}");
                }
                failed += 1;
            }
        }
        thread::sleep(Duration::from_millis(45));
    }
    // One last answer, then compare with the truth at that moment.
    let last = (0..20)
        .find_map(|_| reader.poll().ok())
        .expect("a final answer");
    filter.encoders(last.0, last.1, 0.05);
    let truth = {
        let g = shared.lock().unwrap();
        start.inverse().compose(&g.0.pose)
    };
    stop.store(true, Ordering::Relaxed);
    let answered = emulator.join().expect("emulator thread");
    let est: Pose2 = filter.pose();
    let dp = ((est.x - truth.x).powi(2) + (est.y - truth.y).powi(2)).sqrt();
    let dth = wrap_angle(est.theta - truth.theta).abs().to_degrees();
    let travelled = truth.x.hypot(truth.y);
    println!(
        "polls ok {ok1} before / {ok2} after the unplug, failed {failed}; emulator answered {answered}; \
         {:?}; pose error {dp:.3} m, {dth:.2}° after {travelled:.2} m",
        reader.stats()
    );
    assert!(ok1 >= 35, "only {ok1} good polls in 2.5 s at 20 Hz");
    assert!(failed >= 1, "the unplug was not noticed");
    assert!(ok2 >= 20, "only {ok2} good polls after the replug");
    assert!(reader.link().stats().reopens >= 1);
    assert!(travelled > 0.1, "the robot did not move");
    assert!(
        dp < 0.05 && dth < 3.0,
        "pose off the truth by {dp} m, {dth}°"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
