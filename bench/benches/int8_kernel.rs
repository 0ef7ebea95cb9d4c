//! The int8 matrix kernel of x86-64 AVX2 hosts without VNNI (`models::int8_kernel`) against
//! tract's two that it stands in for: `avx2_mmm_i32_8x8` (tract's pick on such hosts) and
//! `avx_mmm_i32_8x4` (its all-VEX 128-bit sibling), one thread, the same packed operands
//! each, at the shapes of three of Method B's convolutions (`m` output channels, `k` = input
//! channels × 3 × 3, `n` output pixels). The ratios to ours are printed. Elsewhere (another
//! architecture, or a host without AVX2) it prints why and measures nothing.

use criterion::{Criterion, criterion_group, criterion_main};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::time::{Duration, Instant};

    use criterion::Criterion;
    use tract_linalg::mmm::{AsInputValue, FusedSpec, MatMatMul};
    use tract_onnx::prelude::{DatumType, Tensor};

    /// (m, k, n) of three convolutions of the 64 × 384 model.
    const SHAPES: [(usize, usize, usize); 3] = [(32, 288, 1536), (64, 576, 384), (128, 1152, 96)];

    fn kernel(name: &str) -> Box<dyn MatMatMul> {
        tract_linalg::mmm_routines::declared()
            .map(|r| (r.make)())
            .find(|k| k.name() == name)
            .unwrap_or_else(|| panic!("{name} is not linked"))
    }

    /// Time of `iters` products C = A · B on `mmm`'s i8 packing.
    fn time(mmm: &dyn MatMatMul, (m, k, n): (usize, usize, usize), iters: u64) -> Duration {
        let a = Tensor::zero_dt(DatumType::I8, &[m, k]).unwrap();
        let b = Tensor::zero_dt(DatumType::I8, &[k, n]).unwrap();
        let (pack_a, pack_b) = &mmm.packings()[1];
        let pa = pack_a.prepare_one(&a, 1, 0).unwrap();
        let pb = pack_b.prepare_one(&b, 0, 1).unwrap();
        // SAFETY: scratch space and packed panels as the kernel declares them.
        let mut scratch = unsafe { mmm.allocate_scratch_space() };
        let specs = [FusedSpec::AddMatMul {
            a: AsInputValue::Borrowed(&*pa),
            b: AsInputValue::Borrowed(&*pb),
            packing: 1,
        }];
        let t = Instant::now();
        for _ in 0..iters {
            // SAFETY: as above.
            unsafe {
                mmm.run_with_scratch_space(m, n, scratch.as_mut(), &specs)
                    .unwrap()
            };
        }
        t.elapsed()
    }

    pub fn bench(c: &mut Criterion) {
        if !std::is_x86_feature_detected!("avx2") {
            println!("int8_kernel: this host has no AVX2; nothing to measure");
            return;
        }
        let names = [
            models::int8_kernel::KERNEL,
            "avx2_mmm_i32_8x8",
            "avx_mmm_i32_8x4",
        ];
        let mut medians = vec![];
        for shape in SHAPES {
            let mut group = c.benchmark_group(format!("int8_kernel/{shape:?}"));
            group.sample_size(20);
            let mut row = vec![];
            for name in names {
                let mmm = kernel(name);
                group.bench_function(name, |b| b.iter_custom(|iters| time(&*mmm, shape, iters)));
                // One more measurement outside criterion for the ratio table.
                row.push(time(&*mmm, shape, 20).as_secs_f64() / 20.0);
            }
            group.finish();
            medians.push((shape, row));
        }
        println!("\n| (m, k, n) | ours ms | avx2_mmm_i32_8x8 / ours | avx_mmm_i32_8x4 / ours |");
        println!("|---|---|---|---|");
        for ((m, k, n), row) in medians {
            println!(
                "| ({m}, {k}, {n}) | {:.3} | {:.1} | {:.1} |",
                row[0] * 1e3,
                row[1] / row[0],
                row[2] / row[0]
            );
        }
    }
}

fn bench(c: &mut Criterion) {
    #[cfg(target_arch = "x86_64")]
    x86::bench(c);
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = c;
        println!("int8_kernel: x86-64 only; nothing to measure here");
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
