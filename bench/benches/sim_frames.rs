//! Simulator speed.
//!
//! * `raycast_360`: one revolution's 360 rays from a free spot, through the grid index and by
//!   brute force over every primitive (the peer: what the simulator would cost without spatial
//!   indexing), in the same world.
//! * `labelled_frames`: whole labelled frames (simulation, raster, boxes) in memory, on all
//!   threads, as `umbra-sim speed` measures them.
//!
//! `cargo bench -p umbra-bench --bench sim_frames`

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sim::dataset::{DatasetConfig, in_memory};
use sim::world::{RoomKind, World, WorldConfig};

fn raycast(c: &mut Criterion) {
    let cfg = WorldConfig {
        kinds: vec![RoomKind::TwoRooms],
        ..WorldConfig::default()
    };
    let world = World::generate(3, &cfg);
    let origin = world
        .free_point(&mut ChaCha8Rng::seed_from_u64(1), 0.5)
        .unwrap_or(world.robot_start);
    let mut g = c.benchmark_group("raycast_360");
    g.throughput(Throughput::Elements(360));
    g.bench_function("grid", |b| {
        b.iter(|| {
            for d in 0..360 {
                black_box(world.raycast(black_box(origin), (d as f32).to_radians(), 6.0));
            }
        })
    });
    g.bench_function("brute_force_peer", |b| {
        b.iter(|| {
            for d in 0..360 {
                black_box(world.raycast_brute(black_box(origin), (d as f32).to_radians(), 6.0));
            }
        })
    });
    g.finish();
}

fn frames(c: &mut Criterion) {
    let cfg = DatasetConfig {
        scenarios: 8,
        frames: 50,
        ..DatasetConfig::default()
    };
    let mut g = c.benchmark_group("labelled_frames");
    g.sample_size(10);
    g.throughput(Throughput::Elements((cfg.scenarios * cfg.frames) as u64));
    g.bench_function("in_memory_all_threads", |b| {
        b.iter(|| black_box(in_memory(&cfg)))
    });
    g.finish();
}

criterion_group!(benches, raycast, frames);
criterion_main!(benches);
