//! Method A speed: one full scene (the largest held-out cloud), cloud update to labelled objects, the
//! adaptive DBSCAN alone and the cloud's clearing of what the rays passed through; with scikit-learn's DBSCAN on the same points as the peer
//! (`bench/dbscan_peer.py`, run in the same process tree when python3 with scikit-learn is
//! there; the ratios are printed).
//!
//! `cargo bench -p umbra-bench --bench method_a`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use lab::scenes_a::{PoseSource, SceneConfig, run_scene};
use perception::geometry::Point2;
use perception::method_a::{MethodA, MethodAConfig};

/// The oscillating scene of seed 2 (held-out rooms) whose cloud is largest after 80
/// revolutions (stopping at the first to reach 7,000 points). The simulated rooms with the
/// 3.5 m range window give 4,000–4,700 points; the figure printed is the one measured.
fn scene() -> (Box<MethodA>, Point2) {
    let cfg = SceneConfig {
        seed: 2,
        frames: 80,
        first: 79,
        every: 1,
        pose: PoseSource::Odometry,
        ..SceneConfig::default()
    };
    let mut m = Box::new(MethodA::new());
    let mut sensor = Point2::default();
    for i in (0..200).step_by(2) {
        run_scene(
            i,
            &cfg,
            &MethodAConfig::default(),
            &mut m,
            models::forest::forest(),
            |v| {
                sensor = v.sensor;
            },
        );
        if m.cloud().len() >= 7_000 {
            println!("scene {i} of seed 2");
            break;
        }
    }
    (m, sensor)
}

fn peer_ms(points: &[Point2]) -> Option<f64> {
    let path = std::env::temp_dir().join("umbra-method-a-cloud.csv");
    let text: String = points
        .iter()
        .map(|p| format!("{},{}\n", p.x, p.y))
        .collect();
    std::fs::write(&path, text).ok()?;
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/dbscan_peer.py");
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(&path)
        .output()
        .ok()?;
    let s = String::from_utf8_lossy(&out.stdout);
    println!("peer: {}", s.trim());
    s.split_whitespace().nth(1)?.parse().ok()
}

fn bench(c: &mut Criterion) {
    let (base, sensor) = scene();
    let cfg = MethodAConfig::default();
    let points: Vec<Point2> = base.cloud().iter().copied().collect();
    println!(
        "scene: {} cloud points, {} candidates, {} segments, {} doors",
        points.len(),
        base.candidates().len(),
        base.segments().len(),
        base.doors().len()
    );
    let forest = models::forest::forest();
    let mut g = c.benchmark_group("method_a");
    // The whole frame: add a revolution's worth of points (age + insert), then run.
    let ranges = [2.0f32; 360];
    let mut m = base.clone();
    g.bench_function("full_frame", |b| {
        b.iter(|| {
            m.add_scan(
                &perception::cloud::Scan {
                    ranges: black_box(&ranges),
                    start: perception::geometry::Pose2::IDENTITY,
                    end: perception::geometry::Pose2::IDENTITY,
                    mount: perception::geometry::Pose2::IDENTITY,
                },
                &MethodAConfig {
                    cloud: perception::cloud::CloudConfig {
                        drop_fraction: 0.0,
                        ..cfg.cloud
                    },
                    ..cfg
                },
            );
            m.run(sensor, &cfg, forest);
            // Back to the same cloud for the next iteration.
            m.clone_from(&base);
        })
    });
    let mut d = Box::new(perception::dbscan::Dbscan::new());
    g.bench_function("dbscan", |b| {
        b.iter(|| d.run(black_box(&points), &cfg.dbscan))
    });
    // Forgetting what the rays passed through (`GlobalCloud::clear_seen_through`), every
    // point looked at: a revolution of returns at 0.5 m passes no point, so none goes and
    // every iteration sees the whole cloud.
    let mut cloud = perception::cloud::GlobalCloud::new();
    for p in &points {
        cloud.push(*p);
    }
    let near = [0.5f32; 360];
    let scan = perception::cloud::Scan {
        ranges: &near,
        start: perception::geometry::Pose2::new(sensor.x, sensor.y, 0.0),
        end: perception::geometry::Pose2::new(sensor.x, sensor.y, 0.05),
        mount: perception::geometry::Pose2::IDENTITY,
    };
    let (margin, beyond) = (cfg.cloud.clear_margin_m, cfg.cloud.clear_beyond_rays);
    g.bench_function("cloud_clear", |b| {
        b.iter(|| cloud.clear_seen_through(black_box(&scan), margin, beyond))
    });
    let mut copy = base.clone();
    g.bench_function("clone_state_for_reference", |b| {
        b.iter(|| copy.clone_from(&base))
    });
    g.finish();

    // Ratios against the peer, timed here with the same points.
    let time = bench::median_ms;
    let mut m2 = base.clone();
    let ours_full = time(&mut || m2.run(sensor, &cfg, forest));
    let ours_dbscan = time(&mut || d.run(&points, &cfg.dbscan));
    let ours_clear = time(&mut || {
        cloud.clear_seen_through(&scan, margin, beyond);
    });
    println!(
        "ours: pipeline run {ours_full:.4} ms, DBSCAN {ours_dbscan:.4} ms, clearing the cloud \
         {ours_clear:.4} ms ({:.3} of the pipeline run) (medians of 200)",
        ours_clear / ours_full
    );
    match peer_ms(&points) {
        Some(p) => println!(
            "ratio to scikit-learn DBSCAN ({p:.4} ms): pipeline {:.4}, DBSCAN {:.4}",
            ours_full / p,
            ours_dbscan / p
        ),
        None => println!("peer not run: python3 with scikit-learn not found"),
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
