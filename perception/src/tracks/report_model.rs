//! The report model: a logistic model, fitted on labelled runs, of how likely a track that has
//! earned its report is a phantom, from the evidence it gathered ([`Tally`],
//! [`Track::report_features`]). A track it finds a phantom with at least
//! [`ReportModel::threshold`] is held back, as one below [`TrackConfig::min_likelihood`] is.
//!
//! One rule cannot do what the model does: a phantom's detections score lower than a piece's,
//! come from nearer, in fewer of the frames it was in view, from one method, with wider
//! outlines, and none of these alone tells them apart (`docs/world.md`, 41st session). The
//! weights come from `training/fit_report_model.py`, fitted on the tracks that
//! `umbra replay --track-log` writes on the simulator's tuning seeds; they are compiled in from
//! `models` like the scores' calibration, and belong to one Method B model and calibration.

use crate::class::ObjectClass;
use crate::fusion::Evidence;

use super::{Track, TrackConfig};

/// Features the model reads ([`Track::report_features`]).
pub const REPORT_FEATURES: usize = 31;

/// Names of the features, in order (the track log's header, the fitting script's columns).
pub const FEATURE_NAMES: [&str; REPORT_FEATURES] = [
    "chair",
    "box",
    "desk",
    "door",
    "seen_a",
    "seen_b",
    "seen_ab",
    "ln_hits",
    "rate",
    "likelihood",
    "p_max",
    "share_a",
    "share_b",
    "share_ab",
    "range_m",
    "score",
    "existence",
    "width_m",
    "ln_misses",
    "ln_empties",
    "miss_rate",
    "ln_wide",
    "ln_narrow",
    "ln_arc",
    "ln_flat",
    "ln_since",
    "view_span_m",
    "scatter_m",
    "born_on_free",
    "class_score",
    "ln_age",
];

/// What a track's observations and misses were, beyond its hits and likelihood.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tally {
    /// The most probable observation's probability.
    pub p_max: f32,
    /// Observations by source (A, B, AB).
    pub hits_by: [u16; 3],
    /// Sum of the observations' distances from the LiDAR, m.
    pub range_sum: f32,
    /// Sum of the observations' scores.
    pub score_sum: f32,
    /// Sum of the observations' squared distances from the centre they were added to, m².
    pub scatter_sum: f32,
    /// Frames it was missed in plain view.
    pub misses: u16,
    /// Frames its place was seen empty.
    pub empties: u16,
}

impl Tally {
    /// Notes an observation of probability `p` and score `score`, `range` m from the LiDAR
    /// and `offset` m from the track's centre.
    pub fn observe(&mut self, source: Evidence, p: f32, score: f32, range: f32, offset: f32) {
        let k = source as usize;
        self.p_max = self.p_max.max(p);
        self.hits_by[k] = self.hits_by[k].saturating_add(1);
        if range.is_finite() && offset.is_finite() {
            self.range_sum += range;
            self.scatter_sum += offset * offset;
        }
        self.score_sum += score.clamp(0.0, 1.0);
    }

    /// Notes a frame's negative evidence: `empty` its place seen empty, else a miss.
    pub fn unobserved(&mut self, empty: bool) {
        let n = if empty {
            &mut self.empties
        } else {
            &mut self.misses
        };
        *n = n.saturating_add(1);
    }

    /// Adds another track's tally (a merge).
    pub fn absorb(&mut self, other: &Tally) {
        self.p_max = self.p_max.max(other.p_max);
        for (v, x) in self.hits_by.iter_mut().zip(other.hits_by) {
            *v = v.saturating_add(x);
        }
        self.range_sum += other.range_sum;
        self.score_sum += other.score_sum;
        self.scatter_sum += other.scatter_sum;
        self.misses = self.misses.saturating_add(other.misses);
        self.empties = self.empties.saturating_add(other.empties);
    }
}

/// A logistic model over [`Track::report_features`]: weights on the raw features (the
/// fitting script folds its standardisation into them) and the threshold on the phantom
/// probability at which a track is held back.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ReportModel {
    /// One weight a feature.
    pub weights: [f32; REPORT_FEATURES],
    /// The intercept.
    pub bias: f32,
    /// Held back at this phantom probability or more (above 1: never).
    pub threshold: f32,
    /// Judged only while it has fewer hits than this: a piece seen in so many frames has
    /// outlived the phantoms the model learnt from (few of those last this long), and the
    /// pieces it would hold back there are ones a tour found long ago.
    pub max_hits: u32,
}

impl ReportModel {
    /// The probability that a track with these features is a phantom.
    pub fn phantom_probability(&self, features: &[f32; REPORT_FEATURES]) -> f32 {
        let mut z = self.bias;
        for (w, x) in self.weights.iter().zip(features) {
            if x.is_finite() {
                z += w * x;
            }
        }
        1.0 / (1.0 + libm::expf(-z.clamp(-30.0, 30.0)))
    }
}

/// `ln(1 + x)` of a count.
fn ln1p(x: f32) -> f32 {
    libm::log1pf(x.max(0.0))
}

impl Track {
    /// What the report model reads of the track in `frame` ([`FEATURE_NAMES`]).
    pub fn report_features(&self, frame: u64) -> [f32; REPORT_FEATURES] {
        let y = &self.tally;
        let hits = self.hits.max(1) as f32;
        let views = self.views.max(1) as f32;
        let mut f = [0.0; REPORT_FEATURES];
        f[self.class() as usize] = 1.0;
        f[4 + self.evidence() as usize] = 1.0;
        f[7] = ln1p(self.hits as f32);
        f[8] = self.hits as f32 / views;
        f[9] = self.likelihood();
        f[10] = y.p_max;
        for k in 0..3 {
            f[11 + k] = y.hits_by[k] as f32 / hits;
        }
        f[14] = y.range_sum / hits;
        f[15] = y.score_sum / hits;
        f[16] = self.existence;
        f[17] = self.width_m;
        f[18] = ln1p(y.misses as f32);
        f[19] = ln1p(y.empties as f32);
        f[20] = y.misses as f32 / views;
        f[21] = ln1p(self.box_wide_views as f32);
        f[22] = ln1p(self.narrow_views as f32);
        f[23] = ln1p(self.arc_views as f32);
        f[24] = ln1p(self.flat_views as f32);
        f[25] = ln1p(frame.saturating_sub(self.last_seen) as f32);
        f[26] = self.view_span;
        f[27] = libm::sqrtf(y.scatter_sum / hits);
        f[28] = f32::from(u8::from(self.born_on_free));
        f[29] = self.class_score();
        f[30] = ln1p(frame.saturating_sub(self.first_seen) as f32);
        f
    }

    /// Whether the track, though it earned its report, is not reported in `frame`: seen only
    /// in the ways the methods are mostly wrong ([`Track::unlikely`]), or a phantom by the
    /// report model ([`TrackConfig::report_model`]). Door frames are judged by the map's
    /// walls instead, as by [`Track::unlikely`].
    pub fn held_back(&self, frame: u64, cfg: &TrackConfig) -> bool {
        if self.unlikely(cfg) {
            return true;
        }
        match &cfg.report_model {
            Some(m) if self.class() != ObjectClass::DoorFrame && self.hits < m.max_hits => {
                m.phantom_probability(&self.report_features(frame)) >= m.threshold
            }
            _ => false,
        }
    }
}
