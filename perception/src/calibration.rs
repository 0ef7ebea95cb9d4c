//! What a detection's score means: the measured probability that a detection of its source
//! (A, B, AB), class and score stands on a piece of that class (a door frame: on a door).
//! The methods' own scores are not probabilities — Method A's forest calls a piece of wall a
//! desk at 0.7 and is right one time in twenty, Method B's boxes at 0.3 are right one time in
//! three, and what both methods agree on is right at any score — so the world model weighs
//! each observation by this instead. Fitted from counts ([`Calibration::fit`]: tenths of the
//! score, a uniform prior, made non-decreasing in the score by pooling adjacent violators);
//! read by piecewise-linear interpolation between the tenths' middles. `no_std`, fixed size.

use crate::class::ObjectClass;
use crate::fusion::Evidence;

/// Score bins: tenths.
pub const SCORE_BINS: usize = 10;

/// Sources × classes × bins × `[n, true]`: the length of the counts [`Calibration::fit`]
/// reads (source A, B, AB; classes in [`ObjectClass::ALL`] order).
pub const COUNTS_LEN: usize = 3 * 4 * SCORE_BINS * 2;

/// Where the `n` of source `source` (0 = A, 1 = B, 2 = AB), class index `class` and score
/// tenth `bin` lies in the counts [`Calibration::fit`] reads; its `true` count follows.
pub const fn count_index(source: usize, class: usize, bin: usize) -> usize {
    ((source * 4 + class) * SCORE_BINS + bin) * 2
}

/// Detections a (source, class) needs before its scores are recalibrated at all; with fewer
/// its scores are taken as they are.
pub const MIN_DETECTIONS: u32 = 20;

/// A score → probability map per source and class.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Calibration {
    /// Probability at each tenth's middle; `None`: too few detections, the score stands.
    p: [[Option<[f32; SCORE_BINS]>; 4]; 3],
}

/// Index of a source.
fn source_index(e: Evidence) -> usize {
    match e {
        Evidence::A => 0,
        Evidence::B => 1,
        Evidence::AB => 2,
    }
}

impl Calibration {
    /// Every score taken as it is.
    pub const IDENTITY: Calibration = Calibration { p: [[None; 4]; 3] };

    /// From counts laid out as [`COUNTS_LEN`] says (`[n, true]` per bin, in the order of
    /// sources, then classes, then bins); a slice of another length gives [`Self::IDENTITY`].
    pub fn fit(counts: &[u32]) -> Calibration {
        let mut c = Calibration::IDENTITY;
        if counts.len() != COUNTS_LEN {
            return c;
        }
        for (s, row) in c.p.iter_mut().enumerate() {
            for (k, slot) in row.iter_mut().enumerate() {
                let at = |b: usize| count_index(s, k, b);
                let total: u32 = (0..SCORE_BINS).map(|b| counts[at(b)]).sum();
                if total < MIN_DETECTIONS {
                    continue;
                }
                // Each bin with detections, with a uniform prior (one true, one false);
                // bins without any take their neighbours' rates.
                let mut rate = [0.0f32; SCORE_BINS];
                let mut weight = [0.0f32; SCORE_BINS];
                for b in 0..SCORE_BINS {
                    let (n, t) = (counts[at(b)], counts[at(b) + 1].min(counts[at(b)]));
                    rate[b] = (t as f32 + 1.0) / (n as f32 + 2.0);
                    weight[b] = n as f32;
                }
                *slot = Some(pool_adjacent_violators(rate, weight));
            }
        }
        c
    }

    /// The probability for a detection of `source`, `class` and `score` (a score that is not
    /// a number stays so; the world model refuses it).
    pub fn probability(&self, source: Evidence, class: ObjectClass, score: f32) -> f32 {
        let Some(p) = self.p[source_index(source)][class as usize] else {
            return score;
        };
        if !score.is_finite() {
            return score;
        }
        // Bin b's middle is (b + ½) / 10.
        let x = score.clamp(0.0, 1.0) * SCORE_BINS as f32 - 0.5;
        if x <= 0.0 {
            return p[0];
        }
        let b = (x as usize).min(SCORE_BINS - 1);
        if b + 1 >= SCORE_BINS {
            return p[SCORE_BINS - 1];
        }
        let f = x - b as f32;
        p[b] + (p[b + 1] - p[b]) * f
    }
}

/// The non-decreasing sequence nearest `rate` in the weighted least-squares sense over the
/// bins of positive weight; a bin of weight 0 is interpolated between its neighbours (held
/// flat past the last one). All weights 0: ½ everywhere.
fn pool_adjacent_violators(
    rate: [f32; SCORE_BINS],
    weight: [f32; SCORE_BINS],
) -> [f32; SCORE_BINS] {
    // Blocks as (value, weight, bins of positive weight); merged while a block is above the
    // next.
    let mut value = [0.0f32; SCORE_BINS];
    let mut w = [0.0f32; SCORE_BINS];
    let mut len = [0usize; SCORE_BINS];
    let mut blocks = 0;
    for b in (0..SCORE_BINS).filter(|&b| weight[b] > 0.0) {
        value[blocks] = rate[b];
        w[blocks] = weight[b];
        len[blocks] = 1;
        blocks += 1;
        while blocks >= 2 && value[blocks - 2] > value[blocks - 1] {
            let (v1, w1, v2, w2) = (
                value[blocks - 2],
                w[blocks - 2],
                value[blocks - 1],
                w[blocks - 1],
            );
            value[blocks - 2] = (v1 * w1 + v2 * w2) / (w1 + w2);
            w[blocks - 2] = w1 + w2;
            len[blocks - 2] += len[blocks - 1];
            blocks -= 1;
        }
    }
    let mut out = [0.5f32; SCORE_BINS];
    let mut known = [false; SCORE_BINS];
    let mut bins = (0..SCORE_BINS).filter(|&b| weight[b] > 0.0);
    for k in 0..blocks {
        for _ in 0..len[k] {
            if let Some(b) = bins.next() {
                out[b] = value[k];
                known[b] = true;
            }
        }
    }
    // Fill the empty bins.
    for b in 0..SCORE_BINS {
        if known[b] {
            continue;
        }
        let below = (0..b).rev().find(|&i| known[i]);
        let above = (b + 1..SCORE_BINS).find(|&i| known[i]);
        out[b] = match (below, above) {
            (Some(i), Some(j)) => out[i] + (out[j] - out[i]) * (b - i) as f32 / (j - i) as f32,
            (Some(i), None) => out[i],
            (None, Some(j)) => out[j],
            (None, None) => 0.5,
        };
    }
    out
}

#[cfg(test)]
mod test {
    use super::*;

    fn counts(set: &[(usize, usize, usize, u32, u32)]) -> [u32; COUNTS_LEN] {
        let mut c = [0u32; COUNTS_LEN];
        for &(s, k, b, n, t) in set {
            let at = count_index(s, k, b);
            c[at] = n;
            c[at + 1] = t;
        }
        c
    }

    #[test]
    fn a_score_becomes_how_often_it_came_true() {
        // Method A's desks (source 0, class 2): 5 of 100 right at 0.7, 10 of 100 at 0.8.
        let c = Calibration::fit(&counts(&[(0, 2, 7, 100, 5), (0, 2, 8, 100, 10)]));
        let p = c.probability(Evidence::A, ObjectClass::Desk, 0.75);
        assert!((p - 6.0 / 102.0).abs() < 1e-4, "{p}");
        let p = c.probability(Evidence::A, ObjectClass::Desk, 0.85);
        assert!((p - 11.0 / 102.0).abs() < 1e-4, "{p}");
        // Between the middles: interpolated.
        let mid = c.probability(Evidence::A, ObjectClass::Desk, 0.8);
        assert!(mid > 6.0 / 102.0 && mid < 11.0 / 102.0);
        // Classes and sources without data keep their scores.
        assert_eq!(c.probability(Evidence::B, ObjectClass::Desk, 0.42), 0.42);
        assert_eq!(c.probability(Evidence::A, ObjectClass::Chair, 0.42), 0.42);
        assert!(
            c.probability(Evidence::A, ObjectClass::Desk, f32::NAN)
                .is_nan()
        );
    }

    #[test]
    fn higher_scores_never_mean_less() {
        // A dip in the middle bin is pooled with its neighbour.
        let c = Calibration::fit(&counts(&[
            (1, 1, 3, 50, 20),
            (1, 1, 4, 50, 10),
            (1, 1, 5, 50, 40),
        ]));
        let mut last = 0.0;
        for k in 0..=100 {
            let p = c.probability(Evidence::B, ObjectClass::Box, k as f32 / 100.0);
            assert!(p >= last - 1e-6, "{k}: {p} < {last}");
            assert!((0.0..=1.0).contains(&p));
            last = p;
        }
        let pooled = c.probability(Evidence::B, ObjectClass::Box, 0.35);
        assert!((pooled - c.probability(Evidence::B, ObjectClass::Box, 0.45)).abs() < 1e-6);
    }

    #[test]
    fn too_few_or_misshapen_counts_change_nothing() {
        let c = Calibration::fit(&counts(&[(2, 0, 9, 5, 5)]));
        assert_eq!(c, Calibration::IDENTITY);
        assert_eq!(Calibration::fit(&[1, 2, 3]), Calibration::IDENTITY);
        assert_eq!(
            Calibration::IDENTITY.probability(Evidence::AB, ObjectClass::Chair, 0.3),
            0.3
        );
    }
}
