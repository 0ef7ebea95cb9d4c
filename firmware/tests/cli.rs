//! End-to-end tests of the `umbra` binary: the contract of `docs/interfaces.md` (commands, exit
//! status, the first line, the JSON output line checked against `docs/output-line.schema.json`).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;
use sim::corrupt::{Corruption, corrupt};
use sim::lds01::{Lds01Sim, Lds01SimConfig};
use sim::world::World;

fn umbra(args: &[&str]) -> Output {
    umbra_logging(args, "warn")
}

/// `umbra` with its log at `level` (`RUST_LOG`).
fn umbra_logging(args: &[&str], level: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_umbra"))
        .args(args)
        .env("RUST_LOG", level)
        .output()
        .expect("run umbra")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("umbra-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn capture(path: &Path, revolutions: usize, mix: Corruption) {
    let mut sim = Lds01Sim::new(World::random_room(4), Lds01SimConfig::default(), 4);
    let mut bytes = Vec::new();
    sim.emit_revolutions(revolutions, &mut bytes);
    let bytes = corrupt(bytes.chunks(42), mix, 4).bytes;
    std::fs::write(path, bytes).unwrap();
}

/// The output line's JSON Schemas: the repository's own (`docs/output-line.schema.json`,
/// always), and the product owner's contract when `../shared/reference` is beside the
/// repository (the two must agree: a line valid for ours is valid for theirs).
fn schemas() -> Vec<Value> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let ours = root.join("../docs/output-line.schema.json");
    let text = std::fs::read_to_string(&ours).unwrap_or_else(|e| panic!("{}: {e}", ours.display()));
    let mut v = vec![serde_json::from_str(&text).expect("docs/output-line.schema.json is JSON")];
    let theirs = root.join("../../shared/reference/output-line.schema.json");
    match std::fs::read_to_string(&theirs) {
        Ok(s) => v.push(serde_json::from_str(&s).expect("the contract's schema is JSON")),
        Err(_) => println!(
            "contract schema {} not found: checking against docs/output-line.schema.json only",
            theirs.display()
        ),
    }
    v
}

/// A validator for the JSON Schema keywords the contract uses: type, required, properties,
/// additionalProperties (as a schema), items, enum, minimum, maximum, exclusiveMinimum,
/// minItems, maxItems. Returns the first violation with its path.
fn validate(v: &Value, s: &Value, path: &str) -> Result<(), String> {
    let fail = |what: &str| Err(format!("{path}: {what} (value {v})"));
    if let Some(t) = s.get("type") {
        let types: Vec<&str> = match t {
            Value::String(x) => vec![x.as_str()],
            Value::Array(xs) => xs.iter().filter_map(Value::as_str).collect(),
            _ => vec![],
        };
        let ok = types.iter().any(|t| match *t {
            "object" => v.is_object(),
            "array" => v.is_array(),
            "number" => v.is_number(),
            "integer" => v.is_i64() || v.is_u64(),
            "boolean" => v.is_boolean(),
            "string" => v.is_string(),
            "null" => v.is_null(),
            _ => false,
        });
        if !ok {
            return fail(&format!("not of type {t}"));
        }
    }
    if let Some(e) = s.get("enum").and_then(Value::as_array)
        && !e.contains(v)
    {
        return fail("not in enum");
    }
    if let Some(x) = v.as_f64() {
        if s.get("minimum")
            .and_then(Value::as_f64)
            .is_some_and(|m| x < m)
        {
            return fail("below minimum");
        }
        if s.get("maximum")
            .and_then(Value::as_f64)
            .is_some_and(|m| x > m)
        {
            return fail("above maximum");
        }
        if s.get("exclusiveMinimum")
            .and_then(Value::as_f64)
            .is_some_and(|m| x <= m)
        {
            return fail("not above exclusiveMinimum");
        }
    }
    if let Some(obj) = v.as_object() {
        for r in s
            .get("required")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            let r = r.as_str().unwrap_or_default();
            if !obj.contains_key(r) {
                return fail(&format!("missing required {r}"));
            }
        }
        let props = s.get("properties").and_then(Value::as_object);
        for (k, val) in obj {
            let sub = props
                .and_then(|p| p.get(k))
                .or(s.get("additionalProperties"));
            if let Some(sub) = sub.filter(|x| x.is_object()) {
                validate(val, sub, &format!("{path}.{k}"))?;
            }
        }
    }
    if let Some(arr) = v.as_array() {
        let n = arr.len() as u64;
        if s.get("minItems")
            .and_then(Value::as_u64)
            .is_some_and(|m| n < m)
        {
            return fail("too few items");
        }
        if s.get("maxItems")
            .and_then(Value::as_u64)
            .is_some_and(|m| n > m)
        {
            return fail("too many items");
        }
        if let Some(items) = s.get("items") {
            for (i, x) in arr.iter().enumerate() {
                validate(x, items, &format!("{path}[{i}]"))?;
            }
        }
    }
    Ok(())
}

#[test]
fn run_without_hardware_uses_the_simulated_robot() {
    let out = umbra(&["run", "--frames", "3", "--jsonl", "-", "--quiet"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let mut lines = stdout.lines();
    let first = lines.next().unwrap();
    assert!(first.contains("simulated robot"), "first line: {first}");
    let frames: Vec<Value> = lines.map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(frames.len(), 3);
    for (i, f) in frames.iter().enumerate() {
        assert_eq!(f["frame"], i as u64);
        assert_eq!(f["lidar"]["packets"], 60);
    }
}

#[test]
fn replay_of_a_noisy_capture_writes_valid_lines_with_faults() {
    let cap = tmp("noisy.bin");
    let jsonl = tmp("noisy.jsonl");
    capture(&cap, 40, Corruption::ISSUE_MIX);
    let out = umbra(&[
        "replay",
        cap.to_str().unwrap(),
        "--jsonl",
        jsonl.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&jsonl).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(lines.len() >= 39, "{} frames", lines.len());
    for schema in schemas() {
        for l in &lines {
            validate(l, &schema, "$").unwrap();
        }
    }
    let last = lines.last().unwrap();
    assert!(last["faults"]["lidar_bad_checksum"].as_u64().unwrap() > 0);
    assert!(last["faults"]["lidar_bytes_skipped"].as_u64().unwrap() > 0);
    // Frames are in order on the sensor clock, ~0.2 s apart.
    for w in lines.windows(2) {
        assert!(w[1]["t"].as_f64() > w[0]["t"].as_f64());
    }
    let span = last["t"].as_f64().unwrap() - lines[0]["t"].as_f64().unwrap();
    assert!((6.0..9.0).contains(&span), "40 revolutions span {span} s");
}

#[test]
fn replay_frame_and_seconds_limits() {
    let cap = tmp("clean.bin");
    capture(&cap, 30, Corruption::NONE);
    let count = |args: &[&str]| {
        let mut a = vec!["replay", cap.to_str().unwrap(), "--jsonl", "-", "--quiet"];
        a.extend_from_slice(args);
        let out = umbra(&a);
        assert!(out.status.success());
        String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .filter(|l| l.starts_with('{'))
            .count()
    };
    assert_eq!(count(&[]), 30);
    assert_eq!(count(&["--frames", "7"]), 7);
    // Sensor clock: 2 s ≈ 10 revolutions at ~300 rpm.
    let n = count(&["--seconds", "2"]);
    assert!((9..=11).contains(&n), "{n} frames in 2 s");
}

#[test]
fn errors_name_what_is_wrong_and_exit_2_or_1() {
    let out = umbra(&["replay", "/nonexistent/capture.bin"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/capture.bin"));

    let cfg = tmp("bad.toml");
    std::fs::write(&cfg, "[lidar]\nmax_range_m = 0.05\n").unwrap();
    let out = umbra(&["run", "--frames", "1", "--config", cfg.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("lidar.max_range_m") && err.contains("bad.toml"),
        "{err}"
    );

    std::fs::write(&cfg, "[lidar]\nchecksum = \"sometimes\"\n").unwrap();
    let out = umbra(&["run", "--frames", "1", "--config", cfg.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("checksum"));

    let out = umbra(&["run", "--frames", "1", "--lidar", "/dev/umbra-no-such-port"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/dev/umbra-no-such-port"));

    // An output file that cannot be made is a start-up error, as for --record and --snapshot.
    let out = umbra(&["run", "--frames", "1", "--track-log", "/nonexistent/t.txt"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--track-log /nonexistent/t.txt"), "{err}");

    let out = umbra(&["run", "--frames", "x"]);
    assert_eq!(out.status.code(), Some(2));
    let out = umbra(&["run", "--lidar-model", "ld06", "--frames", "1"]);
    assert_eq!(out.status.code(), Some(2));

    // The live map needs a terminal (here stdout is a pipe), and the terminal to itself.
    let out = umbra(&["run", "--frames", "1", "--view"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--view"));
    let out = umbra(&["run", "--frames", "1", "--view", "--jsonl", "-"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--jsonl"));
}

#[test]
fn bad_model_files_are_start_up_errors_naming_the_file() {
    let garbage = tmp("garbage.onnx");
    std::fs::write(&garbage, b"\x08\x07definitely not a protobuf graph").unwrap();
    let wrong =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/yolo/testdata/wrong-input.onnx");
    let missing = tmp("missing.onnx");
    for (file, what) in [
        (&garbage, "not a readable ONNX model"),
        (&wrong.to_path_buf(), "input is"),
        (&missing, "cannot read it"),
    ] {
        let f = file.to_str().unwrap();
        let out = umbra(&["run", "--frames", "1", "--model", f]);
        assert_eq!(out.status.code(), Some(2), "{f}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(f) && err.contains(what), "{f}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // The same file through the configuration.
    let cfg = tmp("model.toml");
    std::fs::write(
        &cfg,
        format!("[method_b]\nmodel = {:?}\n", garbage.to_str().unwrap()),
    )
    .unwrap();
    let out = umbra(&["run", "--frames", "1", "--config", cfg.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    // Method B off: the model is not loaded at all.
    std::fs::write(&cfg, "[method_b]\nenabled = false\n").unwrap();
    let out = umbra(&[
        "run",
        "--frames",
        "3",
        "--quiet",
        "--config",
        cfg.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn precision_picks_the_compiled_in_file_unless_a_file_is_given() {
    let cfg = tmp("precision.toml");
    let chosen = |toml: &str, more: &[&str]| -> String {
        std::fs::write(&cfg, toml).unwrap();
        let mut args = vec!["run", "--frames", "1", "--quiet", "--config"];
        args.push(cfg.to_str().unwrap());
        args.extend_from_slice(more);
        let out = umbra_logging(&args, "info");
        assert_eq!(out.status.code(), Some(0), "{toml}");
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        let line = err.lines().find(|l| l.contains("Method B: ")).unwrap_or("");
        line.to_string()
    };
    let int8 = "<built-in umbra-yolov8n-int8.onnx>";
    let fp32 = "<built-in umbra-yolov8n.onnx>";
    assert!(chosen("[method_b]\nprecision = \"int8\"\n", &[]).contains(int8));
    assert!(chosen("[method_b]\nprecision = \"fp32\"\n", &[]).contains(fp32));
    // fp32 by default, whatever the board.
    assert!(chosen("[power]\nboard = \"pi3b\"\n", &[]).contains(fp32));
    assert!(chosen("[power]\nboard = \"pi5\"\n", &[]).contains(fp32));
    // A file is run whatever the precision says.
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/yolo/umbra-yolov8n.onnx");
    let f = file.to_str().unwrap();
    let line = chosen("[method_b]\nprecision = \"int8\"\n", &["--model", f]);
    assert!(line.contains(f) && !line.contains("built-in"), "{line}");
    // A precision it does not know is a start-up error naming the value.
    std::fs::write(&cfg, "[method_b]\nprecision = \"half\"\n").unwrap();
    let out = umbra(&["run", "--frames", "1", "--config", cfg.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("half"));
}

#[test]
fn count_policy_keeps_and_counts_bad_packets() {
    let cap = tmp("count.bin");
    capture(
        &cap,
        20,
        Corruption {
            bit_flip: 1e-3,
            ..Corruption::NONE
        },
    );
    let cfg = tmp("count.toml");
    std::fs::write(&cfg, "[lidar]\nchecksum = \"count\"\n").unwrap();
    let run = |extra: &[&str]| -> Value {
        let mut a = vec!["replay", cap.to_str().unwrap(), "--jsonl", "-", "--quiet"];
        a.extend_from_slice(extra);
        let out = umbra(&a);
        assert!(out.status.success());
        let s = String::from_utf8(out.stdout).unwrap();
        serde_json::from_str(s.lines().rfind(|l| l.starts_with('{')).unwrap()).unwrap()
    };
    let verify = run(&[]);
    let count = run(&["--config", cfg.to_str().unwrap()]);
    let bad = verify["faults"]["lidar_bad_checksum"].as_u64().unwrap();
    assert!(bad > 0);
    assert_eq!(count["faults"]["lidar_bad_checksum"].as_u64().unwrap(), bad);
    // Under `verify` every bad packet goes missing; under `count` only those whose sync or
    // index byte was hit (a flipped index can also split a revolution), far fewer.
    let missing_verify = verify["faults"]["lidar_missing_packets"].as_u64().unwrap();
    let missing_count = count["faults"]["lidar_missing_packets"].as_u64().unwrap();
    println!("bad checksum {bad}; missing: verify {missing_verify}, count {missing_count}");
    assert!(missing_verify >= bad);
    assert!(missing_count * 2 < missing_verify);
}

/// A dataset's replay recordings (no Method A/B files, no pictures) under a fresh `name`.
fn recordings(name: &str, scenarios: usize, frames: usize, seed: u64) -> PathBuf {
    let dir = tmp(name);
    let _ = std::fs::remove_dir_all(&dir);
    let cfg = sim::dataset::DatasetConfig {
        scenarios,
        frames,
        seed,
        method_b: false,
        method_a: false,
        pictures: 0,
        ..sim::dataset::DatasetConfig::default()
    };
    sim::dataset::generate(&cfg, &dir, |_| {}).unwrap();
    dir
}

fn json_lines(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// A configuration file that turns scan matching off (the wheels' pose alone).
fn no_scan_match() -> PathBuf {
    let path = tmp("no-scan-match.toml");
    std::fs::write(&path, "[pose]\nscan_match = false\n").unwrap();
    path
}

/// `umbra replay` of recording `rec` with its odometry into `out`: (output lines, truth lines).
fn replay_recording(rec: &Path, out: &Path) -> (Vec<Value>, Vec<Value>) {
    replay_recording_with(rec, out, &[])
}

/// [`replay_recording`] with more arguments.
fn replay_recording_with(rec: &Path, out: &Path, more: &[&str]) -> (Vec<Value>, Vec<Value>) {
    let (cap, odom) = (rec.join("capture.bin"), rec.join("odom.jsonl"));
    let mut args = vec![
        "replay",
        cap.to_str().unwrap(),
        "--odom",
        odom.to_str().unwrap(),
        "--jsonl",
        out.to_str().unwrap(),
        "--quiet",
    ];
    args.extend_from_slice(more);
    let o = umbra(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (json_lines(out), json_lines(&rec.join("truth.jsonl")))
}

#[test]
fn replay_with_odometry_follows_the_true_pose() {
    let dir = recordings("odom-ds", 2, 40, 5);
    // Scenario 1 drives a waypoint tour. The wheels' pose alone (no scan matching: the pose
    // filter's arithmetic is what is checked here).
    let rec = dir.join("recordings/s0001");
    let no_match = no_scan_match();
    let (frames, truth) = replay_recording_with(
        &rec,
        &tmp("odom.jsonl"),
        &["--config", no_match.to_str().unwrap()],
    );
    assert_eq!(frames.len(), truth.len());
    let f = |v: &Value| v.as_f64().unwrap();
    let last = frames.last().unwrap();
    let last_truth = truth.last().unwrap();
    let travelled = f(&last_truth["pose"]["x"]).hypot(f(&last_truth["pose"]["y"]));
    // An independent integration of the same samples (Burger constants, plain arithmetic),
    // to each frame's time (interpolated between samples): the runtime must agree with it to the
    // millimetre.
    let odom = json_lines(&rec.join("odom.jsonl"));
    let m_per_tick = 2.0 * std::f64::consts::PI * 0.033 / 4096.0;
    let (mut x, mut y, mut th) = (0.0f64, 0.0f64, 0.0f64);
    let mut prev: Option<(i64, i64)> = None;
    let mut k = 0;
    let mut worst_pipe = 0.0f64;
    let mut worst = (0.0f64, 0.0f64);
    for (a, b) in frames.iter().zip(&truth) {
        assert!((f(&a["t"]) - f(&b["t"])).abs() < 1e-3);
        while k < odom.len() && f(&odom[k]["t"]) <= f(&a["t"]) {
            let (l, r) = (
                odom[k]["left_ticks"].as_i64().unwrap(),
                odom[k]["right_ticks"].as_i64().unwrap(),
            );
            if let Some((l0, r0)) = prev {
                let (dl, dr) = ((l - l0) as f64 * m_per_tick, (r - r0) as f64 * m_per_tick);
                let (d, dth) = ((dl + dr) / 2.0, (dr - dl) / 0.16);
                x += d * (th + dth / 2.0).cos();
                y += d * (th + dth / 2.0).sin();
                th += dth;
            }
            prev = Some((l, r));
            k += 1;
        }
        // The runtime reports the pose at the frame's time: the step to the next sample,
        // taken at constant wheel speed, in proportion.
        let (mut xi, mut yi) = (x, y);
        if let (Some((l0, r0)), Some(next)) = (prev, odom.get(k)) {
            let t0 = f(&odom[k - 1]["t"]);
            let (l, r) = (
                next["left_ticks"].as_i64().unwrap(),
                next["right_ticks"].as_i64().unwrap(),
            );
            let frac = ((f(&a["t"]) - t0) / (f(&next["t"]) - t0)).clamp(0.0, 1.0);
            let (dl, dr) = (
                (l - l0) as f64 * m_per_tick * frac,
                (r - r0) as f64 * m_per_tick * frac,
            );
            let (d, dth) = ((dl + dr) / 2.0, (dr - dl) / 0.16);
            xi += d * (th + dth / 2.0).cos();
            yi += d * (th + dth / 2.0).sin();
        }
        let pipe = (f(&a["pose"]["x"]) - xi).hypot(f(&a["pose"]["y"]) - yi);
        worst_pipe = worst_pipe.max(pipe);
        let dp = (f(&a["pose"]["x"]) - f(&b["pose"]["x"]))
            .hypot(f(&a["pose"]["y"]) - f(&b["pose"]["y"]));
        let dth = (f(&a["pose"]["theta"]) - f(&b["pose"]["theta"]))
            .sin()
            .asin()
            .abs();
        worst = (worst.0.max(dp), worst.1.max(dth.to_degrees()));
    }
    println!(
        "odometry replay over {travelled:.2} m: vs independent integration {worst_pipe:.5} m; vs truth worst position {:.3} m, heading {:.2}°",
        worst.0, worst.1
    );
    assert!(travelled > 0.3, "the tour did not move ({travelled} m)");
    assert!(
        worst_pipe < 1e-3,
        "runtime pose differs from the samples' integration by {worst_pipe} m"
    );
    // Against the truth, odometry alone with 2 % wheel slip over 8 s of turning and driving:
    // plausibility only.
    assert!(worst.0 < 0.05 && worst.1 < 10.0, "{worst:?}");
    assert_eq!(last["faults"]["encoder_errors"], 0);
    // With scan matching (the default) the same replay is laid on the scans: its heading is
    // no further from the truth than the wheels' alone, at any frame.
    let (matched, _) = replay_recording(&rec, &tmp("odom-matched.jsonl"));
    let scans = matched
        .iter()
        .zip(&truth)
        .map(|(a, b)| {
            (f(&a["pose"]["theta"]) - f(&b["pose"]["theta"]))
                .sin()
                .asin()
                .abs()
                .to_degrees()
        })
        .fold(0.0, f64::max);
    let wheels = worst.1;
    println!(
        "worst heading error against the truth: wheels {wheels:.2}°, scan matched {scans:.2}°"
    );
    assert!(
        scans <= wheels + 0.1,
        "{scans:.2}° scan matched, {wheels:.2}° wheels"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_odometry_lines_are_counted_not_fatal() {
    let cap = tmp("odom-bad.bin");
    capture(&cap, 10, Corruption::NONE);
    let odom = tmp("odom-bad.jsonl");
    std::fs::write(
        &odom,
        "{\"t\": 0.0, \"left_ticks\": 0, \"right_ticks\": 0}\nnot json\n{\"t\": 0.5, \"left_ticks\": \"x\"}\n{\"t\": 1.0, \"left_ticks\": 100, \"right_ticks\": 100}\n",
    )
    .unwrap();
    // The capture is of a robot standing still: scan matching (the default) would rightly hold
    // it where it is, so it is off to see the good lines' ticks move the pose.
    let no_match = no_scan_match();
    let o = umbra(&[
        "replay",
        cap.to_str().unwrap(),
        "--odom",
        odom.to_str().unwrap(),
        "--jsonl",
        "-",
        "--quiet",
        "--config",
        no_match.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let s = String::from_utf8(o.stdout).unwrap();
    let last: Value =
        serde_json::from_str(s.lines().rfind(|l| l.starts_with('{')).unwrap()).unwrap();
    assert_eq!(last["faults"]["encoder_errors"], 2);
    assert!(last["pose"]["x"].as_f64().unwrap() > 0.0);
    let o = umbra(&[
        "replay",
        cap.to_str().unwrap(),
        "--odom",
        "/nonexistent/odom.jsonl",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("/nonexistent/odom.jsonl"));
}

#[test]
fn calibrate_compass_writes_the_config_that_run_uses() {
    let cfg = tmp("cal.toml");
    let _ = std::fs::remove_file(&cfg);
    let o = umbra(&["calibrate-compass", "--write", cfg.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&cfg).unwrap();
    assert!(text.contains("hard_iron_ut"), "{text}");
    let o = umbra(&[
        "run",
        "--frames",
        "2",
        "--quiet",
        "--config",
        cfg.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    // Half a turn of readings is refused with a clear message.
    let odom = tmp("half-turn.jsonl");
    let lines: String = (0..60)
        .map(|i| {
            let a = (i as f32 * 3.0_f32).to_radians();
            format!(
                "{{\"t\": {}, \"mag_ut\": [{}, {}, -40.0]}}\n",
                i as f32 * 0.05,
                5.0 + 20.0 * a.cos(),
                20.0 * a.sin()
            )
        })
        .collect();
    std::fs::write(&odom, lines).unwrap();
    let o = umbra(&["calibrate-compass", "--odom", odom.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("full turn"));
}

#[test]
fn replay_of_a_simulated_recording_finds_its_true_objects() {
    // Both methods end to end: capture + odometry through `umbra replay`, objects scored
    // against the recording's truth (same class within 0.3 m, `docs/interfaces.md` §3). Method A's
    // objects are those with source A or AB, Method B's those with B or AB.
    let dir = recordings("method-a-ds", 4, 60, 11);
    let (mut with_walls, mut frames_seen) = (0, 0);
    // (reported, right) for A and for B.
    let mut score = [(0usize, 0usize); 2];
    let mut bbox_ok = true;
    for s in 0..4 {
        let (frames, truth) = replay_recording(
            &dir.join(format!("recordings/s{s:04}")),
            &tmp(&format!("method-a-{s}.jsonl")),
        );
        let f = |v: &Value| v.as_f64().unwrap();
        for (frame, t) in frames.iter().zip(&truth).skip(30) {
            frames_seen += 1;
            if !frame["walls"].as_array().unwrap().is_empty() {
                with_walls += 1;
            }
            // The frame's own detections: `detections` with the world model on (the default),
            // `objects` with it off.
            let found = frame.get("detections").unwrap_or(&frame["objects"]);
            for o in found.as_array().unwrap() {
                let src = o["source"].as_str().unwrap();
                let hit = t["objects"].as_array().unwrap().iter().any(|g| {
                    g["class"] == o["class"]
                        && (f(&g["x"]) - f(&o["x"])).hypot(f(&g["y"]) - f(&o["y"])) <= 0.3
                });
                if src.contains('A') && o["class"] != "door_frame" {
                    score[0].0 += 1;
                    score[0].1 += usize::from(hit);
                }
                if src.contains('B') {
                    score[1].0 += 1;
                    score[1].1 += usize::from(hit);
                    bbox_ok &= o["bbox"].as_array().is_some_and(|b| b.len() == 4);
                }
            }
        }
    }
    let [(ra, a), (rb, b)] = score;
    eprintln!(
        "replay: method A {a}/{ra} reported objects right, method B {b}/{rb}; walls in {with_walls}/{frames_seen} frames"
    );
    assert!(
        with_walls * 10 >= frames_seen * 9,
        "{with_walls}/{frames_seen} frames with walls"
    );
    assert!(ra >= 40, "only {ra} Method A objects reported");
    assert!(
        a * 10 >= ra * 8,
        "Method A: {a}/{ra} match a true object of their class"
    );
    assert!(rb >= 40, "only {rb} Method B objects reported");
    assert!(bbox_ok, "a Method B object without a 4-number bbox");
    // The small CPU-trained model (models/README.md) places half of its boxes within 0.3 m.
    assert!(
        b * 2 >= rb,
        "Method B: {b}/{rb} match a true object of their class"
    );
}

#[test]
fn the_track_log_holds_every_reported_object_with_its_report_features() {
    let dir = recordings("track-log-ds", 1, 60, 12);
    let log = tmp("tracks.txt");
    let (frames, _) = replay_recording_with(
        &dir.join("recordings/s0000"),
        &tmp("track-log.jsonl"),
        &["--track-log", log.to_str().unwrap()],
    );
    let text = std::fs::read_to_string(&log).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
    let names = perception::tracks::FEATURE_NAMES;
    assert_eq!(header.len(), 7 + names.len(), "{header:?}");
    assert_eq!(&header[7..], &names[..]);
    let mut logged = std::collections::HashSet::new();
    for l in lines {
        let c: Vec<&str> = l.split_whitespace().collect();
        assert_eq!(c.len(), 6 + names.len(), "{l}");
        assert!(
            c[6..]
                .iter()
                .all(|v| v.parse::<f32>().is_ok_and(f32::is_finite)),
            "{l}"
        );
        logged.insert((c[0].parse::<u64>().unwrap(), c[1].parse::<u64>().unwrap()));
    }
    // Every object a line reports earned its report that frame, so it is in the log.
    let mut reported = 0;
    for f in &frames {
        for o in f["objects"].as_array().unwrap() {
            let key = (f["frame"].as_u64().unwrap(), o["id"].as_u64().unwrap());
            assert!(logged.contains(&key), "{key:?} reported but not logged");
            reported += 1;
        }
    }
    assert!(reported > 20, "only {reported} objects reported");
}

/// The deadline table that a run prints at its end (from `| stage` to the power line).
fn table_of(stderr: &str) -> String {
    let start = stderr.find("| stage |").expect("a deadline table");
    let rest = &stderr[start..];
    let end = rest.find("power: ").expect("a power line");
    let tail = &rest[end..];
    let nl = tail.find('\n').map_or(tail.len(), |i| i + 1);
    rest[..end + nl].to_owned()
}

#[test]
fn run_ends_with_the_deadline_table_and_report_rebuilds_it() {
    let jsonl = tmp("table.jsonl");
    let out = umbra(&[
        "run",
        "--frames",
        "120",
        "--speed",
        "max",
        "--quiet",
        "--jsonl",
        jsonl.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let table = table_of(&stderr);
    for stage in ["ingest", "pose", "method_a", "method_b", "output", "total"] {
        assert!(table.contains(&format!("| {stage} |")), "{table}");
    }
    assert!(table.contains("| total | 120 |"), "{table}");
    assert!(table.contains("power: mean "), "{table}");
    assert!(table.contains("source: model (Pi 5 figures"), "{table}");
    // Every line carries the figures the table is made of, and validates.
    let lines = json_lines(&jsonl);
    assert_eq!(lines.len(), 120);
    let s = schemas();
    for l in &lines {
        assert!(l["timing_ms"]["output"].is_number(), "{l}");
        assert!(l["power_source"].is_string(), "{l}");
        for s in &s {
            validate(l, s, "line").unwrap();
        }
    }
    // The model needs half a second of run before its first figure; 120 frames flat out take
    // longer than that.
    assert!(lines.last().unwrap()["power_w"].as_f64().unwrap() > 2.8);
    let rep = umbra(&["report", jsonl.to_str().unwrap()]);
    assert!(
        rep.status.success(),
        "{}",
        String::from_utf8_lossy(&rep.stderr)
    );
    assert_eq!(String::from_utf8(rep.stdout).unwrap(), table);
}

#[test]
fn over_budget_frames_shed_method_b_first_and_are_counted() {
    // A 2 ms deadline: Method B (several ms) cannot fit, so the policy skips it once its time
    // is known; Method A overruns its share, so the cloud shrinks; frames still miss.
    let cfg = tmp("tight.toml");
    std::fs::write(&cfg, "[runtime]\ndeadline_ms = 2.0\n").unwrap();
    let jsonl = tmp("tight.jsonl");
    let out = umbra(&[
        "run",
        "--frames",
        "20",
        "--speed",
        "max",
        "--quiet",
        "--config",
        cfg.to_str().unwrap(),
        "--jsonl",
        jsonl.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let lines = json_lines(&jsonl);
    let last = &lines.last().unwrap()["faults"];
    // Frames 0–1 fill the raster; frame 2 runs B and learns its time; 3.. skip it.
    let with_b = lines
        .iter()
        .filter(|l| l["timing_ms"].get("method_b").is_some())
        .count();
    assert_eq!(with_b, 1, "Method B ran only until its time was known");
    assert_eq!(last["method_b_skipped"], 17);
    assert!(last["cloud_shrunk"].as_u64().unwrap() > 0, "{last}");
    assert!(lines[3]["degraded"].as_bool().unwrap());
    let degraded = lines.iter().filter(|l| l["degraded"] == true).count() as u64;
    assert_eq!(last["degraded_frames"], degraded);
    let missed = lines
        .iter()
        .filter(|l| l["deadline_missed"] == true)
        .count() as u64;
    assert_eq!(last["deadline_missed"], missed);
    let table = table_of(&stderr);
    assert!(
        table.contains(&format!(
            "{missed} missed, {degraded} degraded (Method B skipped 17"
        )),
        "{table}"
    );
}

#[test]
fn method_b_follows_its_schedule() {
    // `every = 3`: Method B in frames 3, 6, 9 (frames 0–1 fill its three revolutions), none
    // skipped by the policy.
    let cfg = tmp("every.toml");
    std::fs::write(&cfg, "[method_b]\nevery = 3\n").unwrap();
    let jsonl = tmp("every.jsonl");
    let args = |cfg: &Path, speed: &'static str, jsonl: &Path| -> Vec<String> {
        [
            "run", "--frames", "11", "--speed", speed, "--quiet", "--config",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([
            cfg.display().to_string(),
            "--jsonl".into(),
            jsonl.display().to_string(),
        ])
        .collect()
    };
    let run = |a: Vec<String>| umbra(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let out = run(args(&cfg, "max", &jsonl));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = json_lines(&jsonl);
    let with_b: Vec<u64> = lines
        .iter()
        .filter(|l| l["timing_ms"].get("method_b").is_some_and(|v| !v.is_null()))
        .map(|l| l["frame"].as_u64().unwrap())
        .collect();
    assert_eq!(with_b, [3, 6, 9]);
    assert_eq!(lines.last().unwrap()["faults"]["method_b_skipped"], 0);
    // A Pi 3 puts Method B on its own thread at the LiDAR's pace, and keeps it in the frame
    // at full speed (a deterministic replay).
    std::fs::write(&cfg, "[power]\nboard = \"pi3b\"\n").unwrap();
    for (speed, worker) in [("max", false), ("1", true)] {
        let out = Command::new(env!("CARGO_BIN_EXE_umbra"))
            .args(args(&cfg, speed, &jsonl))
            .env("RUST_LOG", "info")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{stderr}");
        assert_eq!(
            stderr.contains("Method B on its own thread:"),
            worker,
            "{speed}: {stderr}"
        );
        assert_eq!(
            stderr.contains("in the frame"),
            !worker,
            "{speed}: {stderr}"
        );
    }
}

#[test]
fn bad_budgets_and_power_settings_name_the_field() {
    for (toml, field) in [
        (
            "[runtime.budget_ms]\nmethod_b = 300.0\n",
            "runtime.budget_ms.method_b",
        ),
        (
            "[runtime.budget_ms]\nmethod_a = 200.0\nmethod_b = 200.0\n",
            "runtime.budget_ms",
        ),
        ("[power]\nbudget_w = -1.0\n", "power.budget_w"),
        ("[power]\nsource = \"solar\"\n", "source"),
        ("[power]\nsource = \"pmic\"\n", "power.source"),
    ] {
        let cfg = tmp("bad-power.toml");
        std::fs::write(&cfg, toml).unwrap();
        let out = umbra(&["run", "--frames", "1", "--config", cfg.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{toml}: {stderr}");
        assert!(stderr.contains(field), "{toml}: {stderr}");
    }
    let out = umbra(&["report", "/nonexistent/run.jsonl"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/run.jsonl"));
}

#[test]
fn version_names_features_and_the_model_by_hash() {
    let out = umbra(&["--version"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("umbra "), "{text}");
    assert!(text.contains("features: method-b viz sim view"), "{text}");
    assert!(text.contains(models::yolo::BUILTIN_SHA256), "{text}");
    assert!(text.contains("built for: "), "{text}");
}

/// The package's files say what the binary understands: the unit's command line parses, and
/// the conffile it points at is a valid configuration.
#[test]
fn the_packaged_unit_and_configuration_are_valid() {
    use clap::Parser;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("debian");
    let unit = std::fs::read_to_string(dir.join("umbra.service")).unwrap();
    let exec = unit
        .replace("\\\n", " ")
        .lines()
        .find_map(|l| l.strip_prefix("ExecStart=").map(str::to_owned))
        .expect("an ExecStart line");
    let args: Vec<&str> = exec.split_whitespace().collect();
    assert_eq!(args[0], "/usr/bin/umbra");
    let cli = firmware::cli::Cli::try_parse_from(&args);
    assert!(cli.is_ok(), "{exec}: {:?}", cli.err());
    assert!(exec.contains("--config /etc/umbra/umbra.toml"), "{exec}");
    let out = umbra(&[
        "run",
        "--frames",
        "1",
        "--quiet",
        "--config",
        dir.join("umbra.toml").to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
