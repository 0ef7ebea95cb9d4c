//! Hardware-in-the-loop for the whole runtime on a robot: `umbra run --lidar PTY --opencr PTY`
//! against an emulated LDS-01 and an emulated OpenCR, each on a pseudo-terminal behind a
//! symlink (as `/dev/serial/by-id/…`), at their real byte rates.
//!
//! The LDS-01 waits for the motor-start byte `b`, then plays a still robot's room at 300 rpm
//! (42 bytes every 1/300 s) with garbage between packets and a burst each revolution; then its
//! motor stalls (1.5 s of packets whose speed field reads 0 rpm and whose index stands still);
//! it turns again; then it is unplugged for 0.6 s and replugged (a new pty behind the same
//! path), must be restarted with `b`, and plays on until the runtime is done, when it must hear
//! the stop byte `e`. The OpenCR answers DYNAMIXEL 2.0 READs of the wheels' present positions
//! for a robot driving straight at a known speed, and is itself unplugged for 0.5 s.
//!
//! The runtime must keep going through all of it, end cleanly with its report, and count every
//! fault in its output lines; its pose must follow the wheels.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use drivers::lds01::PACKET_LEN;
use drivers::lds01::packet::Packet;
use serialport::TTYPort;
use sim::lds01::{Lds01Sim, Lds01SimConfig};
use sim::pty::{expect_byte, saw_stop_byte, serve_opencr};
use sim::world::World;

/// Frames the runtime is asked for: the phases before the replug give ~11, so the last ones
/// come after it.
const FRAMES: usize = 18;
/// Wheel speed of the emulated robot, ticks/s on both wheels (4096 ticks a turn, r = 0.033 m:
/// 0.0405 m/s).
const TICKS_PER_S: f64 = 800.0;
const METRES_PER_TICK: f64 = 2.0 * std::f64::consts::PI * 0.033 / 4096.0;

/// A new pty behind `link` (again: a replug), 5 ms reads.
fn plug(link: &Path) -> TTYPort {
    sim::pty::plug(link, Duration::from_millis(5))
}

/// What the emulated LDS-01 did and heard.
#[derive(Debug, Default)]
struct LidarLog {
    garbage_bytes: usize,
    stalled_packets: usize,
    replugged_at: Option<Instant>,
    restarted_after_replug: bool,
    heard: Vec<u8>,
}

struct Lds01Player {
    sim: Lds01Sim,
    rng: u64,
}

impl Lds01Player {
    fn noise(&mut self) -> u8 {
        self.rng ^= self.rng << 13;
        self.rng ^= self.rng >> 7;
        self.rng ^= self.rng << 17;
        (self.rng >> 24) as u8
    }

    /// Plays revolutions at the link rate until `revolutions` are sent or `done`; garbage
    /// after every 7th packet and a 200-byte burst at the start of each revolution.
    fn play(
        &mut self,
        master: &mut TTYPort,
        revolutions: usize,
        done: &AtomicBool,
        log: &mut LidarLog,
    ) {
        let start = Instant::now();
        let mut t = 0.0f64;
        let mut packet = [0u8; PACKET_LEN];
        for n in 0..revolutions * 60 {
            if done.load(Ordering::Relaxed) {
                return;
            }
            if n % 60 == 0 {
                let burst: Vec<u8> = (0..200).map(|_| self.noise()).collect();
                let _ = master.write_all(&burst);
                log.garbage_bytes += burst.len();
            }
            t += self.sim.slot_s();
            self.sim.emit_packet(&mut packet);
            if n % 7 == 6 {
                let junk = [0x00, 0x13, 0xA5, 0xFF, 0x62];
                let _ = master.write_all(&junk);
                log.garbage_bytes += junk.len();
            }
            let _ = master.write_all(&packet);
            let due = start + Duration::from_secs_f64(t);
            if let Some(wait) = due.checked_duration_since(Instant::now()) {
                thread::sleep(wait);
            }
        }
    }

    /// The motor stalls for `seconds`: packets keep coming at the packet rate, speed field 0,
    /// the index standing still.
    fn stall(&mut self, master: &mut TTYPort, seconds: f64, log: &mut LidarLog) {
        let mut packet = [0u8; PACKET_LEN];
        self.sim.emit_packet(&mut packet);
        let mut p = Packet::new_unchecked(&mut packet[..]);
        p.set_speed_raw(0);
        p.fill_checksum();
        let start = Instant::now();
        let mut t = 0.0;
        while t < seconds {
            let _ = master.write_all(&packet);
            log.stalled_packets += 1;
            t += 1.0 / 300.0;
            let due = start + Duration::from_secs_f64(t);
            if let Some(wait) = due.checked_duration_since(Instant::now()) {
                thread::sleep(wait);
            }
        }
    }
}

fn lds01(link: PathBuf, first: TTYPort, done: Arc<AtomicBool>) -> (LidarLog, bool) {
    let mut log = LidarLog::default();
    let mut player = Lds01Player {
        sim: Lds01Sim::new(World::random_room(9), Lds01SimConfig::default(), 9),
        rng: 0x9E37_79B9_7F4A_7C15,
    };
    let mut master = first;
    let mut heard = Vec::new();
    assert!(
        expect_byte(&mut master, b'b', Duration::from_secs(10), &mut heard),
        "no motor-start byte"
    );
    player.play(&mut master, 6, &done, &mut log);
    player.stall(&mut master, 1.5, &mut log);
    player.play(&mut master, 4, &done, &mut log);
    drop(master); // unplug
    thread::sleep(Duration::from_millis(600));
    let mut master = plug(&link); // replug
    log.replugged_at = Some(Instant::now());
    heard.clear();
    log.restarted_after_replug =
        expect_byte(&mut master, b'b', Duration::from_secs(10), &mut heard);
    if log.restarted_after_replug {
        player.play(&mut master, 30, &done, &mut log);
    }
    let stopped = saw_stop_byte(master, &heard);
    log.heard = heard;
    (log, stopped)
}

/// Plays the OpenCR for a robot driving straight at [`TICKS_PER_S`] since `t0`; unplugged
/// from 3.0 s to 3.5 s. Returns the READs answered.
fn opencr(link: PathBuf, first: TTYPort, t0: Instant, done: Arc<AtomicBool>) -> u64 {
    let ticks = || {
        let t = (t0.elapsed().as_secs_f64() * TICKS_PER_S) as i32;
        (t, t)
    };
    let unplug = AtomicBool::new(false);
    let mut master = first;
    let before = thread::scope(|s| {
        s.spawn(|| {
            while t0.elapsed() < Duration::from_millis(3000) && !done.load(Ordering::Relaxed) {
                thread::sleep(Duration::from_millis(10));
            }
            unplug.store(true, Ordering::Relaxed);
        });
        serve_opencr(&mut master, &unplug, ticks)
    });
    drop(master); // unplug
    thread::sleep(Duration::from_millis(500));
    let mut master = plug(&link); // replug
    before + serve_opencr(&mut master, &done, ticks)
}

/// `umbra run --quiet` with Method B off, its JSON lines and its log (info) in files under
/// `dir`: the command (ports to be added), and the two paths. Scan matching is off: the
/// emulated LiDAR is the simulated robot's while the emulated wheels drive on their own, so
/// the scans would rightly hold back the pose that these tests check follows the wheels.
fn umbra_run(dir: &Path) -> (Command, PathBuf, PathBuf) {
    let cfg = dir.join("cfg.toml");
    // The deadline at its most: a frame the loaded test machine makes slow is not degraded, so
    // the run does not depend on the machine's speed (the time per frame is the benches' job).
    std::fs::write(
        &cfg,
        format!(
            "[method_b]\nenabled = false\n[pose]\nscan_match = false\n[runtime]\ndeadline_ms = {}\n",
            firmware::config::MAX_DEADLINE_MS
        ),
    )
    .unwrap();
    let (jsonl, log) = (dir.join("out.jsonl"), dir.join("stderr.log"));
    let mut c = Command::new(env!("CARGO_BIN_EXE_umbra"));
    c.args(["run", "--quiet", "--config"])
        .arg(&cfg)
        .arg("--jsonl")
        .arg(&jsonl)
        .env("RUST_LOG", "info")
        .stderr(std::fs::File::create(&log).unwrap());
    (c, jsonl, log)
}

/// The JSON lines of a run (each must be whole).
fn json_lines(path: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).expect("every line whole"))
        .collect()
}

#[test]
fn whole_runtime_survives_garbage_a_stalled_motor_and_unplugs_and_reports_them() {
    let dir = std::env::temp_dir().join(format!("umbra-hil-runtime-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let lidar_link = dir.join("ttyLDS");
    let opencr_link = dir.join("ttyACM");
    let done = Arc::new(AtomicBool::new(false));
    let t0 = Instant::now();
    let lidar = {
        let (first, link, done) = (plug(&lidar_link), lidar_link.clone(), done.clone());
        thread::spawn(move || lds01(link, first, done))
    };
    let board = {
        let (first, link, done) = (plug(&opencr_link), opencr_link.clone(), done.clone());
        thread::spawn(move || opencr(link, first, t0, done))
    };
    let (mut umbra, jsonl, err_path) = umbra_run(&dir);
    let out = umbra
        .arg("--lidar")
        .arg(&lidar_link)
        .arg("--opencr")
        .arg(&opencr_link)
        .args(["--frames", &FRAMES.to_string()])
        .output()
        .expect("umbra runs");
    let ended = Instant::now();
    done.store(true, Ordering::Relaxed);
    let (log, stopped) = lidar.join().expect("LDS-01 emulator");
    let answered = board.join().expect("OpenCR emulator");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = std::fs::read_to_string(&err_path).unwrap_or_default();
    println!("{stdout}\n{stderr}");
    println!(
        "emulator: {} garbage bytes, {} stalled packets, OpenCR answered {answered} reads",
        log.garbage_bytes, log.stalled_packets
    );
    assert!(out.status.success(), "exit {:?}", out.status);
    assert!(stdout.contains("LDS-01"), "the first line names the LiDAR");
    assert!(
        stderr.contains("| total | 18 |") && stderr.contains("power: mean"),
        "the run ends with its report"
    );
    assert!(
        log.restarted_after_replug,
        "the motor was restarted after the replug"
    );
    assert!(stopped, "the motor was stopped (`e`) on exit");
    assert!(
        stderr.contains("stalled"),
        "the stall was reported in the log"
    );
    assert!(answered > 20, "the OpenCR was polled");

    let lines = json_lines(&jsonl);
    assert_eq!(lines.len(), FRAMES, "every frame asked for came");
    let last = &lines[FRAMES - 1]["faults"];
    println!("last faults: {last}");
    let count = |k: &str| last[k].as_u64().unwrap_or_else(|| panic!("faults.{k}"));
    assert!(count("lidar_bytes_skipped") > 0, "garbage counted");
    assert!(
        count("lidar_stalled_packets") > 100,
        "stalled packets counted"
    );
    assert!(count("lidar_link_lost") >= 1, "the unplug counted");
    assert!(count("lidar_link_reopened") >= 1, "the replug counted");
    assert!(count("encoder_errors") >= 1, "the OpenCR unplug counted");
    assert_eq!(count("deadline_missed"), 0);
    // Frames after the LiDAR's replug: the runtime went on.
    let replugged = log.replugged_at.expect("replugged");
    assert!(replugged < ended);
    let reopened_frames = lines
        .iter()
        .filter(|l| l["faults"]["lidar_link_reopened"].as_u64() >= Some(1))
        .count();
    assert!(
        reopened_frames >= 3,
        "{reopened_frames} frames after the replug"
    );
    // The pose follows the wheels: over the first frames (before any stall or unplug) the
    // robot moves at the emulated speed, straight ahead.
    let pose = |k: usize| {
        let p = &lines[k]["pose"];
        (
            lines[k]["t"].as_f64().unwrap(),
            p["x"].as_f64().unwrap(),
            p["y"].as_f64().unwrap(),
            p["theta"].as_f64().unwrap(),
        )
    };
    let (ta, xa, _, _) = pose(1);
    let (tb, xb, yb, thb) = pose(5);
    let speed = (xb - xa) / (tb - ta);
    let want = TICKS_PER_S * METRES_PER_TICK;
    println!("speed from the pose {speed:.4} m/s, wheels {want:.4} m/s");
    assert!(
        (speed - want).abs() < 0.25 * want,
        "speed {speed} vs {want}"
    );
    assert!(
        yb.abs() < 0.02 && thb.abs() < 0.02,
        "straight: y {yb}, θ {thb}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sigterm_stops_the_motor_flushes_the_lines_and_prints_the_report() {
    let dir = std::env::temp_dir().join(format!("umbra-hil-sigterm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let link = dir.join("ttyLDS");
    let done = Arc::new(AtomicBool::new(false));
    let first = plug(&link);
    let lidar = {
        let done = done.clone();
        thread::spawn(move || {
            let mut player = Lds01Player {
                sim: Lds01Sim::new(World::random_room(3), Lds01SimConfig::default(), 3),
                rng: 1,
            };
            let mut master = first;
            let mut heard = Vec::new();
            let mut log = LidarLog::default();
            assert!(
                expect_byte(&mut master, b'b', Duration::from_secs(10), &mut heard),
                "no motor-start byte"
            );
            player.play(&mut master, 300, &done, &mut log);
            saw_stop_byte(master, &heard)
        })
    };
    let (mut umbra, jsonl, err_path) = umbra_run(&dir);
    let child = umbra
        .arg("--lidar")
        .arg(&link)
        .args(["--lidar-model", "lds01"])
        .spawn()
        .expect("umbra runs");
    // Frames flowing (at least five whole lines on disk, however slowly this machine started
    // umbra), then the service manager's stop.
    let deadline = Instant::now() + Duration::from_secs(60);
    while std::fs::read_to_string(&jsonl).map_or(0, |t| t.matches('\n').count()) < 5 {
        assert!(
            Instant::now() < deadline,
            "no frames from umbra within 60 s"
        );
        thread::sleep(Duration::from_millis(50));
    }
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(killed.success());
    let out = child.wait_with_output().expect("umbra ends");
    done.store(true, Ordering::Relaxed);
    let stopped = lidar.join().expect("LDS-01 emulator");
    let stderr = std::fs::read_to_string(&err_path).unwrap_or_default();
    println!("{stderr}");
    assert!(out.status.success(), "a clean stop: {:?}", out.status);
    assert!(stderr.contains("stopped by signal"), "{stderr}");
    assert!(stderr.contains("| total |"), "the report is printed");
    assert!(stopped, "the motor was stopped (`e`)");
    assert!(std::fs::read_to_string(&jsonl).unwrap().ends_with('\n'));
    let lines = json_lines(&jsonl);
    assert!(lines.len() >= 5, "{} frames flushed", lines.len());
    let _ = std::fs::remove_dir_all(&dir);
}
