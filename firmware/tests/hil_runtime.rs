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

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use drivers::dynamixel::{INST_STATUS, StatusDecoder, emit};
use drivers::lds01::PACKET_LEN;
use drivers::lds01::packet::Packet;
use serialport::{SerialPort, TTYPort};
use sim::lds01::{Lds01Sim, Lds01SimConfig};
use sim::world::World;

/// Frames the runtime is asked for: the phases before the replug give ~11, so the last ones
/// come after it.
const FRAMES: usize = 18;
/// Wheel speed of the emulated robot, ticks/s on both wheels (4096 ticks a turn, r = 0.033 m:
/// 0.0405 m/s).
const TICKS_PER_S: f64 = 800.0;
const METRES_PER_TICK: f64 = 2.0 * std::f64::consts::PI * 0.033 / 4096.0;

/// A new pty whose slave is reachable at `link` (calling it again is a replug). The master's
/// descriptor is made close-on-exec: `serialport` opens it without, so the `umbra` child would
/// inherit it and hold the pty open through an unplug.
fn plug(link: &Path) -> TTYPort {
    use std::os::fd::{FromRawFd, IntoRawFd, OwnedFd};
    let (master, slave) = TTYPort::pair().expect("pty pair");
    let name = slave.name().expect("slave name");
    drop(slave);
    // SAFETY: the descriptor comes from `into_raw_fd`: open, and owned by nobody else.
    #[allow(unsafe_code)]
    let raw = unsafe { OwnedFd::from_raw_fd(master.into_raw_fd()) };
    // `try_clone` duplicates with F_DUPFD_CLOEXEC; dropping `raw` closes the inheritable one.
    let cloexec = raw.try_clone().expect("dup pty master");
    drop(raw);
    // SAFETY: as above.
    #[allow(unsafe_code)]
    let mut master = unsafe { TTYPort::from_raw_fd(cloexec.into_raw_fd()) };
    master
        .set_timeout(Duration::from_millis(5))
        .expect("pty timeout");
    let tmp = link.with_extension("new");
    let _ = std::fs::remove_file(&tmp);
    std::os::unix::fs::symlink(&name, &tmp).expect("symlink");
    std::fs::rename(&tmp, link).expect("rename symlink");
    master
}

/// Waits up to `timeout` for `byte` on `master`; everything heard goes into `heard`.
fn expect_byte(master: &mut TTYPort, byte: u8, timeout: Duration, heard: &mut Vec<u8>) -> bool {
    let end = Instant::now() + timeout;
    let mut buf = [0u8; 64];
    while Instant::now() < end {
        if let Ok(n) = master.read(&mut buf) {
            heard.extend_from_slice(&buf[..n]);
            if buf[..n].contains(&byte) {
                return true;
            }
        }
    }
    false
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

/// Reads `master` until end of file or 5 s and tells whether the stop byte `e` came (plain
/// file reads: `serialport` reports a hang-up before the bytes that preceded it).
fn saw_stop_byte(master: TTYPort, heard: &[u8]) -> bool {
    use std::os::fd::{FromRawFd, IntoRawFd};
    if heard.contains(&b'e') {
        return true;
    }
    // SAFETY: the descriptor comes from `into_raw_fd`, so it is open and owned by nobody else.
    #[allow(unsafe_code)]
    let mut file = unsafe { std::fs::File::from_raw_fd(master.into_raw_fd()) };
    let end = Instant::now() + Duration::from_secs(5);
    let mut buf = [0u8; 64];
    while Instant::now() < end {
        match file.read(&mut buf) {
            Ok(n) if buf[..n].contains(&b'e') => return true,
            Ok(0) | Err(_) => thread::sleep(Duration::from_millis(20)),
            Ok(_) => {}
        }
    }
    false
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

/// Serves the OpenCR's READs (id 200, present positions at 136/140) for a robot driving
/// straight at [`TICKS_PER_S`] since `t0`; unplugged from 3.0 s to 3.5 s.
fn opencr(link: PathBuf, first: TTYPort, t0: Instant, done: Arc<AtomicBool>) -> u64 {
    let mut master = first;
    let mut dec = StatusDecoder::new();
    let mut buf = [0u8; 256];
    let mut answered = 0;
    let mut unplugged = false;
    while !done.load(Ordering::Relaxed) {
        if !unplugged && t0.elapsed() > Duration::from_millis(3000) {
            drop(std::mem::replace(
                &mut master,
                plug(&link.with_extension("void")),
            ));
            thread::sleep(Duration::from_millis(500));
            master = plug(&link);
            dec = StatusDecoder::new();
            unplugged = true;
        }
        let n = match master.read(&mut buf) {
            Ok(n) => n,
            Err(_) => {
                thread::sleep(Duration::from_millis(2));
                continue;
            }
        };
        let mut input = &buf[..n];
        while let Some(p) = dec.next_packet(&mut input) {
            let Some((addr, len)) = p.read_args().filter(|_| p.id == 200) else {
                continue;
            };
            let ticks = (t0.elapsed().as_secs_f64() * TICKS_PER_S) as i32;
            let mut table = [0u8; 256];
            table[136..140].copy_from_slice(&ticks.to_le_bytes());
            table[140..144].copy_from_slice(&ticks.to_le_bytes());
            let (a, l) = (usize::from(addr), usize::from(len).min(64));
            let mut params = [0u8; 65];
            params[1..=l].copy_from_slice(&table[a..(a + l).min(256)][..l]);
            let mut out = [0u8; 96];
            if let Ok(n) = emit(200, INST_STATUS, &params[..=l], &mut out) {
                let _ = master.write_all(&out[..n]);
                answered += 1;
            }
        }
    }
    answered
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
    let cfg = dir.join("cfg.toml");
    std::fs::write(&cfg, "[method_b]\nenabled = false\n").unwrap();
    let jsonl = dir.join("out.jsonl");
    let err_path = dir.join("stderr.log");
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .arg("run")
        .arg("--lidar")
        .arg(&lidar_link)
        .arg("--opencr")
        .arg(&opencr_link)
        .args(["--frames", &FRAMES.to_string(), "--quiet"])
        .arg("--config")
        .arg(&cfg)
        .arg("--jsonl")
        .arg(&jsonl)
        .env("RUST_LOG", "info")
        .stderr(std::fs::File::create(&err_path).unwrap())
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

    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
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
            player.play(&mut master, 100, &done, &mut log);
            saw_stop_byte(master, &heard)
        })
    };
    let cfg = dir.join("cfg.toml");
    std::fs::write(&cfg, "[method_b]\nenabled = false\n").unwrap();
    let jsonl = dir.join("out.jsonl");
    let err_path = dir.join("stderr.log");
    let child = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .arg("run")
        .arg("--lidar")
        .arg(&link)
        .args(["--lidar-model", "lds01", "--quiet"])
        .arg("--config")
        .arg(&cfg)
        .arg("--jsonl")
        .arg(&jsonl)
        .env("RUST_LOG", "info")
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .expect("umbra runs");
    // Two seconds of frames (~10 revolutions), then the service manager's stop.
    thread::sleep(Duration::from_secs(2));
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
    let text = std::fs::read_to_string(&jsonl).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("every line whole"))
        .collect();
    assert!(text.ends_with('\n'));
    assert!(lines.len() >= 5, "{} frames flushed", lines.len());
    let _ = std::fs::remove_dir_all(&dir);
}
