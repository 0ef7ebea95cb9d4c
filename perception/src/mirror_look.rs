//! Method B's second look: the same three revolutions mirrored, run through the network again,
//! and the two looks' boxes fused so that a box counts by what both looks say of it.
//!
//! The mirror is the one the training data is augmented with (`training/mirror.py`): column
//! `d` → `359 − d` of the 360 scan columns, padding left on the right. It is the room mirrored
//! and seen by a robot turned by 1°, an equally real scan, so a network that learnt furniture
//! (not one side of it) should find the same boxes in both looks. A phantom the network makes
//! of an accident of one image (a wall's dashes, a seam) is less often made again in its
//! mirror image.
//!
//! **Fusing** ([`fuse`], the two-model case of weighted boxes fusion): each box of the first
//! look is paired with the unused box of the second look (mirrored back) that overlaps it most,
//! at IoU ≥ [`FuseConfig::iou`] (of the same class unless `agnostic`). A pair becomes one box,
//! its sides the score-weighted mean of the two, its score the mean of the two scores. A box of
//! one look alone keeps half its score: the other look scored it below the threshold it was
//! decoded at, taken as 0. With `agnostic`, a pair whose classes differ keeps the surer look's
//! class at half its score. So both looks must be decoded at half the score the fused boxes
//! must reach ([`FuseConfig::look_decode`]). [`fuse_second_look`] is the whole step after the two
//! runs, for every caller (the runtime's frame, the image evaluator).
//!
//! Everything works in place or in caller-owned buffers: no allocation, no panic.

use heapless::Vec;

use crate::raster::{RASTER_H, RASTER_LEN, RASTER_W, SCAN_COLUMNS};
use crate::yolo::{DecodeConfig, Detection, iou};

/// A raster input that is not `3 × 64 × 384` floats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BadInputLength(pub usize);

impl core::fmt::Display for BadInputLength {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "raster input has {} floats, expected {RASTER_LEN}",
            self.0
        )
    }
}

impl core::error::Error for BadInputLength {}

/// Mirrors a channel-first `3 × 64 × 384` raster input in place: in every row of every channel,
/// column `d` ↔ `359 − d`; the padding columns stay as they are. Applying it twice restores the
/// input.
pub fn mirror_chw(input: &mut [f32]) -> Result<(), BadInputLength> {
    if input.len() != RASTER_LEN {
        return Err(BadInputLength(input.len()));
    }
    for row in input.chunks_exact_mut(RASTER_W) {
        row[..SCAN_COLUMNS].reverse();
    }
    debug_assert_eq!(input.len() / RASTER_W % RASTER_H, 0);
    Ok(())
}

/// A box found in the mirrored raster, in the columns of the raster as it was: `x → 360 − x`.
pub fn unmirror(d: &Detection) -> Detection {
    Detection {
        cx: SCAN_COLUMNS as f32 - d.cx,
        ..*d
    }
}

/// How the two looks' boxes are fused.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FuseConfig {
    /// A fused box's score must be above this (the runtime's `conf`).
    pub conf: f32,
    /// Two looks' boxes are one object at this IoU or more.
    pub iou: f32,
    /// Boxes of different classes pair (the surer class stays).
    pub agnostic: bool,
    /// Most boxes kept.
    pub max_det: usize,
}

impl FuseConfig {
    /// The weighted-boxes-fusion papers' pairing IoU (0.55).
    pub const PAIR_IOU: f32 = 0.55;

    /// The fusion that keeps what `decode` would keep of one look: its score threshold, its
    /// class-agnosticism, its number of boxes.
    pub fn of(decode: &DecodeConfig) -> FuseConfig {
        FuseConfig {
            conf: decode.conf,
            iou: Self::PAIR_IOU,
            agnostic: decode.agnostic,
            max_det: decode.max_det,
        }
    }

    /// How each look is decoded: as `decode`, at half of [`FuseConfig::conf`], so that a pair
    /// of boxes whose mean passes `conf` is not lost because one of the two was below it.
    pub fn look_decode(&self, decode: &DecodeConfig) -> DecodeConfig {
        DecodeConfig {
            conf: self.conf * 0.5,
            ..*decode
        }
    }
}

/// The step after both runs: `second` (the mirrored look's boxes) is mirrored back and fused
/// with `first` ([`fuse`]), and `first` then holds the fused boxes (`fused` is scratch).
pub fn fuse_second_look<const N: usize>(
    first: &mut Vec<Detection, N>,
    second: &mut Vec<Detection, N>,
    cfg: &FuseConfig,
    fused: &mut Vec<Detection, N>,
) -> FuseStats {
    for d in second.iter_mut() {
        *d = unmirror(d);
    }
    let stats = fuse(first, second, cfg, fused);
    core::mem::swap(first, fused);
    stats
}

/// What [`fuse`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FuseStats {
    /// Boxes both looks found.
    pub paired: usize,
    /// Boxes of one look alone.
    pub single: usize,
    /// Fused boxes above `conf` that did not fit `max_det` or the output.
    pub dropped: usize,
}

/// Fuses the first look's boxes `first` with the mirrored look's `second` (already mirrored
/// back, [`unmirror`]) into `out` (cleared first), best score first. `second` is used up: its
/// paired boxes' scores are set to NaN.
pub fn fuse<const N: usize>(
    first: &[Detection],
    second: &mut [Detection],
    cfg: &FuseConfig,
    out: &mut Vec<Detection, N>,
) -> FuseStats {
    out.clear();
    let mut stats = FuseStats::default();
    let mut keep = |d: Detection, stats: &mut FuseStats| {
        // NaN scores never pass.
        if d.score.partial_cmp(&cfg.conf) != Some(core::cmp::Ordering::Greater) {
            return;
        }
        if out.len() >= cfg.max_det || out.push(d).is_err() {
            stats.dropped += 1;
        }
    };
    for a in first {
        let ab = a.xyxy();
        let mut best: Option<(usize, f32)> = None;
        for (k, b) in second.iter().enumerate() {
            if b.score.is_nan() || !(cfg.agnostic || b.class == a.class) {
                continue;
            }
            let o = iou(&ab, &b.xyxy());
            if o >= cfg.iou && best.is_none_or(|(_, bo)| o > bo) {
                best = Some((k, o));
            }
        }
        let fused = match best {
            Some((k, _)) => {
                let b = second[k];
                second[k].score = f32::NAN;
                stats.paired += 1;
                pair(a, &b)
            }
            None => {
                stats.single += 1;
                Detection {
                    score: a.score * 0.5,
                    ..*a
                }
            }
        };
        keep(fused, &mut stats);
    }
    for b in second.iter().filter(|b| !b.score.is_nan()) {
        stats.single += 1;
        keep(
            Detection {
                score: b.score * 0.5,
                ..*b
            },
            &mut stats,
        );
    }
    // Best first; stable, so ties keep the first look's order. Insertion sort: a few dozen boxes.
    let s = out.as_mut_slice();
    for i in 1..s.len() {
        let mut j = i;
        while j > 0 && s[j - 1].score < s[j].score {
            s.swap(j - 1, j);
            j -= 1;
        }
    }
    stats
}

/// Two looks' boxes of one object as one box (module docs).
fn pair(a: &Detection, b: &Detection) -> Detection {
    if a.class != b.class {
        let surer = if b.score > a.score { b } else { a };
        return Detection {
            score: surer.score * 0.5,
            ..*surer
        };
    }
    let (wa, wb) = (a.score, b.score);
    let total = wa + wb;
    if total.is_nan() || total <= 0.0 {
        return *a;
    }
    let (aa, bb) = (a.xyxy(), b.xyxy());
    let mut s = [0.0f32; 4];
    for (i, v) in s.iter_mut().enumerate() {
        *v = (aa[i] * wa + bb[i] * wb) / total;
    }
    Detection {
        class: a.class,
        score: total * 0.5,
        cx: (s[0] + s[2]) * 0.5,
        cy: (s[1] + s[3]) * 0.5,
        w: s[2] - s[0],
        h: s[3] - s[1],
    }
}

#[cfg(test)]
mod test {
    use super::*;
    use crate::class::ObjectClass;

    fn det(class: ObjectClass, score: f32, cx: f32, w: f32) -> Detection {
        Detection {
            class,
            score,
            cx,
            cy: 20.0,
            w,
            h: 10.0,
        }
    }

    const CFG: FuseConfig = FuseConfig {
        conf: 0.25,
        iou: FuseConfig::PAIR_IOU,
        agnostic: true,
        max_det: 32,
    };

    #[test]
    fn mirroring_twice_restores_the_input_and_keeps_the_padding() {
        let mut x = [0.0f32; RASTER_LEN];
        for (i, v) in x.iter_mut().enumerate() {
            *v = (i % 7) as f32;
        }
        let orig = x;
        mirror_chw(&mut x).unwrap();
        // Row 5 of channel 1: column 0 now holds column 359, padding unchanged.
        let row = (RASTER_H + 5) * RASTER_W;
        assert_eq!(x[row], orig[row + 359]);
        assert_eq!(x[row + 359], orig[row]);
        assert_eq!(x[row + 100], orig[row + 259]);
        assert_eq!(
            x[row + 360..row + RASTER_W],
            orig[row + 360..row + RASTER_W]
        );
        mirror_chw(&mut x).unwrap();
        assert_eq!(x, orig);
        assert_eq!(mirror_chw(&mut x[1..]), Err(BadInputLength(RASTER_LEN - 1)));
    }

    #[test]
    fn a_box_mirrored_and_back_is_the_same_box() {
        // Columns 10..20 (bearings 10–19°) mirror to 340..350 (bearings 340–349°).
        let d = det(ObjectClass::Box, 0.9, 15.0, 10.0);
        let m = Detection { cx: 345.0, ..d };
        assert_eq!(unmirror(&m), d);
        assert_eq!(unmirror(&unmirror(&d)), d);
    }

    #[test]
    fn boxes_both_looks_found_are_averaged_and_lone_ones_halved() {
        let first = [
            det(ObjectClass::Chair, 0.8, 50.0, 10.0),
            det(ObjectClass::Box, 0.7, 200.0, 10.0), // alone: 0.35 stays
            det(ObjectClass::Desk, 0.4, 300.0, 10.0), // alone: 0.2 goes
        ];
        let mut second = [
            det(ObjectClass::Chair, 0.6, 51.0, 10.0),
            det(ObjectClass::Box, 0.45, 120.0, 8.0), // alone: 0.225 goes
        ];
        let mut out: Vec<Detection, 8> = Vec::new();
        let s = fuse(&first, &mut second, &CFG, &mut out);
        assert_eq!(
            s,
            FuseStats {
                paired: 1,
                single: 3,
                dropped: 0
            }
        );
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].class, ObjectClass::Chair);
        assert!((out[0].score - 0.7).abs() < 1e-6);
        // Sides weighted 0.8 : 0.6 → centre 50 + 1 · 0.6 / 1.4.
        assert!(
            (out[0].cx - (50.0 + 0.6 / 1.4)).abs() < 1e-4,
            "{}",
            out[0].cx
        );
        assert!((out[0].w - 10.0).abs() < 1e-4);
        assert_eq!(out[1].class, ObjectClass::Box);
        assert!((out[1].score - 0.35).abs() < 1e-6);
    }

    #[test]
    fn a_second_look_is_mirrored_back_before_it_is_fused() {
        let cfg = FuseConfig::of(&DecodeConfig::RUNTIME);
        assert_eq!((cfg.conf, cfg.max_det), (0.25, 32));
        assert_eq!(cfg.look_decode(&DecodeConfig::RUNTIME).conf, 0.125);
        let mut first: Vec<Detection, 4> = Vec::new();
        let mut second: Vec<Detection, 4> = Vec::new();
        let mut fused: Vec<Detection, 4> = Vec::new();
        first.push(det(ObjectClass::Box, 0.6, 15.0, 10.0)).unwrap();
        // The same box, found at columns 340..350 of the mirrored raster.
        second
            .push(det(ObjectClass::Box, 0.4, 345.0, 10.0))
            .unwrap();
        let s = fuse_second_look(&mut first, &mut second, &cfg, &mut fused);
        assert_eq!(s.paired, 1);
        assert_eq!(first.len(), 1);
        assert!((first[0].score - 0.5).abs() < 1e-6 && (first[0].cx - 15.0).abs() < 1e-4);
    }

    #[test]
    fn classes_that_differ_pair_only_when_agnostic() {
        let first = [det(ObjectClass::Chair, 0.9, 50.0, 10.0)];
        let second = [det(ObjectClass::Desk, 0.7, 50.0, 10.0)];
        let mut out: Vec<Detection, 8> = Vec::new();
        fuse(&first, &mut second.clone(), &CFG, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].class, ObjectClass::Chair);
        assert!((out[0].score - 0.45).abs() < 1e-6);
        let per_class = FuseConfig {
            agnostic: false,
            ..CFG
        };
        fuse(&first, &mut second.clone(), &per_class, &mut out);
        assert_eq!(out.len(), 2, "{out:?}");
        assert!(out[0].score > out[1].score);
    }

    #[test]
    fn a_full_output_counts_what_it_drops_and_nan_scores_never_pass() {
        let first = [
            det(ObjectClass::Box, 0.9, 50.0, 10.0),
            det(ObjectClass::Box, 0.8, 150.0, 10.0),
            det(ObjectClass::Box, f32::NAN, 250.0, 10.0),
        ];
        let mut out: Vec<Detection, 1> = Vec::new();
        let s = fuse(&first, &mut [], &CFG, &mut out);
        assert_eq!(out.len(), 1);
        assert_eq!(s.dropped, 1);
        assert!(out[0].score.is_finite());
    }
}
