//! Method B scored on a simulator dataset split: precision, recall, mAP50 and mAP50-95, the way
//! Ultralytics' `DetectionValidator` (8.4) computes them, so the two can be compared number for
//! number (`umbra-lab eval-b`, and a test against Ultralytics' own figures).
//!
//! Per image: the model's output decoded with Ultralytics' validation settings
//! ([`DecodeConfig::VALIDATION`]: conf 0.001, IoU 0.7, multi-label, 300 boxes), true boxes from
//! the YOLO label file scaled to 384 × 64 pixels. Matching ([`match_predictions`]):
//! detections in descending score order each take the unclaimed true box of their class with
//! the highest IoU, separately at each IoU threshold 0.50, 0.55 … 0.95. Then per class
//! (`ap_per_class`): the precision/recall curve over descending score, AP as COCO's 101-point
//! interpolation of the precision envelope, and P / R read at the score where the mean F1
//! over classes (box-smoothed over 1,000 score steps) is highest. Only classes with true boxes
//! in the split count.
//!
//! Next to our own ruler, the **study's ruler** ([`study_box`]): the study's label generator
//! pads every box to the object's bearing span plus 25 px and its row span plus 15 px (ours:
//! plus 5 and plus 3), so its mAP is measured on boxes 20 px wider and 12 px taller, which are
//! easier to overlap. Both our true boxes and the model's are widened that way (clamped to the image) and
//! scored again, so a figure can be set beside the study's like for like. The study also drew
//! boxes for objects hidden from the sensor; that part cannot be reproduced from our labels and
//! is not.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use models::yolo::YoloModel;
use perception::class::ObjectClass;
use perception::mirror_look::{FuseConfig, fuse_second_look, mirror_chw};
use perception::raster::{RASTER_C, RASTER_H, RASTER_LEN, RASTER_W};
use perception::yolo::{ANCHORS, DecodeConfig, DecodeScratch, Detection, decode};

/// Extra width and height, px, of the study's boxes over ours (its + 25 / + 15 against our
/// `sim::labels` padding: span + 1 + 2 × 2 columns, span + 1 + 2 × 1 rows).
pub const STUDY_EXTRA: [f64; 2] = [20.0, 12.0];

/// A box `[x0, y0, x1, y1]` widened to the study's label rule, clamped to the image.
pub fn study_box(b: [f64; 4]) -> [f64; 4] {
    let [dw, dh] = STUDY_EXTRA.map(|e| e / 2.0);
    [
        (b[0] - dw).max(0.0),
        (b[1] - dh).max(0.0),
        (b[2] + dw).min(RASTER_W as f64),
        (b[3] + dh).min(RASTER_H as f64),
    ]
}

/// A detection with its box widened by [`study_box`].
fn study_detection(d: &Detection) -> Detection {
    let [x0, y0, x1, y1] = study_box(xyxy(d)).map(|v| v as f32);
    Detection {
        cx: (x0 + x1) / 2.0,
        cy: (y0 + y1) / 2.0,
        w: x1 - x0,
        h: y1 - y0,
        ..*d
    }
}

/// A split scored with our ruler and with the study's.
#[derive(Debug, Clone, Default)]
pub struct Scored {
    /// Our tight boxes.
    pub ours: Stats,
    /// Both sides widened to the study's label rule ([`study_box`]).
    pub study: Stats,
}

/// The metrics as `--json` writes them: ours at the top level, the study's ruler beside.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Report {
    /// Our ruler.
    #[serde(flatten)]
    pub ours: Metrics,
    /// The study's ruler (boxes widened as its label generator does).
    pub study_rule: Metrics,
}

/// IoU thresholds of mAP50-95.
pub fn iou_thresholds() -> [f64; 10] {
    // torch.linspace(0.5, 0.95, 10) in f32, as Ultralytics computes them.
    core::array::from_fn(|i| f64::from(0.5f32 + (0.45f32 / 9.0) * i as f32))
}

/// A true box: class and `[x0, y0, x1, y1]` in pixels.
pub type TrueBox = (ObjectClass, [f64; 4]);

/// Ultralytics' `box_iou` (with its 1e-7 in the denominator).
fn box_iou(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let iw = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
    let ih = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
    let inter = iw * ih;
    let area = |r: &[f64; 4]| (r[2] - r[0]) * (r[3] - r[1]);
    inter / (area(a) + area(b) - inter + 1e-7)
}

fn xyxy(d: &Detection) -> [f64; 4] {
    d.xyxy().map(f64::from)
}

/// Which detections are correct at each IoU threshold (`preds` in descending score order).
pub fn match_predictions(truth: &[TrueBox], preds: &[Detection]) -> Vec<[bool; 10]> {
    let thr = iou_thresholds();
    let mut correct = vec![[false; 10]; preds.len()];
    if truth.is_empty() || preds.is_empty() {
        return correct;
    }
    let iou: Vec<Vec<f64>> = truth
        .iter()
        .map(|(c, b)| {
            preds
                .iter()
                .map(|p| {
                    if p.class == *c {
                        box_iou(b, &xyxy(p))
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    let mut matched = vec![[false; 10]; truth.len()];
    for (j, cor) in correct.iter_mut().enumerate() {
        if !iou.iter().any(|row| row[j] >= thr[0]) {
            continue;
        }
        for (t, &th) in thr.iter().enumerate() {
            // Best unclaimed true box (first on ties, like numpy's argmax).
            let mut best_k = 0;
            let mut best = f64::NEG_INFINITY;
            for (k, row) in iou.iter().enumerate() {
                let v = if matched[k][t] { 0.0 } else { row[j] };
                if v > best {
                    best = v;
                    best_k = k;
                }
            }
            cor[t] = best >= th;
            matched[best_k][t] |= cor[t];
        }
    }
    correct
}

/// Everything the metrics need, gathered image by image.
#[derive(Debug, Clone, Default)]
pub struct Stats {
    tp: Vec<[bool; 10]>,
    conf: Vec<f64>,
    pred_cls: Vec<usize>,
    target_cls: Vec<usize>,
    /// Images containing each class.
    images_with: [usize; 4],
    /// Images seen.
    pub images: usize,
}

impl Stats {
    /// Adds one image's true boxes and detections (descending score order).
    pub fn add_image(&mut self, truth: &[TrueBox], preds: &[Detection]) {
        self.images += 1;
        self.tp.extend(match_predictions(truth, preds));
        self.conf.extend(preds.iter().map(|p| f64::from(p.score)));
        self.pred_cls.extend(preds.iter().map(|p| p.class as usize));
        self.target_cls.extend(truth.iter().map(|t| t.0 as usize));
        for c in 0..4 {
            if truth.iter().any(|t| t.0 as usize == c) {
                self.images_with[c] += 1;
            }
        }
    }

    /// The metrics.
    pub fn metrics(&self) -> Metrics {
        ap_per_class(self)
    }
}

/// Metrics of one class.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ClassMetrics {
    /// Class name.
    pub class: &'static str,
    /// Images that contain it.
    pub images: usize,
    /// True boxes.
    pub instances: usize,
    /// Precision at the best-F1 score.
    pub p: f64,
    /// Recall at the best-F1 score.
    pub r: f64,
    /// AP at IoU 0.5.
    pub map50: f64,
    /// AP averaged over IoU 0.5…0.95.
    pub map50_95: f64,
}

/// Metrics of a split.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Metrics {
    /// Images.
    pub images: usize,
    /// Classes with true boxes.
    pub per_class: Vec<ClassMetrics>,
    /// Mean precision.
    pub p: f64,
    /// Mean recall.
    pub r: f64,
    /// Mean AP at 0.5.
    pub map50: f64,
    /// Mean AP at 0.5…0.95.
    pub map50_95: f64,
}

/// numpy's `interp(x, xp, fp)` for increasing `xp` (duplicates allowed), with `left` / `right`.
fn interp(x: f64, xp: &[f64], fp: &[f64], left: f64, right: f64) -> f64 {
    let n = xp.len();
    if n == 0 {
        return f64::NAN;
    }
    if x < xp[0] {
        return left;
    }
    if x > xp[n - 1] {
        return right;
    }
    if x == xp[n - 1] {
        return fp[n - 1];
    }
    // Largest j with xp[j] <= x (then xp[j + 1] > x).
    let j = xp.partition_point(|&v| v <= x) - 1;
    let slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]);
    let y = slope * (x - xp[j]) + fp[j];
    if y.is_nan() { fp[j] } else { y }
}

/// Ultralytics' `compute_ap`: 101-point interpolated area under the precision envelope.
fn compute_ap(recall: &[f64], precision: &[f64]) -> f64 {
    let mut mrec = Vec::with_capacity(recall.len() + 3);
    mrec.push(0.0);
    mrec.extend_from_slice(recall);
    mrec.push(recall.last().copied().unwrap_or(1.0));
    mrec.push(1.0);
    let mut mpre = Vec::with_capacity(precision.len() + 3);
    mpre.push(1.0);
    mpre.extend_from_slice(precision);
    mpre.extend([0.0, 0.0]);
    for i in (0..mpre.len() - 1).rev() {
        mpre[i] = mpre[i].max(mpre[i + 1]);
    }
    let y: Vec<f64> = (0..101)
        .map(|i| {
            interp(
                i as f64 / 100.0,
                &mrec,
                &mpre,
                mpre[0],
                mpre[mpre.len() - 1],
            )
        })
        .collect();
    y.windows(2).map(|w| (w[0] + w[1]) / 2.0 * 0.01).sum()
}

/// Ultralytics' `smooth`: box filter of width 2·round(n·f)/2 + 1, edges padded.
fn smooth(y: &[f64], f: f64) -> Vec<f64> {
    let nf = ((y.len() as f64 * f * 2.0).round() as usize) / 2 + 1;
    let pad = nf / 2;
    let mut yp = vec![y[0]; pad];
    yp.extend_from_slice(y);
    yp.extend(std::iter::repeat_n(y[y.len() - 1], pad));
    yp.windows(nf)
        .map(|w| w.iter().sum::<f64>() / nf as f64)
        .collect()
}

/// Ultralytics' `ap_per_class`.
fn ap_per_class(s: &Stats) -> Metrics {
    const EPS: f64 = 1e-16;
    let mut order: Vec<usize> = (0..s.conf.len()).collect();
    order.sort_by(|&a, &b| s.conf[b].total_cmp(&s.conf[a]));
    let conf: Vec<f64> = order.iter().map(|&i| s.conf[i]).collect();
    let x: Vec<f64> = (0..1000).map(|i| i as f64 / 999.0).collect();
    let classes: Vec<usize> = (0..4).filter(|c| s.target_cls.contains(c)).collect();
    let mut p_curve = vec![vec![0.0; 1000]; classes.len()];
    let mut r_curve = vec![vec![0.0; 1000]; classes.len()];
    let mut ap = vec![[0.0f64; 10]; classes.len()];
    for (ci, &c) in classes.iter().enumerate() {
        let n_l = s.target_cls.iter().filter(|&&t| t == c).count();
        let idx: Vec<usize> = (0..order.len())
            .filter(|&k| s.pred_cls[order[k]] == c)
            .collect();
        if idx.is_empty() {
            continue;
        }
        let neg_conf: Vec<f64> = idx.iter().map(|&k| -conf[k]).collect();
        let mut recall = vec![[0.0f64; 10]; idx.len()];
        let mut precision = vec![[0.0f64; 10]; idx.len()];
        let mut tpc = [0.0f64; 10];
        let mut fpc = [0.0f64; 10];
        for (n, &k) in idx.iter().enumerate() {
            let tp = &s.tp[order[k]];
            for t in 0..10 {
                if tp[t] {
                    tpc[t] += 1.0;
                } else {
                    fpc[t] += 1.0;
                }
                recall[n][t] = tpc[t] / (n_l as f64 + EPS);
                precision[n][t] = tpc[t] / (tpc[t] + fpc[t]);
            }
        }
        let r0: Vec<f64> = recall.iter().map(|r| r[0]).collect();
        let p0: Vec<f64> = precision.iter().map(|p| p[0]).collect();
        for (i, &xi) in x.iter().enumerate() {
            r_curve[ci][i] = interp(-xi, &neg_conf, &r0, 0.0, r0[r0.len() - 1]);
            p_curve[ci][i] = interp(-xi, &neg_conf, &p0, 1.0, p0[p0.len() - 1]);
        }
        for t in 0..10 {
            let rt: Vec<f64> = recall.iter().map(|r| r[t]).collect();
            let pt: Vec<f64> = precision.iter().map(|p| p[t]).collect();
            ap[ci][t] = compute_ap(&rt, &pt);
        }
    }
    let nc = classes.len();
    let (p, r) = if nc == 0 {
        (Vec::new(), Vec::new())
    } else {
        let f1_mean: Vec<f64> = (0..1000)
            .map(|i| {
                (0..nc)
                    .map(|ci| {
                        let (p, r) = (p_curve[ci][i], r_curve[ci][i]);
                        2.0 * p * r / (p + r + EPS)
                    })
                    .sum::<f64>()
                    / nc as f64
            })
            .collect();
        let sm = smooth(&f1_mean, 0.1);
        let mut best = 0;
        for (i, v) in sm.iter().enumerate() {
            if *v > sm[best] {
                best = i;
            }
        }
        (
            (0..nc).map(|ci| p_curve[ci][best]).collect(),
            (0..nc).map(|ci| r_curve[ci][best]).collect::<Vec<_>>(),
        )
    };
    let mean = |v: &[f64]| {
        if v.is_empty() {
            0.0
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let per_class: Vec<ClassMetrics> = classes
        .iter()
        .enumerate()
        .map(|(ci, &c)| ClassMetrics {
            class: ObjectClass::ALL[c].as_str(),
            images: s.images_with[c],
            instances: s.target_cls.iter().filter(|&&t| t == c).count(),
            p: p[ci],
            r: r[ci],
            map50: ap[ci][0],
            map50_95: mean(&ap[ci]),
        })
        .collect();
    let ap50: Vec<f64> = ap.iter().map(|a| a[0]).collect();
    let all: Vec<f64> = ap.iter().flat_map(|a| a.iter().copied()).collect();
    Metrics {
        images: s.images,
        p: mean(&p),
        r: mean(&r),
        map50: mean(&ap50),
        map50_95: mean(&all),
        per_class,
    }
}

/// Reads a YOLO label file into pixel boxes (a missing file is an image without objects).
pub fn read_labels(path: &Path) -> Result<Vec<TrueBox>, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let bad = || format!("{}:{}: not `class cx cy w h`", path.display(), n + 1);
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|t| t.parse::<f64>().map_err(|_| bad()))
            .collect::<Result<_, _>>()?;
        if v.len() != 5 || v[0] < 0.0 || v[0] >= 4.0 || v[0].fract() != 0.0 {
            return Err(bad());
        }
        // Ultralytics reads label files as float32.
        let f = |i: usize, scale: f64| f64::from(v[i] as f32) * scale;
        let (w, h) = (RASTER_W as f64, RASTER_H as f64);
        let (cx, cy, bw, bh) = (f(1, w), f(2, h), f(3, w), f(4, h));
        out.push((
            ObjectClass::ALL[v[0] as usize],
            [cx - bw / 2.0, cy - bh / 2.0, cx + bw / 2.0, cy + bh / 2.0],
        ));
    }
    Ok(out)
}

/// Reads a dataset PNG (384 × 64 RGB) into the model's input tensor (CHW, /255).
pub fn read_png_into(path: &Path, input: &mut [f32]) -> Result<(), String> {
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let file = std::fs::File::open(path).map_err(|e| err(&e))?;
    let mut dec = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| err(&e))?;
    let mut buf = vec![0u8; dec.output_buffer_size().unwrap_or(0)];
    let info = dec.next_frame(&mut buf).map_err(|e| err(&e))?;
    if info.width as usize != RASTER_W
        || info.height as usize != RASTER_H
        || info.color_type != png::ColorType::Rgb
        || info.bit_depth != png::BitDepth::Eight
        || input.len() != RASTER_LEN
    {
        return Err(err(&"not a 384 × 64 8-bit RGB raster"));
    }
    for y in 0..RASTER_H {
        for x in 0..RASTER_W {
            for c in 0..RASTER_C {
                input[(c * RASTER_H + y) * RASTER_W + x] =
                    f32::from(buf[(y * RASTER_W + x) * RASTER_C + c]) / 255.0;
            }
        }
    }
    Ok(())
}

/// The images of a split, in name order.
pub fn split_images(dataset: &Path, split: &str) -> Result<Vec<PathBuf>, String> {
    let dir = dataset.join("images").join(split);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "png"))
        .collect();
    v.sort();
    Ok(v)
}

/// Runs `model` over a split (with `mirror`, a second look at each image mirrored and fused:
/// `perception::mirror_look`) and gathers the statistics by both rulers; `progress` is called
/// per image.
pub fn evaluate(
    model: &mut YoloModel,
    dataset: &Path,
    split: &str,
    mirror: bool,
    mut progress: impl FnMut(usize, usize),
) -> Result<Scored, String> {
    let images = split_images(dataset, split)?;
    if images.is_empty() {
        return Err(format!("{}: no images in split {split}", dataset.display()));
    }
    let mut stats = Scored::default();
    let mut wide: Vec<Detection> = Vec::with_capacity(300);
    let mut wide_truth: Vec<TrueBox> = Vec::new();
    let mut scratch = DecodeScratch::new();
    let mut dets: heapless::Vec<Detection, 300> = heapless::Vec::new();
    let mut second: heapless::Vec<Detection, 300> = heapless::Vec::new();
    let mut fused: heapless::Vec<Detection, 300> = heapless::Vec::new();
    let fuse_cfg = FuseConfig::of(&DecodeConfig::VALIDATION);
    let cfg = if mirror {
        fuse_cfg.look_decode(&DecodeConfig::VALIDATION)
    } else {
        DecodeConfig::VALIDATION
    };
    for (n, img) in images.iter().enumerate() {
        read_png_into(img, model.input_mut())?;
        let label = dataset
            .join("labels")
            .join(split)
            .join(img.file_stem().unwrap_or_default())
            .with_extension("txt");
        let truth = read_labels(&label)?;
        look(model, &cfg, &mut scratch, &mut dets)?;
        if mirror {
            mirror_chw(model.input_mut()).map_err(|e| e.to_string())?;
            look(model, &cfg, &mut scratch, &mut second)?;
            fuse_second_look(&mut dets, &mut second, &fuse_cfg, &mut fused);
        }
        stats.ours.add_image(&truth, &dets);
        wide_truth.clear();
        wide_truth.extend(truth.iter().map(|&(c, b)| (c, study_box(b))));
        wide.clear();
        wide.extend(dets.iter().map(study_detection));
        stats.study.add_image(&wide_truth, &wide);
        progress(n + 1, images.len());
    }
    Ok(stats)
}

/// One run of `model` on its current input, decoded into `dets`.
fn look(
    model: &mut YoloModel,
    cfg: &DecodeConfig,
    scratch: &mut DecodeScratch,
    dets: &mut heapless::Vec<Detection, 300>,
) -> Result<(), String> {
    model
        .run(|out| decode(out, ANCHORS, cfg, scratch, dets))
        .map_err(|e| e.to_string())?
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// The metrics as Ultralytics prints them.
pub fn table(m: &Metrics) -> String {
    let mut s = format!(
        "{:>12} {:>7} {:>9} {:>7} {:>7} {:>7} {:>9}\n",
        "class", "images", "instances", "P", "R", "mAP50", "mAP50-95"
    );
    let all: usize = m.per_class.iter().map(|c| c.instances).sum();
    let _ = writeln!(
        s,
        "{:>12} {:>7} {:>9} {:>7.3} {:>7.3} {:>7.3} {:>9.3}",
        "all", m.images, all, m.p, m.r, m.map50, m.map50_95
    );
    for c in &m.per_class {
        let _ = writeln!(
            s,
            "{:>12} {:>7} {:>9} {:>7.3} {:>7.3} {:>7.3} {:>9.3}",
            c.class, c.images, c.instances, c.p, c.r, c.map50, c.map50_95
        );
    }
    s
}

#[cfg(test)]
mod test {
    use super::*;

    fn det(class: ObjectClass, score: f32, b: [f32; 4]) -> Detection {
        Detection {
            class,
            score,
            cx: (b[0] + b[2]) / 2.0,
            cy: (b[1] + b[3]) / 2.0,
            w: b[2] - b[0],
            h: b[3] - b[1],
        }
    }

    #[test]
    fn the_study_ruler_widens_and_clamps() {
        assert_eq!(
            study_box([100.0, 20.0, 110.0, 30.0]),
            [90.0, 14.0, 120.0, 36.0]
        );
        assert_eq!(study_box([2.0, 1.0, 380.0, 62.0]), [0.0, 0.0, 384.0, 64.0]);
        // A prediction off by 6 px on a 10-px box: IoU 0.25 by our ruler, 0.67 by the study's.
        let t = [100.0, 20.0, 110.0, 30.0];
        let p = det(ObjectClass::Chair, 0.9, [106.0, 20.0, 116.0, 30.0]);
        let ours = match_predictions(&[(ObjectClass::Chair, t)], core::slice::from_ref(&p));
        assert!(!ours[0][0]);
        let wide = match_predictions(
            &[(ObjectClass::Chair, study_box(t))],
            &[study_detection(&p)],
        );
        assert!(wide[0][0] && !wide[0][9]);
    }

    #[test]
    fn interp_matches_numpy() {
        let xp = [0.0, 0.5, 0.5, 1.0];
        let fp = [1.0, 0.8, 0.6, 0.0];
        assert_eq!(interp(-1.0, &xp, &fp, 9.0, 7.0), 9.0);
        assert_eq!(interp(2.0, &xp, &fp, 9.0, 7.0), 7.0);
        assert_eq!(interp(1.0, &xp, &fp, 9.0, 7.0), 0.0);
        assert!((interp(0.25, &xp, &fp, 9.0, 7.0) - 0.9).abs() < 1e-12);
        // On a duplicated xp numpy takes the right-hand value.
        assert_eq!(interp(0.5, &xp, &fp, 9.0, 7.0), 0.6);
        assert!((interp(0.75, &xp, &fp, 9.0, 7.0) - 0.3).abs() < 1e-12);
    }

    #[test]
    fn perfect_detections_score_one() {
        let mut s = Stats::default();
        for i in 0..5 {
            let b = [10.0 * i as f32, 5.0, 10.0 * i as f32 + 8.0, 20.0];
            let truth = [(ObjectClass::Box, b.map(f64::from))];
            s.add_image(&truth, &[det(ObjectClass::Box, 0.9, b)]);
        }
        let m = s.metrics();
        // 0.995, not 1: Ultralytics' envelope ends at precision 0 at recall 1, and the last
        // of the 101 trapezoids is half of it (its perfect score is 0.995 too).
        assert!(
            (m.map50 - 0.995).abs() < 1e-9 && (m.map50_95 - 0.995).abs() < 1e-9,
            "{m:?}"
        );
        assert!((m.p - 1.0).abs() < 1e-9 && (m.r - 1.0).abs() < 1e-9);
        assert_eq!(m.per_class.len(), 1);
    }

    #[test]
    fn misses_and_false_positives_lower_the_score() {
        let mut s = Stats::default();
        let b = [0.0, 0.0, 10.0, 10.0];
        let truth = [
            (ObjectClass::Chair, b.map(f64::from)),
            (ObjectClass::Chair, [50.0, 0.0, 60.0, 10.0]),
        ];
        // One right (IoU 1), one wrong class on the second, one stray.
        let preds = [
            det(ObjectClass::Chair, 0.9, b),
            det(ObjectClass::Desk, 0.8, [50.0, 0.0, 60.0, 10.0]),
            det(ObjectClass::Chair, 0.7, [200.0, 0.0, 210.0, 10.0]),
        ];
        s.add_image(&truth, &preds);
        let m = s.metrics();
        // Chair: P/R curve (1, 0.5), (0.5, 0.5): AP = 0.5 by 101-point interpolation
        // (51 points at precision 1 → trapezoid 0.5 − 0.005 + ...): checked against numpy.
        let chair = m.per_class[0];
        assert_eq!(chair.class, "chair");
        assert!((chair.map50 - 0.5).abs() < 0.01, "{chair:?}");
        assert_eq!(
            m.per_class.len(),
            1,
            "desk has no true boxes: not a class here"
        );
    }

    #[test]
    fn matching_is_per_threshold_and_one_to_one() {
        let truth = [(ObjectClass::Box, [0.0, 0.0, 10.0, 10.0])];
        // IoU 0.8 then IoU 1.0: the first (higher score) claims the box at 0.5..0.8, the
        // second at the thresholds the first fails.
        let preds = [
            det(ObjectClass::Box, 0.9, [0.0, 0.0, 10.0, 8.0]),
            det(ObjectClass::Box, 0.8, [0.0, 0.0, 10.0, 10.0]),
        ];
        let c = match_predictions(&truth, &preds);
        let thr = iou_thresholds();
        for t in 0..10 {
            assert_eq!(c[0][t], 0.8 >= thr[t] - 1e-6, "t {t}");
            assert_eq!(c[1][t], !c[0][t], "t {t}");
        }
    }

    #[test]
    fn labels_parse_and_reject() {
        let dir = std::env::temp_dir().join(format!("umbra-evalb-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.txt");
        std::fs::write(&p, "1 0.5 0.5 0.25 0.5\n").unwrap();
        let l = read_labels(&p).unwrap();
        assert_eq!(l, [(ObjectClass::Box, [144.0, 16.0, 240.0, 48.0])]);
        std::fs::write(&p, "7 0.5 0.5 0.25 0.5\n").unwrap();
        assert!(read_labels(&p).is_err());
        assert!(read_labels(&dir.join("none.txt")).unwrap().is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
