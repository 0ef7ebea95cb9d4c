//! The detectors' plausibility checks per frame — pieces of wall from the revolution's own
//! returns (`perception::wall_piece`) and round "boxes" (`perception::outline`) — on 24
//! detections of a simulated room, against the same fits done the textbook way: for every
//! detection the returns near it gathered alike, then a total-least-squares line and an
//! algebraic circle by SVD (nalgebra), the code people write first. Both sides do the fits;
//! ours also decide.
//!
//! A 6 × 5 m room seen from inside: its walls, four boxes, two bins; detections on furniture,
//! on walls, at corners and in free space.
//!
//! `cargo bench -p umbra-bench --bench plausible_checks`

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{DMatrix, DVector};
use perception::class::ObjectClass;
use perception::fusion::{Evidence, FrameObject, FrameObjects};
use perception::geometry::{Point2, Pose2};
use perception::outline::drop_round_boxes;
use perception::sight::returns;
use perception::wall_piece::drop_wall_pieces;
use std::hint::black_box;

/// The revolution from the room's centre: walls at x = ±3, y = ±2.5, boxes and bins.
fn revolution() -> [f32; 360] {
    let boxes = [(1.5, 1.0), (-2.0, -1.5), (0.5, -1.8), (-1.0, 1.6)];
    let bins = [(2.0, -1.0, 0.15), (-2.2, 0.8, 0.2)];
    let mut r = [0.0f32; 360];
    for (d, slot) in r.iter_mut().enumerate() {
        let a = (d as f32).to_radians();
        let (dx, dy) = (a.cos(), a.sin());
        let mut best = f32::INFINITY;
        for t in [3.0 / dx, -3.0 / dx, 2.5 / dy, -2.5 / dy] {
            if t > 0.0 && t.is_finite() {
                best = best.min(t);
            }
        }
        for (cx, cy) in boxes {
            // Axis-aligned 0.6 × 0.4 m boxes: slab intersection.
            let (tx0, tx1) = ((cx - 0.3) / dx, (cx + 0.3) / dx);
            let (ty0, ty1) = ((cy - 0.2) / dy, (cy + 0.2) / dy);
            let t0 = tx0.min(tx1).max(ty0.min(ty1));
            let t1 = tx0.max(tx1).min(ty0.max(ty1));
            if t0 > 0.0 && t0 <= t1 {
                best = best.min(t0);
            }
        }
        for (cx, cy, rad) in bins {
            let b = dx * cx + dy * cy;
            let disc = b * b - (cx * cx + cy * cy - rad * rad);
            if disc >= 0.0 {
                best = best.min(b - disc.sqrt());
            }
        }
        // A deterministic ±1 cm ripple as noise.
        *slot = best + 0.01 * ((d * 7919 % 13) as f32 / 6.0 - 1.0);
    }
    r
}

fn detections() -> FrameObjects {
    let mut o = FrameObjects::new();
    let places = [
        (1.5, 1.0),
        (-2.0, -1.5),
        (0.5, -1.8),
        (-1.0, 1.6),
        (2.0, -1.0),
        (-2.2, 0.8),
        (3.0, 0.5),
        (-3.0, -0.4),
        (0.8, 2.5),
        (-1.5, -2.5),
        (2.9, 2.4),
        (-2.9, -2.4),
        (0.0, 1.0),
        (1.0, 0.0),
        (-0.5, -0.7),
        (2.3, 1.9),
        (3.1, -1.5),
        (-1.8, 2.6),
        (1.2, -2.4),
        (-2.6, 1.9),
        (0.3, 0.4),
        (-0.9, 0.2),
        (2.6, -2.2),
        (-0.2, -2.45),
    ];
    for (k, (x, y)) in places.into_iter().enumerate() {
        let _ = o.push(FrameObject {
            class: [ObjectClass::Box, ObjectClass::Chair, ObjectClass::Desk][k % 3],
            centre: Point2::new(x, y),
            score: 0.8,
            evidence: Evidence::B,
            bbox: None,
            width_m: 0.0,
        });
    }
    o
}

/// The peer: per detection, the returns within 0.35 m, a total-least-squares line (SVD of the
/// centred points) and a circle (least squares of x² + y² + D x + E y + F = 0, by SVD).
fn peer(objects: &FrameObjects, ranges: &[f32; 360]) -> f32 {
    let pts: Vec<(f32, f32)> = ranges
        .iter()
        .enumerate()
        .filter(|&(_, &r)| r > 0.0)
        .map(|(d, &r)| {
            let a = (d as f32).to_radians();
            (r * a.cos(), r * a.sin())
        })
        .collect();
    let mut acc = 0.0;
    for o in objects {
        let near: Vec<(f32, f32)> = pts
            .iter()
            .copied()
            .filter(|&(x, y)| (x - o.centre.x).hypot(y - o.centre.y) <= 0.35)
            .collect();
        if near.len() < 3 {
            continue;
        }
        let n = near.len();
        let (mx, my) = near.iter().fold((0.0, 0.0), |(a, b), &(x, y)| {
            (a + x / n as f32, b + y / n as f32)
        });
        let centred = DMatrix::from_fn(n, 2, |i, j| {
            if j == 0 {
                near[i].0 - mx
            } else {
                near[i].1 - my
            }
        });
        let svd = centred.svd(false, true);
        acc += svd.singular_values.min();
        let a = DMatrix::from_fn(n, 3, |i, j| match j {
            0 => near[i].0,
            1 => near[i].1,
            _ => 1.0,
        });
        let b = DVector::from_fn(n, |i, _| -(near[i].0 * near[i].0 + near[i].1 * near[i].1));
        if let Ok(x) = a.svd(true, true).solve(&b, 1e-9) {
            acc += x[2];
        }
    }
    acc
}

fn bench(c: &mut Criterion) {
    let ranges = revolution();
    let objects = detections();
    let mut g = c.benchmark_group("plausible_checks");
    g.bench_function("umbra wall_piece + outline, 24 detections", |b| {
        b.iter(|| {
            let mut o = objects.clone();
            let pts = returns(black_box(&ranges));
            let n = drop_wall_pieces(&mut o, &Pose2::IDENTITY, &pts)
                + drop_round_boxes(&mut o, &Pose2::IDENTITY, &pts);
            black_box(n)
        })
    });
    g.bench_function(
        "peer: nalgebra SVD line + circle fits, 24 detections",
        |b| b.iter(|| black_box(peer(black_box(&objects), black_box(&ranges)))),
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
