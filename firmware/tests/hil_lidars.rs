//! Hardware-in-the-loop for the LiDARs other than the LDS-01: the whole `umbra run --lidar PTY`
//! against a pseudo-terminal that behaves like an LDS-02, an LD06 or an RPLIDAR A1 on its USB
//! adapter, **without naming the model**.
//!
//! A writer thread owns the master side and plays the sensor with the simulator's bytes for
//! that model (`sim::wire`), paced at the model's real byte rate (LDS-02 ≈ 9.0 kB/s, LD06
//! ≈ 17.6 kB/s, RPLIDAR A1 10 kB/s). The RPLIDAR plays its protocol: silent until a SCAN
//! request (`A5 20`), then the response descriptor and nodes; a STOP (`A5 25`) silences it.
//! The runtime must recognise the model from the bytes, say so, run its frames, and stop an
//! RPLIDAR on exit. (DTR, which a pty cannot carry, is checked against a mock in
//! `drivers::rplidar::motor`.)

use std::io::{Read, Write};
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use drivers::lidar::{Family, LidarModel};
use serialport::{SerialPort, TTYPort};
use sim::scenario::{Scenario, ScenarioConfig};
use sim::wire::WireSim;

const FRAMES: usize = 8;

/// What the emulated sensor saw from the host.
#[derive(Debug, Default)]
struct Seen {
    scan_requests: usize,
    stop_requests: usize,
    bytes_sent: usize,
}

fn count(hay: &[u8], needle: [u8; 2]) -> usize {
    hay.windows(2).filter(|w| *w == needle).count()
}

/// Plays `model` on `master` until `done`, paced at its byte rate.
fn play(model: LidarModel, mut master: TTYPort, done: Arc<AtomicBool>) -> Seen {
    let mut sim = WireSim::new(Scenario::new(11, &ScenarioConfig::standard()), model);
    let mut pending: Vec<u8> = Vec::new();
    let mut seen = Seen::default();
    let rate = f64::from(model.wire_bytes_per_second());
    let rplidar = model.family() == Family::Rplidar;
    let mut scanning = !rplidar;
    let mut heard: Vec<u8> = Vec::new();
    let mut buf = [0u8; 256];
    let t0 = Instant::now();
    // Start of the current stream and bytes sent in it (pacing).
    let mut stream_t0 = Instant::now();
    let mut sent = 0usize;
    let _ = master.set_timeout(Duration::from_millis(2));
    while !done.load(Ordering::Relaxed) && t0.elapsed() < Duration::from_secs(60) {
        if let Ok(n) = master.read(&mut buf) {
            heard.extend_from_slice(&buf[..n]);
            let scans = count(&heard, [0xA5, 0x20]);
            let stops = count(&heard, [0xA5, 0x25]);
            if rplidar {
                if scans > seen.scan_requests {
                    scanning = true;
                    // A new SCAN: the descriptor comes first again.
                    pending.clear();
                    sim = WireSim::new(Scenario::new(11, &ScenarioConfig::standard()), model);
                    stream_t0 = Instant::now();
                    sent = 0;
                }
                if stops > seen.stop_requests && stops >= scans {
                    scanning = false;
                }
            }
            seen.scan_requests = scans;
            seen.stop_requests = stops;
        }
        if !scanning {
            continue;
        }
        // Pace: bytes owed since the stream (re)started.
        let owed = (stream_t0.elapsed().as_secs_f64() * rate) as usize;
        let due = owed.saturating_sub(sent);
        if due == 0 {
            thread::sleep(Duration::from_millis(2));
            continue;
        }
        while pending.len() < due {
            sim.emit_revolution(&mut pending);
        }
        let n = due.min(4096);
        if master.write_all(&pending[..n]).is_err() {
            break;
        }
        pending.drain(..n);
        sent += n;
        seen.bytes_sent += n;
    }
    // Whatever came last (the STOP on exit).
    let end = Instant::now() + Duration::from_millis(300);
    while Instant::now() < end {
        if let Ok(n) = master.read(&mut buf) {
            heard.extend_from_slice(&buf[..n]);
        }
    }
    seen.scan_requests = count(&heard, [0xA5, 0x20]);
    seen.stop_requests = count(&heard, [0xA5, 0x25]);
    seen
}

fn run_against(model: LidarModel) {
    let (master, slave) = TTYPort::pair().expect("pty pair");
    let path = slave.name().expect("slave name");
    let done = Arc::new(AtomicBool::new(false));
    let writer = {
        let done = done.clone();
        thread::spawn(move || play(model, master, done))
    };
    let dir = std::env::temp_dir().join(format!(
        "umbra-hil-{}-{}",
        model.cli_name(),
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("cfg.toml");
    std::fs::write(&cfg, "[method_b]\nenabled = false\n").unwrap();
    let jsonl = dir.join("out.jsonl");
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args([
            "run",
            "--lidar",
            &path,
            "--frames",
            &FRAMES.to_string(),
            "--quiet",
        ])
        .arg("--config")
        .arg(&cfg)
        .arg("--jsonl")
        .arg(&jsonl)
        .env("RUST_LOG", "info")
        .output()
        .expect("umbra runs");
    done.store(true, Ordering::Relaxed);
    let seen = writer.join().expect("writer");
    drop(slave);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{model}: {seen:?}\n{stdout}\n{stderr}");
    assert!(out.status.success(), "{model}: exit {:?}", out.status);
    let name = model.display_name();
    assert!(
        stdout.lines().next().unwrap_or("").contains(name),
        "{model}: the first line names the model"
    );
    assert!(
        stderr.contains("found on"),
        "{model}: the detection is reported"
    );
    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), FRAMES, "{model}");
    let last = &lines[FRAMES - 1];
    assert!(
        !last["walls"].as_array().unwrap().is_empty(),
        "{model}: walls seen in the simulated room"
    );
    assert_eq!(last["faults"]["lidar_bad_checksum"], 0, "{model}");
    if model.family() == Family::Rplidar {
        assert!(seen.scan_requests >= 1, "{model}: a SCAN request was sent");
        assert!(
            seen.stop_requests >= 1,
            "{model}: the runtime stopped the sensor on exit"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn lds02_is_recognised_and_runs() {
    run_against(LidarModel::Lds02);
}

#[test]
fn ld06_is_recognised_and_runs() {
    run_against(LidarModel::Ld06);
}

#[test]
fn rplidar_a1_is_recognised_and_runs() {
    run_against(LidarModel::RplidarA1);
}
