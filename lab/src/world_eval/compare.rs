//! `umbra-lab compare`: how far apart two `eval-world --json` results are, and whether that is
//! more than the runs' own scatter.
//!
//! Each figure of the world evaluation is a ratio of sums over runs (phantoms over frames,
//! pieces found over pieces visible, …), and a few long-lived tracks make most of a family's
//! phantoms, so two settings' figures can differ by a run or two. The interval here is a
//! paired bootstrap over runs: the same runs (same seeds, same scenes) drawn with replacement
//! for both settings at once, the figure's difference recomputed each time, its 2.5th and
//! 97.5th percentiles reported. A difference whose interval holds 0 is within the runs' noise.
//! (Hand-rolled: a percentile bootstrap of a ratio of sums is a dozen lines, and no crate on
//! the list does it.)

use std::fmt::Write as _;
use std::path::PathBuf;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::score::Tally;

/// One family × world setting read back from an `eval-world --json` file.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct RunSet {
    /// Family name as the evaluator writes it.
    pub family: String,
    /// World model on.
    pub world: bool,
    /// Per run: its name and its own tally.
    pub runs: Vec<(String, Tally)>,
}

/// A figure of the world evaluation: a ratio of two sums over runs.
pub struct Figure {
    /// Name in the report.
    pub name: &'static str,
    /// A run's numerator and denominator.
    pub parts: fn(&Tally) -> (f64, f64),
    /// Whether a fall is a gain (phantoms) or a loss (recall).
    pub lower_is_better: bool,
}

/// The figures compared, in report order.
pub const FIGURES: [Figure; 7] = [
    Figure {
        name: "phantoms per frame",
        parts: |t| (sum(&t.phantoms), f64::from(t.frames)),
        lower_is_better: true,
    },
    Figure {
        name: "phantom objects per run",
        parts: |t| (f64::from(t.phantom_objects), f64::from(t.runs)),
        lower_is_better: true,
    },
    Figure {
        name: "recall (final map)",
        parts: |t| (sum(&t.map_tp), sum(&t.map_visible)),
        lower_is_better: false,
    },
    Figure {
        name: "precision (final map)",
        parts: |t| (sum(&t.map_tp), sum(&t.map_reported)),
        lower_is_better: false,
    },
    Figure {
        name: "IDF1",
        parts: |t| (2.0 * f64::from(t.idtp), f64::from(t.id_gt + t.id_hyp)),
        lower_is_better: false,
    },
    Figure {
        name: "doors found",
        parts: |t| (f64::from(t.doors[0]), f64::from(t.doors[2])),
        lower_is_better: false,
    },
    Figure {
        name: "people as furniture per frame",
        parts: |t| (f64::from(t.people_as_furniture), f64::from(t.frames)),
        lower_is_better: true,
    },
];

fn sum(a: &[u32]) -> f64 {
    a.iter().map(|&n| f64::from(n)).sum()
}

/// What a difference's interval says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Every run scored the same under both.
    Same,
    /// The interval holds 0.
    WithinNoise,
    /// The interval lies wholly on the good side.
    Better,
    /// The interval lies wholly on the bad side.
    Worse,
}

impl Verdict {
    /// Name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Same => "same",
            Verdict::WithinNoise => "within noise",
            Verdict::Better => "better",
            Verdict::Worse => "worse",
        }
    }
}

/// One figure of one family: both settings' values and the difference's interval.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Family name.
    pub family: String,
    /// Figure name.
    pub figure: &'static str,
    /// Runs paired.
    pub runs: usize,
    /// The base setting's figure over all runs.
    pub base: f64,
    /// The other setting's figure over all runs (NaN when only the base was given).
    pub with: f64,
    /// 2.5th and 97.5th percentiles of the bootstrapped difference (with − base), or of the
    /// base's own figure when only the base was given.
    pub interval: (f64, f64),
    /// What the interval says (`Same` when only the base was given).
    pub verdict: Verdict,
}

/// Reads `eval-world --json` files and joins each family × world setting's runs in file order.
pub fn load(files: &[PathBuf]) -> Result<Vec<RunSet>, String> {
    let mut sets: Vec<RunSet> = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
        let read: Vec<RunSet> = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not an eval-world --json file: {e}", f.display()))?;
        for r in read {
            match sets
                .iter_mut()
                .find(|s| s.family == r.family && s.world == r.world)
            {
                Some(s) => s.runs.extend(r.runs),
                None => sets.push(r),
            }
        }
    }
    Ok(sets)
}

/// A figure over the runs `idx` (with repeats) of `parts` (one row of parts per run).
fn figure_at(parts: &[(f64, f64)], idx: &[usize]) -> f64 {
    let (n, d) = idx
        .iter()
        .fold((0.0, 0.0), |(n, d), &i| (n + parts[i].0, d + parts[i].1));
    if d == 0.0 { f64::NAN } else { n / d }
}

/// The 2.5th and 97.5th percentiles of `v` (NaNs left out; NaN when none is left).
fn percentiles(mut v: Vec<f64>) -> (f64, f64) {
    v.retain(|x| !x.is_nan());
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((q * v.len() as f64) as usize).min(v.len() - 1)];
    (at(0.025), at(0.975))
}

/// Compares `with` against `base`, family by family (paired run by run, so both must be the
/// same seeds' runs in the same order), or, with `with` empty, gives each of the base's
/// figures its own interval. `resamples` bootstrap draws from a generator seeded with `seed`.
pub fn compare(
    base: &[RunSet],
    with: &[RunSet],
    resamples: usize,
    seed: u64,
) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    for b in base {
        let other = if with.is_empty() {
            None
        } else {
            let w = with
                .iter()
                .find(|w| w.family == b.family && w.world == b.world)
                .ok_or_else(|| format!("{}: not in the second set", b.family))?;
            if w.runs.len() != b.runs.len() {
                return Err(format!(
                    "{}: {} runs against {}: compare runs of the same seeds",
                    b.family,
                    b.runs.len(),
                    w.runs.len()
                ));
            }
            if let Some((i, (x, y))) = b
                .runs
                .iter()
                .zip(&w.runs)
                .enumerate()
                .find(|(_, (x, y))| x.0 != y.0)
            {
                return Err(format!(
                    "{}: run {i} is \"{}\" in one and \"{}\" in the other: compare runs of the same seeds, in the same order",
                    b.family, x.0, y.0
                ));
            }
            Some(w)
        };
        let n = b.runs.len();
        let all: Vec<usize> = (0..n).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let draws: Vec<Vec<usize>> = (0..resamples)
            .map(|_| (0..n).map(|_| rng.random_range(0..n)).collect())
            .collect();
        for fig in &FIGURES {
            let pb: Vec<(f64, f64)> = b.runs.iter().map(|(_, t)| (fig.parts)(t)).collect();
            let base_value = figure_at(&pb, &all);
            let (with_value, interval, verdict) = match other {
                None => (
                    f64::NAN,
                    percentiles(draws.iter().map(|d| figure_at(&pb, d)).collect()),
                    Verdict::Same,
                ),
                Some(w) => {
                    let pw: Vec<(f64, f64)> = w.runs.iter().map(|(_, t)| (fig.parts)(t)).collect();
                    let (lo, hi) = percentiles(
                        draws
                            .iter()
                            .map(|d| figure_at(&pw, d) - figure_at(&pb, d))
                            .collect(),
                    );
                    // Which side of 0 is the good one depends on the figure.
                    let (good, bad) = if fig.lower_is_better {
                        (hi < 0.0, lo > 0.0)
                    } else {
                        (lo > 0.0, hi < 0.0)
                    };
                    let verdict = if pb == pw {
                        Verdict::Same
                    } else if good {
                        Verdict::Better
                    } else if bad {
                        Verdict::Worse
                    } else {
                        Verdict::WithinNoise
                    };
                    (figure_at(&pw, &all), (lo, hi), verdict)
                }
            };
            let row = Row {
                family: b.family.clone(),
                figure: fig.name,
                runs: n,
                base: base_value,
                with: with_value,
                interval,
                verdict,
            };
            rows.push(row);
        }
    }
    Ok(rows)
}

/// `umbra-lab compare`: reads both sets of files (one `with` file for each base file, or none)
/// and returns the Markdown table.
pub fn files(
    base: &[PathBuf],
    with: &[PathBuf],
    resamples: usize,
    seed: u64,
) -> Result<String, String> {
    if !with.is_empty() && with.len() != base.len() {
        return Err(format!(
            "{} base files and {} --with files: give one for each",
            base.len(),
            with.len()
        ));
    }
    Ok(report(&compare(
        &load(base)?,
        &load(with)?,
        resamples,
        seed,
    )?))
}

/// The rows as a Markdown table.
pub fn report(rows: &[Row]) -> String {
    let mut s = String::new();
    let paired = rows.iter().any(|r| !r.with.is_nan());
    if paired {
        let _ = writeln!(
            s,
            "| family | runs | figure | base | with | with − base | 95 % interval | verdict |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
        for r in rows {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.3} | {:.3} | {:+.3} | {:+.3} … {:+.3} | {} |",
                r.family,
                r.runs,
                r.figure,
                r.base,
                r.with,
                r.with - r.base,
                r.interval.0,
                r.interval.1,
                r.verdict.name()
            );
        }
    } else {
        let _ = writeln!(s, "| family | runs | figure | value | 95 % interval |");
        let _ = writeln!(s, "|---|---|---|---|---|");
        for r in rows {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.3} | {:.3} … {:.3} |",
                r.family, r.runs, r.figure, r.base, r.interval.0, r.interval.1
            );
        }
    }
    s
}

#[cfg(test)]
mod test {
    use super::*;

    fn run(name: &str, phantoms: u32, found: u32) -> (String, Tally) {
        (
            name.to_string(),
            Tally {
                runs: 1,
                frames: 10,
                phantoms: [phantoms, 0, 0],
                map_tp: [found, 0, 0],
                map_visible: [4, 0, 0],
                map_reported: [4, 0, 0],
                ..Tally::default()
            },
        )
    }

    fn set(runs: Vec<(String, Tally)>) -> Vec<RunSet> {
        vec![RunSet {
            family: "sim".into(),
            world: true,
            runs,
        }]
    }

    fn row<'a>(rows: &'a [Row], figure: &str) -> &'a Row {
        rows.iter().find(|r| r.figure == figure).unwrap()
    }

    #[test]
    fn identical_runs_are_the_same() {
        let a = set(vec![run("0", 3, 4), run("1", 5, 2)]);
        let rows = compare(&a, &a, 200, 1).unwrap();
        let r = row(&rows, "phantoms per frame");
        assert_eq!(r.base, 0.4);
        assert_eq!(r.with, 0.4);
        assert_eq!(r.interval, (0.0, 0.0));
        assert_eq!(r.verdict, Verdict::Same);
    }

    #[test]
    fn more_phantoms_in_every_run_is_worse_and_a_lower_recall_too() {
        // Each run: one phantom more in 10 frames (+0.1 a frame whatever the draw), and one
        // piece fewer of 4 (−0.25 whatever the draw).
        let a = set(vec![run("0", 0, 4), run("1", 2, 3), run("2", 4, 4)]);
        let b = set(vec![run("0", 1, 3), run("1", 3, 2), run("2", 5, 3)]);
        let rows = compare(&a, &b, 500, 7).unwrap();
        let p = row(&rows, "phantoms per frame");
        assert!((p.with - p.base - 0.1).abs() < 1e-12);
        assert!((p.interval.0 - 0.1).abs() < 1e-12 && (p.interval.1 - 0.1).abs() < 1e-12);
        assert_eq!(p.verdict, Verdict::Worse);
        let r = row(&rows, "recall (final map)");
        assert!((r.with - r.base + 0.25).abs() < 1e-12);
        assert_eq!(r.verdict, Verdict::Worse);
        // And the other way round, both are better.
        let rows = compare(&b, &a, 500, 7).unwrap();
        assert_eq!(row(&rows, "phantoms per frame").verdict, Verdict::Better);
        assert_eq!(row(&rows, "recall (final map)").verdict, Verdict::Better);
    }

    #[test]
    fn one_run_going_each_way_is_within_noise() {
        // Run 0 gains 5 phantoms, run 1 loses 5: the draws that repeat one run go either way.
        let a = set(vec![run("0", 0, 4), run("1", 5, 4), run("2", 2, 4)]);
        let b = set(vec![run("0", 5, 4), run("1", 0, 4), run("2", 2, 4)]);
        let rows = compare(&a, &b, 2000, 3).unwrap();
        let p = row(&rows, "phantoms per frame");
        assert_eq!(p.with - p.base, 0.0);
        assert!(p.interval.0 < 0.0 && p.interval.1 > 0.0, "{:?}", p.interval);
        assert_eq!(p.verdict, Verdict::WithinNoise);
        // Seeded: the same draws give the same interval.
        let again = compare(&a, &b, 2000, 3).unwrap();
        assert_eq!(row(&again, "phantoms per frame"), p);
    }

    #[test]
    fn a_figure_alone_gets_its_own_interval() {
        // 0 and 1 phantoms a frame over two runs of 10 frames: the draws are both runs
        // twice (0 or 1) or one of each (0.5).
        let a = set(vec![run("0", 0, 4), run("1", 10, 4)]);
        let rows = compare(&a, &[], 400, 5).unwrap();
        let p = row(&rows, "phantoms per frame");
        assert_eq!(p.base, 0.5);
        assert!(p.with.is_nan());
        assert_eq!(p.interval, (0.0, 1.0));
        assert!(report(&rows).contains("| sim | 2 | phantoms per frame | 0.500 | 0.000 … 1.000 |"));
    }

    #[test]
    fn runs_of_other_seeds_are_refused() {
        let a = set(vec![run("sim 0: rect", 0, 4)]);
        let b = set(vec![run("sim 0: lshape", 0, 4)]);
        let e = compare(&a, &b, 10, 1).unwrap_err();
        assert!(e.contains("same seeds"), "{e}");
        let c = set(vec![run("sim 0: rect", 0, 4), run("sim 1: rect", 0, 4)]);
        assert!(
            compare(&a, &c, 10, 1)
                .unwrap_err()
                .contains("1 runs against 2")
        );
    }
}
