//! What the detections' scores mean: counts of detections by source, class and tenth of the
//! score, and how many stood on a piece of their class (`Tally::reliability`), laid out as
//! `perception::calibration::Calibration::fit` reads them.

use perception::class::ObjectClass;

/// Score bins of `Tally::reliability`: the calibration's tenths.
pub const SCORE_BINS: usize = perception::calibration::SCORE_BINS;

/// Length of `Tally::reliability`: 3 sources × 4 classes × [`SCORE_BINS`] × `[n, true]`,
/// the layout `perception::calibration::Calibration::fit` reads.
pub const RELIABILITY_LEN: usize = perception::calibration::COUNTS_LEN;

/// Where a detection of `source` and `class` with `score` is counted in
/// `Tally::reliability` (its `n`; `true` follows); None for a score that is not a number.
pub fn reliability_index(source: usize, class: ObjectClass, score: f32) -> Option<usize> {
    if !score.is_finite() {
        return None;
    }
    let bin = ((score.clamp(0.0, 1.0) * SCORE_BINS as f32) as usize).min(SCORE_BINS - 1);
    Some(perception::calibration::count_index(
        source.min(2),
        class as usize,
        bin,
    ))
}

/// Counts a detection of `source`, `class` and `score` into `counts` (grown to
/// [`RELIABILITY_LEN`] at its first), `right` when it stood on a piece of its class; a score
/// that is not a number is not counted.
pub fn count(counts: &mut Vec<u32>, source: usize, class: ObjectClass, score: f32, right: bool) {
    if let Some(k) = reliability_index(source, class, score) {
        if counts.len() < RELIABILITY_LEN {
            counts.resize(RELIABILITY_LEN, 0);
        }
        counts[k] += 1;
        counts[k + 1] += u32::from(right);
    }
}
