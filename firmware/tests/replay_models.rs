//! End to end across LiDAR models: the simulator sends the same scene (same room, same robot
//! motion, same readings) as each model's bytes; `umbra replay` recognises each capture's model
//! by itself and runs the pipeline; the objects and walls it reports must agree with the
//! LDS-01's.
//!
//! Method B is off (it is trained on LDS-01 rasters; its agreement is Method A's input
//! agreement); Method A sees the same revolutions bin by bin (`sim::wire`'s test), up to the
//! LDS-02's range-dependent beam bending at edges.

use std::process::Command;

use drivers::lidar::LidarModel;
use serde_json::Value;
use sim::scenario::{Scenario, ScenarioConfig};
use sim::wire::WireSim;

const REVOLUTIONS: usize = 40;

fn replay(model: LidarModel, dir: &std::path::Path) -> (Vec<Value>, String) {
    let mut sim = WireSim::new(Scenario::new(11, &ScenarioConfig::standard()), model);
    let mut bytes = Vec::new();
    sim.emit_revolutions(REVOLUTIONS, &mut bytes);
    let cap = dir.join(format!("{}.bin", model.cli_name()));
    std::fs::write(&cap, &bytes).unwrap();
    // The wheel ticks on the sensor's clock (same for every model: the same motion).
    let odom = dir.join(format!("{}.odom.jsonl", model.cli_name()));
    let lines: Vec<String> = sim
        .drain_odometry()
        .map(|o| {
            format!(
                "{{\"t\": {}, \"left_ticks\": {}, \"right_ticks\": {}}}",
                o.t, o.left_ticks, o.right_ticks
            )
        })
        .collect();
    std::fs::write(&odom, lines.join("\n")).unwrap();
    // No frame degraded for time: the overrun policy ages more of Method A's cloud after a frame
    // whose Method A ran over its budget (`[runtime] deadline_ms`' share, 65 ms). On a loaded
    // machine one frame of a run can (seen: in the LDS-02's and the A2's runs one frame's
    // Method A took 103–106 ms, the next was `degraded`, and they matched 10 and 31 of 40
    // objects). What is compared here is the models' bytes, not the machine's speed.
    let cfg = dir.join("cfg.toml");
    std::fs::write(
        &cfg,
        format!(
            "[method_b]\nenabled = false\n[runtime]\ndeadline_ms = {}\n",
            firmware::config::MAX_DEADLINE_MS
        ),
    )
    .unwrap();
    let jsonl = dir.join(format!("{}.jsonl", model.cli_name()));
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_umbra"));
    cmd.arg("replay").arg(&cap);
    if model == LidarModel::RplidarA2 {
        // A1 and A2 send the same bytes and nodes carry no time: a capture cannot say which,
        // and the clock needs the sample rate. Named, as a user must.
        cmd.args(["--lidar-model", "rplidar-a2"]);
    }
    let out = cmd
        .arg("--odom")
        .arg(&odom)
        .args(["--quiet", "--config"])
        .arg(&cfg)
        .arg("--jsonl")
        .arg(&jsonl)
        .output()
        .expect("umbra runs");
    assert!(
        out.status.success(),
        "{model}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (lines, String::from_utf8_lossy(&out.stdout).into_owned())
}

fn objects(v: &Value) -> Vec<(String, f64, f64)> {
    v["objects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            (
                o["class"].as_str().unwrap().to_owned(),
                o["x"].as_f64().unwrap(),
                o["y"].as_f64().unwrap(),
            )
        })
        .collect()
}

/// Frames compared: the last ten of each run (Method A's cloud has settled by then).
const COMPARED: usize = 10;

#[test]
fn every_model_sees_the_same_room() {
    let dir = std::env::temp_dir().join(format!("umbra-models-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (reference, _) = replay(LidarModel::Lds01, &dir);
    assert_eq!(reference.len(), REVOLUTIONS);
    let reference = &reference[REVOLUTIONS - COMPARED..];
    let ref_objects: usize = reference.iter().map(|l| objects(l).len()).sum();
    assert!(ref_objects > 0, "the LDS-01 sees objects");
    let mut failures = Vec::new();
    for model in LidarModel::ALL.into_iter().skip(1) {
        let (lines, stdout) = replay(model, &dir);
        assert!(
            stdout
                .lines()
                .next()
                .unwrap_or("")
                .contains(model.display_name())
                || model
                    .same_bytes_as()
                    .is_some_and(|t| stdout.contains(t.display_name())),
            "{model}: recognised ({stdout})"
        );
        assert_eq!(lines.len(), REVOLUTIONS, "{model}");
        let (mut matched, mut same_walls) = (0, 0);
        for (a, b) in reference.iter().zip(&lines[REVOLUTIONS - COMPARED..]) {
            let got = objects(b);
            matched += objects(a)
                .iter()
                .filter(|(c, x, y)| {
                    got.iter()
                        .any(|(c2, x2, y2)| c == c2 && (x - x2).hypot(y - y2) < 0.3)
                })
                .count();
            let walls = |v: &Value| v["walls"].as_array().map_or(0, |w| w.len());
            if walls(a).abs_diff(walls(b)) <= 1 {
                same_walls += 1;
            }
        }
        let share = matched as f64 / ref_objects as f64;
        println!(
            "{model}: {matched}/{ref_objects} LDS-01 objects matched (class, < 0.3 m) over the last {COMPARED} frames; wall count within 1 in {same_walls}/{COMPARED} frames"
        );
        // The LD08's beams bend by a range-dependent 0–7° (its geometry correction), so bins
        // beside range jumps differ from the LDS-01's (6 % of bins; `sim::wire`'s test) and
        // object edges with them: measured 68 % here. The other models' beams are straight.
        let need = if model == LidarModel::Lds02 { 0.6 } else { 0.9 };
        if share < need || same_walls * 10 < COMPARED * 7 {
            failures.push(model);
        }
    }
    assert!(failures.is_empty(), "disagree: {failures:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
