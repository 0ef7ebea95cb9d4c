//! Method B per frame: encoding three revolutions into the model's input tensor, inference
//! (fp32 and int8 QLinearConv models, tract, one thread and two), decoding with suppression.
//! The peer is onnxruntime on the same files and the same input tensor, one thread
//! (`bench/yolo_peer.py`, run in the same process tree when `python3` with onnxruntime is
//! there; set `UMBRA_PYTHON` to use another interpreter); the ratios tract / onnxruntime are
//! printed, with the largest difference between the two runtimes' outputs.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use models::yolo::{BUILTIN_INT8_ONNX, BUILTIN_ONNX, YoloModel, YoloOptions};
use perception::raster::{RasterConfig, SCAN_COLUMNS, encode_chw_f32};
use perception::yolo::{ANCHORS, DecodeConfig, DecodeScratch, Detection, decode};
use sim::dataset::{DatasetConfig, simulate};

/// Three consecutive revolutions of a simulated room (newest first).
fn scans() -> [[f32; SCAN_COLUMNS]; 3] {
    let cfg = DatasetConfig {
        scenarios: 1,
        frames: 1,
        seed: 3,
        ..DatasetConfig::default()
    };
    let mut frames = Vec::new();
    simulate(0, &cfg, |_, f, _| frames.push(f.ranges_m()), |_, _| {});
    [frames[2], frames[1], frames[0]]
}

fn write_f32(path: &std::path::Path, v: &[f32]) {
    let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    std::fs::write(path, bytes).expect("temp file");
}

/// onnxruntime's median time and its largest output difference from tract.
fn peer(name: &str, bytes: &[u8], input: &[f32], output: &[f32]) -> Option<(f64, String)> {
    let dir = std::env::temp_dir();
    let model = dir.join(format!("umbra-bench-{name}.onnx"));
    std::fs::write(&model, bytes).ok()?;
    let (inp, out) = (
        dir.join("umbra-bench-input.f32"),
        dir.join(format!("umbra-bench-{name}.out.f32")),
    );
    write_f32(&inp, input);
    write_f32(&out, output);
    let python = std::env::var("UMBRA_PYTHON").unwrap_or_else(|_| "python3".into());
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/yolo_peer.py");
    let o = std::process::Command::new(python)
        .args([
            script.as_ref(),
            model.as_os_str(),
            inp.as_os_str(),
            out.as_os_str(),
        ])
        .output()
        .ok()?;
    let s = String::from_utf8_lossy(&o.stdout).trim().to_string();
    if s.is_empty() {
        println!("peer failed: {}", String::from_utf8_lossy(&o.stderr).trim());
        return None;
    }
    Some((s.split_whitespace().nth(1)?.parse().ok()?, s))
}

fn bench(c: &mut Criterion) {
    let scans = scans();
    let cfg = RasterConfig::default();
    let load = |bytes: &[u8], threads: usize| {
        YoloModel::from_bytes(bytes, "bench", YoloOptions { threads }).expect("built-in model")
    };
    let mut fp32 = load(BUILTIN_ONNX, 1);
    let mut g = c.benchmark_group("method_b");
    g.bench_function("encode", |b| {
        b.iter(|| encode_chw_f32(fp32.input_mut(), [&scans[0], &scans[1], &scans[2]], &cfg))
    });
    let output: Vec<f32> = fp32.run(|o| o.to_vec()).expect("runs");
    let input: Vec<f32> = fp32.input_mut().to_vec();
    let mut scratch = DecodeScratch::new();
    let mut dets: heapless::Vec<Detection, 32> = heapless::Vec::new();
    g.bench_function("decode", |b| {
        b.iter(|| {
            decode(
                black_box(&output),
                ANCHORS,
                &DecodeConfig::RUNTIME,
                &mut scratch,
                &mut dets,
            )
        })
    });
    let mut int8 = load(BUILTIN_INT8_ONNX, 1);
    int8.input_mut().copy_from_slice(&input);
    let mut fp32_2t = load(BUILTIN_ONNX, 2);
    fp32_2t.input_mut().copy_from_slice(&input);
    g.sample_size(30);
    g.bench_function("infer_fp32", |b| {
        b.iter(|| fp32.run(|o| o[0]).expect("runs"))
    });
    g.bench_function("infer_int8", |b| {
        b.iter(|| int8.run(|o| o[0]).expect("runs"))
    });
    g.bench_function("infer_fp32_2_threads", |b| {
        b.iter(|| fp32_2t.run(|o| o[0]).expect("runs"))
    });
    g.finish();

    println!("\n| model | tract ms | onnxruntime ms | tract / onnxruntime | max output diff |");
    println!("|---|---|---|---|---|");
    for (name, bytes, m) in [
        ("fp32", BUILTIN_ONNX, &mut fp32),
        ("int8", BUILTIN_INT8_ONNX, &mut int8),
    ] {
        let ours = bench::median_ms(&mut || {
            m.run(|o| o[0]).expect("runs");
        });
        let out: Vec<f32> = m.run(|o| o.to_vec()).expect("runs");
        match peer(name, bytes, &input, &out) {
            Some((p, line)) => println!(
                "| {name} | {ours:.2} | {p:.2} | {:.2} | {} |",
                ours / p,
                line.split_whitespace().nth(3).unwrap_or("?")
            ),
            None => println!(
                "| {name} | {ours:.2} | not run (python3 with onnxruntime not found) | | |"
            ),
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
