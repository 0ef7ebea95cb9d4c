//! Method B's output side: the YOLOv8 output tensor decoded into boxes, non-maximum
//! suppression, and each box's centre in the map frame. `no_std`, allocation-free: every buffer
//! is a fixed-capacity `heapless::Vec` owned by the caller.
//!
//! ## The output tensor
//!
//! [`decode`] reads either of two forms of a YOLOv8 detection head, told apart by the tensor's
//! length ([`Head`]); both are row-major `(1, rows, A)` floats, the value of row `k`, anchor `a`
//! at `k · A + a`. For our 64 × 384 input and strides 8, 16, 32 there are [`ANCHORS`] =
//! 8·48 + 4·24 + 2·12 = 504 anchors, level by level, each level's grid row by row.
//!
//! - [`Head::Boxes`], Ultralytics' own export: `4 + NC` rows. Rows 0–3 are the box centre x,
//!   centre y, width and height in **input pixels** (384 × 64), rows 4.. the per-class scores
//!   with the sigmoid already applied; there is no objectness row.
//! - [`Head::Logits`], the same graph cut before its box decoding (`training/logits_head.py`,
//!   what the runtime ships): `4 · 16 + NC` rows. Rows `16·s .. 16·s + 16` are the logits of
//!   the distance from the anchor's centre to box side `s` (left, top, right, bottom) over
//!   [`DFL_BINS`] bins of one stride each, the rows after them the class logits. The decoder
//!   does what the graph did — the softmax's expectation per side (YOLOv8's "DFL"), the
//!   anchor arithmetic, the sigmoid — and only for the anchors above the score threshold.
//!   tract runs the graph's own DFL softmax, whose axis is not the last, on a slow generic
//!   path (29 % of the model's time, `docs/method-b.md`); here it is a few hundred `expf`s.
//!
//! ## Suppression, as Ultralytics does it
//!
//! [`decode`] follows `ultralytics.utils.ops.non_max_suppression` so that our evaluator and
//! Ultralytics' validator see the same boxes: a candidate is an anchor (or, with
//! `multi_label`, an anchor–class pair) whose score is **above** `conf`; candidates are taken in
//! descending score order (ties by anchor, then class); a candidate is dropped when its IoU
//! with an already kept box of the same class (any class when `agnostic`) is **above** `iou`;
//! at most `max_det` are kept.
//!
//! ## From a box to the map
//!
//! A box's column centre is a bearing and its row centre a range, by the raster's own mapping
//! ([`crate::raster`]): the training labels put a footprint spanning bearings `[b0, b1]` in
//! columns `[b0, b1 + 1)`, so the bearing of the centre is `cx − 0.5` degrees; rows span the
//! footprint's nearest point to its farthest corner, so `cy · max_range / 63` is the middle of
//! that span, close to the object's centre. [`Detection::centre`] turns that into a map point
//! with the pose the raster was labelled in (the LiDAR at revolution t−1).

use core::fmt;

use heapless::Vec;

use crate::class::ObjectClass;
use crate::geometry::{Point2, Pose2};
use crate::raster::{RASTER_H, RASTER_W, RasterConfig};

/// Classes the model scores (chair, box, desk, door frame: [`ObjectClass::ALL`] order).
pub const NUM_CLASSES: usize = 4;
/// Rows of the output tensor: 4 box values and the class scores.
pub const OUTPUT_ROWS: usize = 4 + NUM_CLASSES;
/// Anchors of a 64 × 384 input at strides 8, 16 and 32.
pub const ANCHORS: usize = (RASTER_H / 8) * (RASTER_W / 8)
    + (RASTER_H / 16) * (RASTER_W / 16)
    + (RASTER_H / 32) * (RASTER_W / 32);
/// Floats in one output tensor.
pub const OUTPUT_LEN: usize = OUTPUT_ROWS * ANCHORS;
/// Candidates one frame can produce before suppression (every anchor–class pair).
pub const MAX_RAW_CANDIDATES: usize = ANCHORS * NUM_CLASSES;
/// Detections the runtime keeps per frame.
pub const MAX_DETECTIONS: usize = 32;
/// Bins of each box side's distance distribution (YOLOv8's `reg_max`).
pub const DFL_BINS: usize = 16;
/// Rows of a [`Head::Logits`] tensor: 4 sides × [`DFL_BINS`], then the class logits.
pub const LOGIT_ROWS: usize = 4 * DFL_BINS + NUM_CLASSES;
/// Floats in a [`Head::Logits`] tensor, the largest [`decode`] reads.
pub const LOGITS_LEN: usize = LOGIT_ROWS * ANCHORS;
/// The anchor grid's levels as (stride, rows, columns), in the tensor's order.
const LEVELS: [(usize, usize, usize); 3] = [
    (8, RASTER_H / 8, RASTER_W / 8),
    (16, RASTER_H / 16, RASTER_W / 16),
    (32, RASTER_H / 32, RASTER_W / 32),
];

/// The two forms of detection head [`decode`] reads (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Head {
    /// Boxes in pixels and class probabilities: [`OUTPUT_ROWS`] rows.
    Boxes,
    /// Box-side bins and class logits: [`LOGIT_ROWS`] rows, for the 64 × 384 grid only.
    Logits,
}

impl Head {
    /// Rows of this form's tensor.
    pub const fn rows(self) -> usize {
        match self {
            Head::Boxes => OUTPUT_ROWS,
            Head::Logits => LOGIT_ROWS,
        }
    }

    /// The form of a tensor of `len` floats over `anchors` anchors, if it is one.
    pub fn of(len: usize, anchors: usize) -> Option<Head> {
        if len == OUTPUT_ROWS * anchors {
            Some(Head::Boxes)
        } else if anchors == ANCHORS && len == LOGITS_LEN {
            Some(Head::Logits)
        } else {
            None
        }
    }
}

/// Centre x, y (px) and stride of anchor `a` of the 64 × 384 grid.
fn anchor_point(a: usize) -> (f32, f32, f32) {
    let mut rest = a;
    for (stride, rows, cols) in LEVELS {
        if rest < rows * cols {
            let s = stride as f32;
            let (y, x) = (rest / cols, rest % cols);
            return ((x as f32 + 0.5) * s, (y as f32 + 0.5) * s, s);
        }
        rest -= rows * cols;
    }
    // Callers pass a < ANCHORS; a point off the grid decodes to nothing useful but no panic.
    (f32::NAN, f32::NAN, 0.0)
}

/// The expected bin of one side's logits `z` (softmax, then Σ j·p_j), in strides.
fn expected_bin(z: impl Fn(usize) -> f32) -> f32 {
    let m = (0..DFL_BINS).map(&z).fold(f32::NEG_INFINITY, f32::max);
    let (mut sum, mut weighted) = (0.0f32, 0.0f32);
    for j in 0..DFL_BINS {
        let e = libm::expf(z(j) - m);
        sum += e;
        weighted += j as f32 * e;
    }
    weighted / sum
}

/// The logistic function.
fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + libm::expf(-x))
}

/// One detected object, in raster pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Detection {
    /// Class.
    pub class: ObjectClass,
    /// Class score in [0, 1].
    pub score: f32,
    /// Centre column, px.
    pub cx: f32,
    /// Centre row, px.
    pub cy: f32,
    /// Width, px.
    pub w: f32,
    /// Height, px.
    pub h: f32,
}

impl Detection {
    /// The box as `[x0, y0, x1, y1]`.
    pub fn xyxy(&self) -> [f32; 4] {
        [
            self.cx - self.w / 2.0,
            self.cy - self.h / 2.0,
            self.cx + self.w / 2.0,
            self.cy + self.h / 2.0,
        ]
    }

    /// Range (m) and bearing (rad, counter-clockwise from the LiDAR's forward axis, in
    /// (−π, π]) of the box centre.
    pub fn polar(&self, cfg: &RasterConfig) -> (f32, f32) {
        let range = self.cy.max(0.0) * cfg.max_range_m / (RASTER_H - 1) as f32;
        let bearing = crate::geometry::wrap_angle((self.cx - 0.5).to_radians());
        (range, bearing)
    }

    /// The box centre in the map frame, seen from `lidar` (the LiDAR's map pose when the
    /// raster's middle revolution was taken).
    pub fn centre(&self, lidar: &Pose2, cfg: &RasterConfig) -> Point2 {
        let (range, bearing) = self.polar(cfg);
        lidar.transform(Point2::from_polar(range, bearing))
    }
}

/// Intersection over union of two `[x0, y0, x1, y1]` boxes (0 for empty boxes).
pub fn iou(a: &[f32; 4], b: &[f32; 4]) -> f32 {
    let iw = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
    let ih = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
    let inter = iw * ih;
    let area = |r: &[f32; 4]| (r[2] - r[0]).max(0.0) * (r[3] - r[1]).max(0.0);
    let union = area(a) + area(b) - inter;
    if union > 0.0 { inter / union } else { 0.0 }
}

/// Decoding and suppression settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecodeConfig {
    /// Scores must be above this.
    pub conf: f32,
    /// A box whose IoU with a kept box is above this is suppressed.
    pub iou: f32,
    /// Every class above `conf` of an anchor is a candidate, not only the best.
    pub multi_label: bool,
    /// Boxes of different classes suppress each other.
    pub agnostic: bool,
    /// Most boxes kept (also bounded by the output's capacity).
    pub max_det: usize,
}

impl DecodeConfig {
    /// The runtime's defaults: Ultralytics' prediction thresholds (0.25, 0.7), one label per
    /// anchor and class-agnostic suppression, so one object gives one report.
    pub const RUNTIME: DecodeConfig = DecodeConfig {
        conf: 0.25,
        iou: 0.7,
        multi_label: false,
        agnostic: true,
        max_det: MAX_DETECTIONS,
    };

    /// Ultralytics' validation settings (conf 0.001, IoU 0.7, multi-label, 300 boxes):
    /// what mAP is computed from.
    pub const VALIDATION: DecodeConfig = DecodeConfig {
        conf: 0.001,
        iou: 0.7,
        multi_label: true,
        agnostic: false,
        max_det: 300,
    };
}

impl Default for DecodeConfig {
    fn default() -> Self {
        Self::RUNTIME
    }
}

/// Why an output tensor could not be decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum DecodeError {
    /// The slice is neither `OUTPUT_ROWS × anchors` nor `LOGIT_ROWS × ANCHORS` floats.
    BadLength {
        /// Floats given.
        len: usize,
        /// Anchors the caller said the tensor has.
        anchors: usize,
    },
    /// More anchors than the candidate buffer is sized for.
    TooManyAnchors(usize),
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::BadLength { len, anchors } => write!(
                f,
                "YOLO output has {len} floats, expected {OUTPUT_ROWS} × {anchors} (boxes) \
                 or {LOGIT_ROWS} × {ANCHORS} (box-side bins and class logits)"
            ),
            DecodeError::TooManyAnchors(a) => {
                write!(
                    f,
                    "YOLO output has {a} anchors, at most {ANCHORS} supported"
                )
            }
        }
    }
}

impl core::error::Error for DecodeError {}

/// A box before suppression.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Candidate {
    score: f32,
    anchor: u16,
    class: u8,
}

/// Working memory of [`decode`] (one per caller; ~16 kB).
pub struct DecodeScratch {
    candidates: Vec<Candidate, MAX_RAW_CANDIDATES>,
}

impl DecodeScratch {
    /// An empty scratch buffer.
    pub const fn new() -> Self {
        DecodeScratch {
            candidates: Vec::new(),
        }
    }
}

impl Default for DecodeScratch {
    fn default() -> Self {
        Self::new()
    }
}

/// What [`decode`] did besides its output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecodeStats {
    /// Candidates above the score threshold.
    pub candidates: usize,
    /// Boxes that survived suppression but did not fit `max_det` or the output.
    pub dropped: usize,
    /// Anchors with a non-finite value (skipped).
    pub non_finite: usize,
}

/// Decodes `output` (either [`Head`] form over `anchors` anchors, see the module docs) into
/// `out` (cleared first), best score first.
pub fn decode<const N: usize>(
    output: &[f32],
    anchors: usize,
    cfg: &DecodeConfig,
    scratch: &mut DecodeScratch,
    out: &mut Vec<Detection, N>,
) -> Result<DecodeStats, DecodeError> {
    out.clear();
    if anchors > ANCHORS {
        return Err(DecodeError::TooManyAnchors(anchors));
    }
    let head = Head::of(output.len(), anchors).ok_or(DecodeError::BadLength {
        len: output.len(),
        anchors,
    })?;
    let rows = head.rows();
    let first_class = rows - NUM_CLASSES;
    let mut stats = DecodeStats::default();
    let at = |row: usize, a: usize| output[row * anchors + a];
    // Anchors with a non-finite value anywhere, found row by row (contiguous reads).
    let mut bad = [0u64; ANCHORS.div_ceil(64)];
    for row in output.chunks_exact(anchors.max(1)) {
        // The common case, a row with nothing to mark, in one vectorisable pass.
        if row.iter().fold(true, |ok, v| ok & v.is_finite()) {
            continue;
        }
        for (a, v) in row.iter().enumerate() {
            if !v.is_finite() {
                bad[a / 64] |= 1 << (a % 64);
            }
        }
    }
    // A logit above logit(conf) is a sigmoid above conf: the sigmoid is only taken for
    // candidates.
    let threshold = match head {
        Head::Boxes => cfg.conf,
        Head::Logits if cfg.conf <= 0.0 => f32::NEG_INFINITY,
        Head::Logits if cfg.conf >= 1.0 => f32::INFINITY,
        Head::Logits => libm::logf(cfg.conf / (1.0 - cfg.conf)),
    };
    let cands = &mut scratch.candidates;
    cands.clear();
    for a in 0..anchors {
        if bad[a / 64] & (1 << (a % 64)) != 0 {
            stats.non_finite += 1;
            continue;
        }
        let value = |c: usize| at(first_class + c, a);
        let mut push = |c: usize| {
            let v = value(c);
            if v > threshold {
                // Capacity is anchors × classes: cannot overflow.
                let _ = cands.push(Candidate {
                    score: match head {
                        Head::Boxes => v,
                        Head::Logits => sigmoid(v),
                    },
                    anchor: a as u16,
                    class: c as u8,
                });
            }
        };
        if cfg.multi_label {
            (0..NUM_CLASSES).for_each(&mut push);
        } else {
            // The sigmoid is monotonic: the best logit is the best score.
            let best = (1..NUM_CLASSES).fold(0, |b, c| if value(c) > value(b) { c } else { b });
            push(best);
        }
    }
    stats.candidates = cands.len();
    cands.sort_unstable_by(|x, y| {
        y.score
            .total_cmp(&x.score)
            .then(x.anchor.cmp(&y.anchor))
            .then(x.class.cmp(&y.class))
    });
    let bbox = |a: usize| -> [f32; 4] {
        match head {
            Head::Boxes => [at(0, a), at(1, a), at(2, a), at(3, a)],
            Head::Logits => {
                let side = |s: usize| expected_bin(|j| at(s * DFL_BINS + j, a));
                let (ax, ay, stride) = anchor_point(a);
                let (l, t, r, b) = (side(0), side(1), side(2), side(3));
                [
                    ax + (r - l) * 0.5 * stride,
                    ay + (b - t) * 0.5 * stride,
                    (l + r) * stride,
                    (t + b) * stride,
                ]
            }
        }
    };
    let limit = cfg.max_det.min(N);
    for cand in cands.iter() {
        let [cx, cy, w, h] = bbox(usize::from(cand.anchor));
        let det = Detection {
            class: ObjectClass::ALL[usize::from(cand.class)],
            score: cand.score,
            cx,
            cy,
            w,
            h,
        };
        let b = det.xyxy();
        let suppressed = out
            .iter()
            .any(|k| (cfg.agnostic || k.class == det.class) && iou(&k.xyxy(), &b) > cfg.iou);
        if suppressed {
            continue;
        }
        if out.len() >= limit {
            stats.dropped += 1;
            continue;
        }
        let _ = out.push(det);
    }
    Ok(stats)
}

#[cfg(test)]
mod test {
    use super::*;

    /// An output tensor with the given (anchor, box, scores) set and everything else 0.
    fn tensor(entries: &[(usize, [f32; 4], [f32; NUM_CLASSES])]) -> [f32; OUTPUT_LEN] {
        let mut t = [0.0; OUTPUT_LEN];
        for &(a, b, s) in entries {
            for k in 0..4 {
                t[k * ANCHORS + a] = b[k];
            }
            for c in 0..NUM_CLASSES {
                t[(4 + c) * ANCHORS + a] = s[c];
            }
        }
        t
    }

    #[test]
    fn anchors_of_a_64_by_384_input() {
        assert_eq!(ANCHORS, 504);
        assert_eq!(OUTPUT_LEN, 8 * 504);
    }

    #[test]
    fn iou_of_known_boxes() {
        assert_eq!(iou(&[0.0, 0.0, 2.0, 2.0], &[1.0, 1.0, 3.0, 3.0]), 1.0 / 7.0);
        assert_eq!(iou(&[0.0, 0.0, 1.0, 1.0], &[2.0, 2.0, 3.0, 3.0]), 0.0);
        assert_eq!(iou(&[0.0, 0.0, 0.0, 0.0], &[0.0, 0.0, 0.0, 0.0]), 0.0);
    }

    #[test]
    fn suppression_keeps_the_best_of_overlapping_boxes() {
        let t = tensor(&[
            (3, [100.0, 20.0, 20.0, 10.0], [0.9, 0.0, 0.0, 0.0]),
            (4, [101.0, 20.0, 20.0, 10.0], [0.8, 0.0, 0.0, 0.0]), // IoU 0.9 with anchor 3
            (9, [200.0, 30.0, 10.0, 10.0], [0.0, 0.0, 0.6, 0.0]),
            (11, [300.0, 30.0, 10.0, 10.0], [0.0, 0.2, 0.0, 0.0]), // below 0.25
        ]);
        let mut out: Vec<Detection, 8> = Vec::new();
        let mut scratch = DecodeScratch::new();
        let st = decode(&t, ANCHORS, &DecodeConfig::RUNTIME, &mut scratch, &mut out).unwrap();
        assert_eq!(st.candidates, 3);
        assert_eq!(out.len(), 2);
        assert_eq!(
            (out[0].class, out[0].score, out[0].cx),
            (ObjectClass::Chair, 0.9, 100.0)
        );
        assert_eq!((out[1].class, out[1].cx), (ObjectClass::Desk, 200.0));
    }

    #[test]
    fn class_aware_suppression_keeps_other_classes() {
        let t = tensor(&[
            (3, [100.0, 20.0, 20.0, 10.0], [0.9, 0.0, 0.0, 0.0]),
            (4, [100.0, 20.0, 20.0, 10.0], [0.0, 0.8, 0.0, 0.0]),
        ]);
        let mut out: Vec<Detection, 8> = Vec::new();
        let mut scratch = DecodeScratch::new();
        let mut cfg = DecodeConfig::RUNTIME;
        decode(&t, ANCHORS, &cfg, &mut scratch, &mut out).unwrap();
        assert_eq!(out.len(), 1, "agnostic: one object, one report");
        cfg.agnostic = false;
        decode(&t, ANCHORS, &cfg, &mut scratch, &mut out).unwrap();
        assert_eq!(out.len(), 2);
    }

    #[test]
    fn multi_label_gives_one_box_per_class_above_threshold() {
        let t = tensor(&[(7, [50.0, 10.0, 8.0, 8.0], [0.5, 0.4, 0.0005, 0.3])]);
        let mut out: Vec<Detection, 8> = Vec::new();
        let mut scratch = DecodeScratch::new();
        decode(
            &t,
            ANCHORS,
            &DecodeConfig::VALIDATION,
            &mut scratch,
            &mut out,
        )
        .unwrap();
        let classes: std::vec::Vec<_> = out.iter().map(|d| d.class).collect();
        assert_eq!(
            classes,
            [ObjectClass::Chair, ObjectClass::Box, ObjectClass::DoorFrame]
        );
    }

    #[test]
    fn capacity_and_max_det_bound_the_output() {
        let entries: std::vec::Vec<_> = (0..10)
            .map(|i| {
                (
                    i * 20,
                    [i as f32 * 30.0 + 10.0, 20.0, 10.0, 10.0],
                    [0.5 + i as f32 * 0.01, 0.0, 0.0, 0.0],
                )
            })
            .collect();
        let t = tensor(&entries);
        let mut out: Vec<Detection, 4> = Vec::new();
        let mut scratch = DecodeScratch::new();
        let st = decode(&t, ANCHORS, &DecodeConfig::RUNTIME, &mut scratch, &mut out).unwrap();
        assert_eq!(out.len(), 4);
        assert_eq!(st.dropped, 6);
        assert!(out.windows(2).all(|w| w[0].score >= w[1].score));
    }

    #[test]
    fn bad_tensors_are_errors_or_skipped() {
        let mut out: Vec<Detection, 4> = Vec::new();
        let mut scratch = DecodeScratch::new();
        let short = [0.0f32; 10];
        assert_eq!(
            decode(
                &short,
                ANCHORS,
                &DecodeConfig::RUNTIME,
                &mut scratch,
                &mut out
            ),
            Err(DecodeError::BadLength {
                len: 10,
                anchors: ANCHORS
            })
        );
        let big = [0.0f32; 8 * 600];
        assert_eq!(
            decode(&big, 600, &DecodeConfig::RUNTIME, &mut scratch, &mut out),
            Err(DecodeError::TooManyAnchors(600))
        );
        let mut t = tensor(&[(3, [100.0, 20.0, 20.0, 10.0], [0.9, 0.0, 0.0, 0.0])]);
        t[ANCHORS + 3] = f32::NAN;
        let st = decode(&t, ANCHORS, &DecodeConfig::RUNTIME, &mut scratch, &mut out).unwrap();
        assert_eq!((out.len(), st.non_finite), (0, 1));
    }

    /// A logits-head tensor: for each (anchor, side distances in strides, class logits), each
    /// side's bins put all their weight on the distance (split between two bins when it is
    /// a half); everything else is −100, which `expf` takes to 0 beside a bin at 0.
    fn logits(entries: &[(usize, [f32; 4], [f32; NUM_CLASSES])]) -> std::vec::Vec<f32> {
        let mut t = std::vec![-100.0f32; LOGITS_LEN];
        for &(a, sides, cls) in entries {
            for (s, d) in sides.iter().enumerate() {
                let j = *d as usize;
                t[(s * DFL_BINS + j) * ANCHORS + a] = 0.0;
                if d.fract() == 0.5 {
                    t[(s * DFL_BINS + j + 1) * ANCHORS + a] = 0.0;
                }
            }
            for (c, z) in cls.iter().enumerate() {
                t[(4 * DFL_BINS + c) * ANCHORS + a] = *z;
            }
        }
        t
    }

    #[test]
    fn the_logits_head_decodes_to_the_boxes_its_bins_say() {
        // Level 0 (stride 8), grid x 10, y 3: centre (84, 28). Sides l 2, t 1, r 3, b 1.5.
        let a0 = 3 * 48 + 10;
        // Level 2 (stride 32), grid x 5, y 1: centre (176, 48). Every side 1.
        let a2 = 8 * 48 + 4 * 24 + 12 + 5;
        let t = logits(&[
            (a0, [2.0, 1.0, 3.0, 1.5], [2.0, -5.0, -5.0, -5.0]),
            (a2, [1.0; 4], [-5.0, -5.0, 1.0, -5.0]),
        ]);
        let mut out: Vec<Detection, 8> = Vec::new();
        let mut scratch = DecodeScratch::new();
        let st = decode(&t, ANCHORS, &DecodeConfig::RUNTIME, &mut scratch, &mut out).unwrap();
        assert_eq!((st.candidates, out.len()), (2, 2));
        let chair = sigmoid(2.0);
        let near = |d: &Detection, want: [f32; 5]| {
            let got = [d.score, d.cx, d.cy, d.w, d.h];
            assert!(
                got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-4),
                "{got:?} vs {want:?}"
            );
        };
        assert_eq!(out[0].class, ObjectClass::Chair);
        near(&out[0], [chair, 88.0, 30.0, 40.0, 20.0]);
        assert_eq!(out[1].class, ObjectClass::Desk);
        near(&out[1], [sigmoid(1.0), 176.0, 48.0, 64.0, 64.0]);
        // The same boxes given in Ultralytics' form decode to the same detections.
        let boxes = tensor(&[
            (a0, [88.0, 30.0, 40.0, 20.0], [chair, 0.0, 0.0, 0.0]),
            (a2, [176.0, 48.0, 64.0, 64.0], [0.0, 0.0, out[1].score, 0.0]),
        ]);
        let mut same: Vec<Detection, 8> = Vec::new();
        decode(
            &boxes,
            ANCHORS,
            &DecodeConfig::RUNTIME,
            &mut scratch,
            &mut same,
        )
        .unwrap();
        for (x, y) in out.iter().zip(&same) {
            assert_eq!((x.class, x.score), (y.class, y.score));
            near(x, [y.score, y.cx, y.cy, y.w, y.h]);
        }
    }

    #[test]
    fn the_head_is_told_by_the_length() {
        assert_eq!(Head::of(OUTPUT_LEN, ANCHORS), Some(Head::Boxes));
        assert_eq!(Head::of(LOGITS_LEN, ANCHORS), Some(Head::Logits));
        assert_eq!(Head::of(8 * 100, 100), Some(Head::Boxes));
        assert_eq!(
            Head::of(LOGIT_ROWS * 100, 100),
            None,
            "logits need the 64 × 384 grid"
        );
        assert_eq!(Head::of(LOGITS_LEN - 1, ANCHORS), None);
        let mut out: Vec<Detection, 4> = Vec::new();
        let mut scratch = DecodeScratch::new();
        let mut t = logits(&[(7, [1.0; 4], [3.0, -5.0, -5.0, -5.0])]);
        decode(&t, ANCHORS, &DecodeConfig::RUNTIME, &mut scratch, &mut out).unwrap();
        assert_eq!(out.len(), 1);
        t[(2 * DFL_BINS + 5) * ANCHORS + 7] = f32::INFINITY;
        let st = decode(&t, ANCHORS, &DecodeConfig::RUNTIME, &mut scratch, &mut out).unwrap();
        assert_eq!(
            (out.len(), st.non_finite),
            (0, 1),
            "a non-finite bin skips the anchor"
        );
        let e = decode(
            &t[1..],
            ANCHORS,
            &DecodeConfig::RUNTIME,
            &mut scratch,
            &mut out,
        );
        assert!(matches!(e, Err(DecodeError::BadLength { .. })));
    }

    #[test]
    fn centre_in_the_map() {
        let cfg = RasterConfig::default();
        // Column 90.5 → bearing 90° (left); row 31.5 → 2.0 m.
        let d = Detection {
            class: ObjectClass::Box,
            score: 0.9,
            cx: 90.5,
            cy: 31.5,
            w: 10.0,
            h: 6.0,
        };
        let (r, b) = d.polar(&cfg);
        assert!((r - 2.0).abs() < 1e-5 && (b - core::f32::consts::FRAC_PI_2).abs() < 1e-5);
        let lidar = Pose2::new(1.0, 0.0, core::f32::consts::FRAC_PI_2);
        let c = d.centre(&lidar, &cfg);
        assert!((c.x - -1.0).abs() < 1e-4 && c.y.abs() < 1e-4, "{c:?}");
        // Bearings past 180° come out negative (REP 103 angles in (−π, π]).
        let back = Detection { cx: 270.5, ..d };
        assert!((back.polar(&cfg).1 + core::f32::consts::FRAC_PI_2).abs() < 1e-5);
    }
}
