//! The Rust evaluator against Ultralytics' own validation of the same model on the same split:
//! `models/yolo/ultralytics-test.json` holds what `training/ultra_val.py` printed for the
//! checkpoint the compiled-in ONNX was exported from, on the test split of
//! `umbra-sim dataset --scenarios 40 --frames 50 --seed 11`. This test regenerates that split
//! (the simulator is deterministic), runs the compiled-in model through tract and
//! `lab::eval_b`, and requires every figure within 0.01 of Ultralytics'.

use std::path::Path;

use sim::dataset::{DatasetConfig, generate};

#[test]
fn evaluator_agrees_with_ultralytics() {
    let refs: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../models/yolo/ultralytics-test.json"
        ))
        .expect("reference figures"),
    )
    .expect("JSON");
    assert_eq!(
        refs["dataset"]["command"],
        "umbra-sim dataset --scenarios 40 --frames 50 --seed 11"
    );
    let dir = std::env::temp_dir().join(format!("umbra-eval-b-{}", std::process::id()));
    let cfg = DatasetConfig {
        scenarios: 40,
        frames: 50,
        seed: 11,
        method_a: false,
        recordings: false,
        pictures: 0,
        ..DatasetConfig::default()
    };
    generate(&cfg, &dir, |_| {}).expect("dataset");
    let mut model = models::yolo::YoloModel::builtin(Default::default()).expect("model");
    let stats = lab::eval_b::evaluate(&mut model, Path::new(&dir), "test", false, |_, _| {})
        .expect("evaluation");
    std::fs::remove_dir_all(&dir).ok();
    let m = stats.ours.metrics();
    println!("{}", lab::eval_b::table(&m));
    assert_eq!(m.images, refs["images"].as_u64().unwrap_or(100) as usize);
    let close = |what: &str, ours: f64, theirs: &serde_json::Value| {
        let theirs = theirs.as_f64().expect("number");
        println!(
            "{what}: ours {ours:.6} Ultralytics {theirs:.6} diff {:.2e}",
            (ours - theirs).abs()
        );
        assert!((ours - theirs).abs() <= 0.01, "{what}: {ours} vs {theirs}");
    };
    close("P", m.p, &refs["p"]);
    close("R", m.r, &refs["r"]);
    close("mAP50", m.map50, &refs["map50"]);
    close("mAP50-95", m.map50_95, &refs["map50_95"]);
    let theirs = refs["per_class"].as_array().expect("classes");
    assert_eq!(m.per_class.len(), theirs.len());
    for (c, t) in m.per_class.iter().zip(theirs) {
        assert_eq!(c.class, t["class"]);
        close(&format!("{} mAP50", c.class), c.map50, &t["map50"]);
        close(&format!("{} mAP50-95", c.class), c.map50_95, &t["map50_95"]);
        close(&format!("{} P", c.class), c.p, &t["p"]);
        close(&format!("{} R", c.class), c.r, &t["r"]);
    }
}
