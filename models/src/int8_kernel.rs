//! The int8 matrix kernel tract runs on x86-64 hosts that have AVX2 but no VNNI.
//!
//! tract-linalg 0.23.9 sends the int8 (`i8 × i8 → i32`) products of such hosts to
//! `avx2_mmm_i32_8x8`, whose inner loop reads its eight A bytes with a legacy-SSE `movq`
//! between 256-bit VEX instructions (`x86_64/fma/avx2_mmm_i32_8x8.S.j2`, line 120). Where the
//! CPU charges for moving between SSE and dirty-upper AVX state, every step of K pays for it:
//! on the AMD EPYC (Zen 3, KVM) machines our CI and sessions ran on in December 2026, ~107 ns
//! for that one instruction (a three-instruction loop, `movq` against `vmovq`: 107.5 against
//! 0.5–0.9 ns an iteration), the kernel at 0.5 GMAC/s against fma f32's 40, and the int8 file's
//! Method B at ~480 ms a frame against fp32's ~10 (`docs/method-b.md`). Intel Haswell and
//! Broadwell charge a transition the same way. Even with `vmovq` that kernel widens every byte
//! to i16 and multiplies one K step at a time (8 GMAC/s there).
//!
//! So this module brings a kernel of its own, [`KERNEL`]: an 8 × 4 tile over tract's K-by-4
//! packing (`PackedI8K4`), four K steps at a time with `vpmaddwd` (i16 pairs multiplied and
//! summed into i32: exact for i8 operands, so its accumulators are bit-identical to tract's),
//! written with `core::arch` intrinsics because no crate has such a kernel for tract. It does
//! only the products; everything a tile does after them (requantisation, bias, stores) it hands
//! to tract's own all-VEX 128-bit kernel `avx_mmm_i32_8x4` through a `LoadTile`, and the i32
//! packing (0) is that kernel's. A tract kernel tier names it for every int8 product but the
//! matrix-vector ones on AVX2 hosts without VNNI. Both are tract's extension points (kernels
//! and tiers are `inventory` data), so no tract source is patched; hosts with VNNI (AVX-VNNI,
//! AVX-512 VNNI, AMX) keep tract's choice. Remove this module once tract's AVX2 kernel is fast.
#![allow(unsafe_code)] // tract's kernel ABI (raw panel pointers) and `core::arch` intrinsics

use core::arch::x86_64::*;

use tract_linalg::isa::{Arch, Isa, IsaReq, IsaSet};
use tract_linalg::mmm::{DynKernel, FusedKerSpec, MatMatMul, Query, Suitable, suitable_named};
use tract_linalg::mmm_routines::MmmRoutine;
use tract_linalg::mmm_tiers::MmmTier;
use tract_linalg::pack::PackedI8K4;
use tract_linalg::x86_64::mmm::avx_mmm_i32_8x4;
use tract_onnx::prelude::DatumType;

/// The tier's name in tract's ladder (`RUST_LOG=debug` prints the ladder).
pub const TIER_NAME: &str = "umbra-avx2-int8";
/// The kernel this module adds.
pub const KERNEL: &str = "umbra_avx2_madd_i32_8x4";
/// Tract's kernel the tier falls back on where [`KERNEL`] does not fit a query.
pub const FALLBACK: &str = "avx_mmm_i32_8x4";

/// Above every x86-64 tier of tract 0.23.9 (1–8): unique per architecture, as tract requires;
/// [`applies`] keeps the tier off every host a higher tier of tract's is for.
const PRECEDENCE: u8 = 9;

const MR: usize = 8;
const NR: usize = 4;
/// The kernel's accumulators, i32, column-major (`memory-budget.md`).
pub const TILE_LEN: usize = MR * NR;
/// Bytes of one spec of tract's kernel ABI.
pub const SPEC_BYTES: usize = core::mem::size_of::<FusedKerSpec<i32>>();
/// The packing index of the i8 panels (index 0 is `avx_mmm_i32_8x4`'s i32 one).
const I8_PACKING: usize = 1;
/// The longest spec list handed on (tract's are a dozen at most; `memory-budget.md`).
pub const MAX_SPECS: usize = 32;
/// Returned to tract (which then fails the product with an error) for a spec list this kernel
/// cannot serve.
const UNSERVED: isize = 1;

/// AVX2 without any VNNI: the hosts tract sends to `avx2_mmm_i32_8x8`.
fn applies(isa: &IsaSet) -> bool {
    isa.has(Isa::X86_64Avx2)
        && !isa.has(Isa::X86_64AvxVnni)
        && !isa.has(Isa::X86_64Avx512Vnni)
        && !isa.has(Isa::X86_64AmxInt8)
}

/// Every int8 product but a matrix-vector one (tract's avx2 tier declines those too).
fn preferred(_: &IsaSet, acc: DatumType, q: &Query, s: &[Suitable]) -> Option<&'static str> {
    if acc != DatumType::I32 || q.n == Some(1) {
        return None;
    }
    Some(if suitable_named(s, KERNEL).is_some() {
        KERNEL
    } else {
        FALLBACK
    })
}

inventory::submit! {
    MmmTier { arch: Some(Arch::X86_64), precedence: PRECEDENCE, name: TIER_NAME, applies, preferred }
}

/// [`KERNEL`] as tract holds it: `avx_mmm_i32_8x4`'s declaration (stores, fusions, its i32
/// packing) with this module's body, i8 packing and name. Its preference sits just under the
/// AVX2 level so that tract's generic rules never pick it on their own: only the tier does.
fn kernel_object() -> DynKernel<MR, NR, i32> {
    let mut k = (*avx_mmm_i32_8x4).clone();
    k.name = KERNEL.to_string();
    k.kernel = kernel;
    k.isa = IsaReq::ANY.needing(&[Isa::X86_64Avx2]);
    k.boost = || -1;
    k.packings.truncate(I8_PACKING);
    k.with_packing(PackedI8K4::new(MR), PackedI8K4::new(NR))
}

fn make() -> Box<dyn MatMatMul> {
    Box::new(kernel_object())
}

inventory::submit! { MmmRoutine { make } }

/// The kernel body, tract's ABI: the tile's spec list, ending in `Done`; 0 when served.
///
/// Clear, LoadTile and the i8 products run here on a column-major tile; at the first other
/// spec the tile and the rest of the list go to `avx_mmm_i32_8x4`.
///
/// # Safety
/// tract's kernel contract: panel pointers hold `k` (padded to 4) K steps of this kernel's
/// packings, tile and store pointers are valid, and the host has AVX2 (the kernel's `isa`).
unsafe fn kernel(specs: &[FusedKerSpec<i32>]) -> isize {
    let mut tile = [0i32; TILE_LEN];
    for (i, spec) in specs.iter().enumerate() {
        match *spec {
            FusedKerSpec::Done => return 0,
            FusedKerSpec::Clear => tile = [0; TILE_LEN],
            FusedKerSpec::LoadTile(col_major, _) => {
                // SAFETY: tract's LoadTile points at a column-major MR × NR tile.
                unsafe { core::ptr::copy_nonoverlapping(col_major, tile.as_mut_ptr(), TILE_LEN) }
            }
            FusedKerSpec::AddMatMul {
                k,
                pa,
                pb,
                packing: I8_PACKING,
            } => {
                // SAFETY: the caller's contract; the kernel only runs where AVX2 is.
                unsafe { add_mat_mul(&mut tile, k, pa.cast(), pb.cast()) }
            }
            // SAFETY: the caller's contract, handed on.
            _ => return unsafe { hand_on(&tile, &specs[i..]) },
        }
    }
    0
}

/// Runs `rest` on `avx_mmm_i32_8x4`, its accumulators loaded from `tile` first.
///
/// # Safety
/// As [`kernel`].
unsafe fn hand_on(tile: &[i32; TILE_LEN], rest: &[FusedKerSpec<i32>]) -> isize {
    let i8_product = |s: &FusedKerSpec<i32>| {
        matches!(
            s,
            FusedKerSpec::AddMatMul {
                packing: I8_PACKING,
                ..
            }
        )
    };
    // An i8 product after other work is not a list tract makes; a longer list neither.
    if rest.len() >= MAX_SPECS || rest.iter().any(i8_product) {
        return UNSERVED;
    }
    let mut list = [FusedKerSpec::Done; MAX_SPECS];
    list[0] = FusedKerSpec::LoadTile(tile.as_ptr(), tile.as_ptr());
    list[1..=rest.len()].copy_from_slice(rest);
    // SAFETY: the caller's contract; the tile outlives the call.
    unsafe { (avx_mmm_i32_8x4.kernel)(&list[..=rest.len()]) }
}

/// `tile += A · B` over `k` K steps of an 8-row A panel and a 4-column B panel, both
/// `PackedI8K4` (per block of four K steps: each row's or column's four bytes in turn).
///
/// Per block, rows 0–3 and 4–7 of A widen to two vectors of i16 (`[r0k0..r0k3, r1k0..]`), the
/// four columns of B to one (`[c0k0..c0k3, c1k0..]`), and each column's four values,
/// broadcast, meet both A vectors in a `vpmaddwd`: lane pairs (k0+k1, k2+k3) per row,
/// summed into the tile at the end.
///
/// # Safety
/// `pa` and `pb` hold `k.div_ceil(4)` blocks (32 and 16 bytes); the host has AVX2.
#[target_feature(enable = "avx2")]
unsafe fn add_mat_mul(tile: &mut [i32; TILE_LEN], k: usize, pa: *const i8, pb: *const i8) {
    let zero = _mm256_setzero_si256();
    let (mut lo, mut hi) = ([zero; NR], [zero; NR]);
    for block in 0..k.div_ceil(4) {
        // SAFETY: within the panels, by the caller's contract.
        let (a, b) = unsafe { (pa.add(block * 4 * MR), pb.add(block * 4 * NR)) };
        let (a03, a47, b) = unsafe {
            (
                _mm256_cvtepi8_epi16(_mm_loadu_si128(a.cast())),
                _mm256_cvtepi8_epi16(_mm_loadu_si128(a.add(16).cast())),
                _mm256_cvtepi8_epi16(_mm_loadu_si128(b.cast())),
            )
        };
        let cols = [
            _mm256_permute4x64_epi64::<0x00>(b),
            _mm256_permute4x64_epi64::<0x55>(b),
            _mm256_permute4x64_epi64::<0xAA>(b),
            _mm256_permute4x64_epi64::<0xFF>(b),
        ];
        for (c, col) in cols.into_iter().enumerate() {
            lo[c] = _mm256_add_epi32(lo[c], _mm256_madd_epi16(a03, col));
            hi[c] = _mm256_add_epi32(hi[c], _mm256_madd_epi16(a47, col));
        }
    }
    for c in 0..NR {
        // hadd: [r0 r1 r4 r5 | r2 r3 r6 r7]; the 64-bit permute puts rows in order.
        let sums = _mm256_permute4x64_epi64::<0xD8>(_mm256_hadd_epi32(lo[c], hi[c]));
        // SAFETY: column c of the tile is 8 i32 at c * MR.
        unsafe {
            let dst = tile.as_mut_ptr().add(c * MR).cast::<__m256i>();
            _mm256_storeu_si256(dst, _mm256_add_epi32(_mm256_loadu_si256(dst), sums));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tract_linalg::BinOp;
    use tract_linalg::MmmDispatch;
    use tract_linalg::mmm::{AsInputValue, FusedSpec};
    use tract_linalg::mmm_tiers;
    use tract_onnx::prelude::{Tensor, tensor0};

    fn avx2() -> IsaSet {
        IsaSet::of_arch(Arch::X86_64)
            .with(Isa::X86_64Avx)
            .with(Isa::X86_64Avx2)
    }

    fn host_has_avx2() -> bool {
        let has = tract_linalg::isa::native().has(Isa::X86_64Avx2);
        if !has {
            println!("skipped: this host cannot run AVX2 kernels");
        }
        has
    }

    #[test]
    fn the_tier_and_kernel_are_linked_and_the_precedence_is_their_own() {
        let tiers: Vec<&MmmTier> = mmm_tiers::declared().collect();
        assert!(tiers.iter().any(|t| t.name == TIER_NAME), "tier not linked");
        let clash = tiers.iter().find(|t| {
            t.name != TIER_NAME && t.arch == Some(Arch::X86_64) && t.precedence == PRECEDENCE
        });
        assert!(
            clash.is_none(),
            "precedence {PRECEDENCE} taken by {}",
            clash.unwrap().name
        );
        let kernels: Vec<_> = tract_linalg::mmm_routines::declared()
            .map(|r| (r.make)())
            .collect();
        assert!(
            kernels.iter().any(|k| k.name() == KERNEL),
            "kernel not linked"
        );
    }

    #[test]
    fn the_tier_speaks_for_avx2_hosts_without_vnni_only() {
        assert!(applies(&avx2()));
        assert!(!applies(&avx2().with(Isa::X86_64AvxVnni)));
        assert!(!applies(
            &avx2().with(Isa::X86_64Avx512f).with(Isa::X86_64Avx512Vnni)
        ));
        assert!(!applies(
            &IsaSet::of_arch(Arch::X86_64).with(Isa::X86_64Avx)
        ));
    }

    #[test]
    fn int8_products_of_such_a_host_get_the_kernel_and_nothing_else_does() {
        if !host_has_avx2() {
            return;
        }
        let dispatch = MmmDispatch::for_isa(avx2());
        let pick = |acc, n| {
            let (mmm, _, _) = dispatch
                .pick(&Query::plain(acc, Some(64), Some(576), n))
                .unwrap();
            mmm.name().to_string()
        };
        assert_eq!(pick(DatumType::I32, Some(1536)), KERNEL);
        assert_ne!(
            pick(DatumType::I32, Some(1)),
            KERNEL,
            "matrix-vector stays tract's"
        );
        assert_ne!(pick(DatumType::F32, Some(1536)), KERNEL);
    }

    /// Deterministic i8 values over the whole range.
    fn bytes(len: usize, seed: u32) -> Vec<i8> {
        let mut s = seed;
        (0..len)
            .map(|_| {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (s >> 24) as u8 as i8
            })
            .collect()
    }

    /// `C = A · B` (A `m × k`, B `k × n`, i8, row-major) by `mmm`'s i8 packing, then
    /// `after`, stored as i32.
    fn product(
        mmm: &dyn MatMatMul,
        (m, k, n): (usize, usize, usize),
        (a, b): (&[i8], &[i8]),
        after: &[FusedSpec],
    ) -> Vec<i32> {
        let a = Tensor::from_shape(&[m, k], a).unwrap();
        let b = Tensor::from_shape(&[k, n], b).unwrap();
        let (pack_a, pack_b) = &mmm.packings()[I8_PACKING];
        let pa = pack_a.prepare_one(&a, 1, 0).unwrap();
        let pb = pack_b.prepare_one(&b, 0, 1).unwrap();
        let mut c = Tensor::zero::<i32>(&[m, n]).unwrap();
        // SAFETY: the store spec wraps `c`, which outlives the run.
        let store = unsafe {
            mmm.c_from_data_and_strides(4, n as isize, 1)
                .wrap(&c.view_mut())
        };
        let mut specs = vec![FusedSpec::AddMatMul {
            a: AsInputValue::Borrowed(&*pa),
            b: AsInputValue::Borrowed(&*pb),
            packing: I8_PACKING,
        }];
        specs.extend(after.iter().cloned());
        specs.push(FusedSpec::Store(store));
        // SAFETY: packed panels and store as the kernel declares them.
        unsafe { mmm.run(m, n, &specs).unwrap() };
        c.try_as_plain_ram()
            .unwrap()
            .as_slice::<i32>()
            .unwrap()
            .to_vec()
    }

    /// The operands of a shape (deterministic) and their exact product.
    fn operands((m, k, n): (usize, usize, usize)) -> (Vec<i8>, Vec<i8>, Vec<i32>) {
        let (a, b) = (bytes(m * k, 7), bytes(k * n, 11));
        let mut c = vec![0i32; m * n];
        for r in 0..m {
            for col in 0..n {
                c[r * n + col] = (0..k)
                    .map(|i| a[r * k + i] as i32 * b[i * n + col] as i32)
                    .sum();
            }
        }
        (a, b, c)
    }

    const SHAPES: [(usize, usize, usize); 5] = [
        (8, 4, 4),
        (8, 1, 4),
        (13, 27, 11),
        (64, 576, 50),
        (3, 1152, 7),
    ];

    #[test]
    fn products_equal_the_exact_ones_at_every_shape() {
        if !host_has_avx2() {
            return;
        }
        let ours = kernel_object();
        for shape in SHAPES {
            let (a, b, c) = operands(shape);
            assert_eq!(product(&ours, shape, (&a, &b), &[]), c, "{shape:?}");
        }
        // The largest products (-128 · -128, summed) stay exact.
        let (m, k, n) = (8, 64, 4);
        let c = product(
            &ours,
            (m, k, n),
            (&vec![-128; m * k], &vec![-128; k * n]),
            &[],
        );
        assert!(c.iter().all(|&x| x == 64 * 128 * 128), "{c:?}");
    }

    #[test]
    fn work_after_the_product_is_tracts_own() {
        if !host_has_avx2() {
            return;
        }
        let (ours, theirs) = (kernel_object(), avx_mmm_i32_8x4.mmm());
        let (three, minus_five) = (tensor0(3i32), tensor0(-5i32));
        let after = [
            FusedSpec::BinScalar(&three, BinOp::Mul),
            FusedSpec::BinScalar(&minus_five, BinOp::Add),
        ];
        for shape in SHAPES {
            let (a, b, c) = operands(shape);
            let expected: Vec<i32> = c.iter().map(|x| x * 3 - 5).collect();
            assert_eq!(
                product(&ours, shape, (&a, &b), &after),
                expected,
                "{shape:?}"
            );
            let tracts = product(&*theirs, shape, (&a, &b), &after);
            assert_eq!(tracts, expected, "tract's, {shape:?}");
        }
    }
}
