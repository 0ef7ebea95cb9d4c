//! Replay of umbra's own MCAP recordings (`docs/interfaces.md` §2), end to end through the binary:
//! a run on the simulated robot recorded with `--record`, replayed with `umbra replay RUN.mcap`,
//! gives the same frames (time, pose, objects of both methods, walls, doors) as the run did;
//! and files that are not such recordings are clear exit-2 errors.
#![cfg(feature = "viz")]

use std::path::{Path, PathBuf};
use std::process::Command;

fn dir(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("umbra-replay-mcap-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn umbra(args: &[&str], paths: &[&Path]) -> std::process::Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_umbra"));
    c.args(args).env("RUST_LOG", "warn");
    for p in paths {
        c.arg(p);
    }
    c.output().expect("umbra runs")
}

fn lines(p: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(p)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// What a frame found, without its timings and power (which differ run to run).
fn findings(v: &serde_json::Value) -> serde_json::Value {
    let keep = ["frame", "t", "pose", "objects", "walls", "doors"];
    keep.iter().map(|k| (k.to_string(), v[k].clone())).collect()
}

#[test]
fn a_recorded_run_replays_to_the_same_frames() {
    let d = dir("same");
    let rec = d.join("run.mcap");
    let live = d.join("live.jsonl");
    let again = d.join("replay.jsonl");
    // No frame degraded for time in either run: the overrun policy's choices follow the
    // machine's speed, which a recording does not carry (`replay_models.rs`).
    let cfg = d.join("cfg.toml");
    std::fs::write(
        &cfg,
        format!(
            "[runtime]\ndeadline_ms = {}\n",
            firmware::config::MAX_DEADLINE_MS
        ),
    )
    .unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args([
            "run", "--frames", "24", "--speed", "max", "--seed", "4", "--quiet",
        ])
        .arg("--config")
        .arg(&cfg)
        .arg("--record")
        .arg(&rec)
        .arg("--jsonl")
        .arg(&live)
        .env("RUST_LOG", "warn")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args(["replay", "--quiet"])
        .arg(&rec)
        .arg("--config")
        .arg(&cfg)
        .arg("--jsonl")
        .arg(&again)
        .env("RUST_LOG", "info")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("as the recording says"), "{stderr}");
    assert!(stderr.contains("samples recorded in"), "{stderr}");
    let (a, b) = (lines(&live), lines(&again));
    assert_eq!(a.len(), 24);
    assert!(b.len() >= 24, "{} frames replayed", b.len());
    let same = a
        .iter()
        .zip(&b)
        .filter(|(x, y)| findings(x) == findings(y))
        .count();
    let objects: usize = a
        .iter()
        .map(|l| l["objects"].as_array().unwrap().len())
        .sum();
    let from_b = a
        .iter()
        .flat_map(|l| l["objects"].as_array().unwrap().clone())
        .filter(|o| o["source"] != "A")
        .count();
    println!("{same} of 24 frames the same; {objects} objects ({from_b} from Method B)");
    assert!(
        objects > 10 && from_b > 0,
        "the run found objects with both methods"
    );
    assert_eq!(same, 24, "every frame replays the same");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn files_that_are_not_recordings_are_exit_2_with_the_reason() {
    let d = dir("bad");
    let fake = d.join("fake.mcap");
    std::fs::write(&fake, b"\x89MCAP0\r\nnot really").unwrap();
    let out = umbra(&["replay"], &[&fake]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("fake.mcap") && err.contains("MCAP"), "{err}");
    // A recording without the raw channel (here: one with only a scan, as another tool
    // would write) says there is nothing to replay.
    let other = d.join("other.mcap");
    {
        let mut w = mcap::Writer::new(std::io::BufWriter::new(
            std::fs::File::create(&other).unwrap(),
        ))
        .unwrap();
        let ch = w
            .add_channel(0, "/scan", "json", &Default::default())
            .unwrap();
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: ch,
                sequence: 0,
                log_time: 0,
                publish_time: 0,
            },
            b"{}",
        )
        .unwrap();
        w.finish().unwrap();
    }
    let out = umbra(&["replay"], &[&other]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("/umbra/lidar_raw"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
