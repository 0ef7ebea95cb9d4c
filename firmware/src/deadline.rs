//! Deadlines: per-stage timing histograms, the stage budgets, the overrun policy, and the
//! deadline table of `docs/interfaces.md` §4.
//!
//! Every stage of every frame is timed with the monotonic clock into a fixed-bucket histogram
//! ([`Histogram`]: log-spaced, 40 buckets a decade from 1 µs to 10 s, so a percentile is
//! known to within 6 %, plus the exact maximum). Nothing here allocates after start-up.
//!
//! The overrun policy ([`Policy`]), in the order the runtime applies it:
//! 1. **Skip Method B** when the time left in the frame is less than Method B's expected time
//!    (the larger of its last time and its decaying average; a skipped frame lowers both, so
//!    Method B is tried again after a hiccup), and **decimate** it (every other frame) while
//!    the loop is behind the LiDAR.
//! 2. **Shrink the cloud's work** when Method A overran its own budget on the previous frame:
//!    the cloud ages [`SHRINK_DROP_FRACTION`] of its points instead of the configured share, so
//!    clustering sees fewer.
//! 3. Only then **miss**: a frame whose total is over the deadline is counted as missed.
//!
//! Degraded frames (1 or 2 applied) and misses are counted and flagged in the output line.

use std::fmt::Write as _;

/// The stages of a frame, in the order they run (`Total` is the frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Decoding the revolution's bytes.
    Ingest,
    /// Odometry, compass, pose at the first and last ray.
    Pose,
    /// Method A (cloud, clustering, walls, doors, forest).
    MethodA,
    /// Method B (raster, network, decode).
    MethodB,
    /// Writing the output line.
    Output,
    /// The whole frame.
    Total,
}

impl Stage {
    /// All stages, in table order.
    pub const ALL: [Stage; 6] = [
        Stage::Ingest,
        Stage::Pose,
        Stage::MethodA,
        Stage::MethodB,
        Stage::Output,
        Stage::Total,
    ];

    /// The name used in the output line and the table.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Ingest => "ingest",
            Stage::Pose => "pose",
            Stage::MethodA => "method_a",
            Stage::MethodB => "method_b",
            Stage::Output => "output",
            Stage::Total => "total",
        }
    }
}

/// Buckets a decade.
const PER_DECADE: usize = 40;
/// Lower edge of the first bucket, ms (1 µs).
const LOW_MS: f64 = 1e-3;
/// Decades covered (1 µs .. 10 s).
const DECADES: usize = 7;
/// Buckets: one below `LOW_MS`, the log-spaced ones, one above 10 s.
pub const BUCKETS: usize = PER_DECADE * DECADES + 2;

/// A fixed-bucket histogram of durations in milliseconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Histogram {
    counts: [u32; BUCKETS],
    n: u64,
    max_ms: f64,
}

impl Default for Histogram {
    fn default() -> Self {
        Histogram {
            counts: [0; BUCKETS],
            n: 0,
            max_ms: 0.0,
        }
    }
}

impl Histogram {
    /// Bucket of a duration.
    fn bucket(ms: f64) -> usize {
        if ms.is_nan() || ms < LOW_MS {
            return 0;
        }
        let k = ((ms / LOW_MS).log10() * PER_DECADE as f64) as usize + 1;
        k.min(BUCKETS - 1)
    }

    /// Upper edge of bucket `k`, ms.
    fn upper_ms(k: usize) -> f64 {
        if k == BUCKETS - 1 {
            return f64::INFINITY;
        }
        LOW_MS * 10f64.powf(k as f64 / PER_DECADE as f64)
    }

    /// Counts one duration.
    pub fn record(&mut self, ms: f64) {
        let k = Self::bucket(ms);
        self.counts[k] = self.counts[k].saturating_add(1);
        self.n += 1;
        if ms > self.max_ms {
            self.max_ms = ms;
        }
    }

    /// Durations counted.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Longest duration, ms (exact).
    pub fn max_ms(&self) -> f64 {
        self.max_ms
    }

    /// The `q` quantile (0 < q ≤ 1), ms: the upper edge of the bucket holding it, never more
    /// than the maximum; 0 when empty.
    pub fn quantile_ms(&self, q: f64) -> f64 {
        if self.n == 0 {
            return 0.0;
        }
        let rank = (q.clamp(0.0, 1.0) * self.n as f64).ceil().max(1.0) as u64;
        let mut seen = 0u64;
        for (k, &c) in self.counts.iter().enumerate() {
            seen += u64::from(c);
            if seen >= rank {
                return Self::upper_ms(k).min(self.max_ms);
            }
        }
        self.max_ms
    }
}

/// Per-stage budgets, ms (`[runtime.budget_ms]`); the frame's is the deadline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budgets {
    /// The whole frame.
    pub deadline_ms: f64,
    /// Ingest.
    pub ingest_ms: f64,
    /// Pose.
    pub pose_ms: f64,
    /// Method A.
    pub method_a_ms: f64,
    /// Method B.
    pub method_b_ms: f64,
    /// Output.
    pub output_ms: f64,
}

impl Budgets {
    /// The budget of one stage.
    pub fn of(&self, s: Stage) -> f64 {
        match s {
            Stage::Ingest => self.ingest_ms,
            Stage::Pose => self.pose_ms,
            Stage::MethodA => self.method_a_ms,
            Stage::MethodB => self.method_b_ms,
            Stage::Output => self.output_ms,
            Stage::Total => self.deadline_ms,
        }
    }
}

/// Cloud share aged per revolution while its work is shrunk (policy step 2).
pub const SHRINK_DROP_FRACTION: f32 = 0.5;

/// What the policy decided for one frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Decision {
    /// Method B does not run this frame.
    pub skip_method_b: bool,
    /// The cloud's work is shrunk this frame.
    pub shrink_cloud: bool,
}

impl Decision {
    /// Whether the frame is degraded.
    pub fn degraded(&self) -> bool {
        self.skip_method_b || self.shrink_cloud
    }
}

/// The overrun policy's memory: recent stage times and the decimation phase.
#[derive(Debug, Clone, Default)]
pub struct Policy {
    /// Method B's decaying average and last time, ms.
    b_avg_ms: f64,
    b_last_ms: f64,
    /// Method A's last time, ms.
    a_last_ms: f64,
    /// Frames decided while behind (decimation phase).
    behind_frames: u64,
}

impl Policy {
    /// Step 2, decided before Method A: shrink the cloud when Method A overran its budget last
    /// frame.
    pub fn before_method_a(&self, budgets: &Budgets) -> bool {
        self.a_last_ms > budgets.method_a_ms
    }

    /// Step 1, decided before Method B with `elapsed_ms` of the frame gone: skip Method B when
    /// it would not fit in what is left of the deadline, or every other frame while `behind`.
    pub fn before_method_b(&mut self, budgets: &Budgets, elapsed_ms: f64, behind: bool) -> bool {
        let expected = self.b_avg_ms.max(self.b_last_ms);
        let no_room = expected > 0.0 && elapsed_ms + expected > budgets.deadline_ms;
        if no_room {
            // A skipped Method B is not measured: let its estimate decay so that one slow
            // frame (a hiccup of the machine) cannot shut it out for good; it is tried again
            // within a few frames and, if still too slow, skipped again.
            self.b_last_ms *= 0.5;
            self.b_avg_ms *= 0.8;
        }
        let decimate = if behind {
            self.behind_frames += 1;
            self.behind_frames.is_multiple_of(2)
        } else {
            self.behind_frames = 0;
            false
        };
        no_room || decimate
    }

    /// Learns Method A's time of this frame.
    pub fn method_a_took(&mut self, ms: f64) {
        self.a_last_ms = ms;
    }

    /// Learns Method B's time of this frame.
    pub fn method_b_took(&mut self, ms: f64) {
        self.b_last_ms = ms;
        self.b_avg_ms = if self.b_avg_ms == 0.0 {
            ms
        } else {
            0.9 * self.b_avg_ms + 0.1 * ms
        };
    }
}

/// The times of one frame, ms (`None`: the stage did not run).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FrameTimes {
    /// Ingest.
    pub ingest: f64,
    /// Pose.
    pub pose: f64,
    /// Method A.
    pub method_a: Option<f64>,
    /// Method B.
    pub method_b: Option<f64>,
    /// Output.
    pub output: f64,
    /// The frame.
    pub total: f64,
}

/// A run's deadline record: one histogram a stage and the counters of the table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DeadlineRecord {
    /// Histograms in [`Stage::ALL`] order.
    pub stages: [Histogram; 6],
    /// Frames over the stage's budget, in [`Stage::ALL`] order.
    pub over_budget: [u64; 6],
    /// Frames over the deadline.
    pub missed: u64,
    /// Degraded frames.
    pub degraded: u64,
    /// Frames without Method B by the policy.
    pub method_b_skipped: u64,
    /// Frames with the cloud's work shrunk.
    pub cloud_shrunk: u64,
    /// Frames that ended with the loop behind the LiDAR.
    pub behind_lidar: u64,
}

impl DeadlineRecord {
    /// Counts one frame.
    pub fn record(&mut self, t: &FrameTimes, budgets: &Budgets, missed: bool, degraded: bool) {
        let values = [
            Some(t.ingest),
            Some(t.pose),
            t.method_a,
            t.method_b,
            Some(t.output),
            Some(t.total),
        ];
        for (i, v) in values.into_iter().enumerate() {
            if let Some(ms) = v {
                self.stages[i].record(ms);
                if ms > budgets.of(Stage::ALL[i]) {
                    self.over_budget[i] += 1;
                }
            }
        }
        self.missed += u64::from(missed);
        self.degraded += u64::from(degraded);
    }

    /// Frames counted.
    pub fn frames(&self) -> u64 {
        self.stages[5].count()
    }
}

/// Power figures of a run for the table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PowerVerdict {
    /// Mean watts over the frames that had a figure.
    pub mean_w: Option<f64>,
    /// Highest figure.
    pub peak_w: Option<f64>,
    /// The budget, W.
    pub budget_w: f64,
    /// Where the watts came from.
    pub source: String,
}

/// The deadline and power table of `docs/interfaces.md` §4 (Markdown, so CI logs and notes can
/// carry it as is).
pub fn table(r: &DeadlineRecord, budgets: &Budgets, power: &PowerVerdict) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| stage | frames | p50 ms | p99 ms | max ms | budget ms | over budget |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    for (i, st) in Stage::ALL.iter().enumerate() {
        let h = &r.stages[i];
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.3} | {:.3} | {:.0} | {} |",
            st.name(),
            h.count(),
            h.quantile_ms(0.5),
            h.quantile_ms(0.99),
            h.max_ms(),
            budgets.of(*st),
            r.over_budget[i]
        );
    }
    let _ = writeln!(
        s,
        "deadline {:.0} ms: {} missed, {} degraded (Method B skipped {}, cloud shrunk {}), behind the LiDAR {} of {} frames",
        budgets.deadline_ms,
        r.missed,
        r.degraded,
        r.method_b_skipped,
        r.cloud_shrunk,
        r.behind_lidar,
        r.frames()
    );
    match (power.mean_w, power.peak_w) {
        (Some(mean), Some(peak)) => {
            let verdict = if peak <= power.budget_w {
                "within"
            } else if mean <= power.budget_w {
                "peaks over"
            } else {
                "OVER"
            };
            let _ = writeln!(
                s,
                "power: mean {mean:.2} W, peak {peak:.2} W: {verdict} the {:.0} W budget (source: {})",
                power.budget_w, power.source
            );
        }
        _ => {
            let _ = writeln!(s, "power: no figure (source: {})", power.source);
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_are_within_a_bucket_and_never_above_the_max() {
        let mut h = Histogram::default();
        for i in 1..=1000 {
            h.record(i as f64 * 0.01); // 0.01 .. 10 ms
        }
        assert_eq!(h.count(), 1000);
        let p50 = h.quantile_ms(0.5);
        assert!((5.0..=5.0 * 1.06).contains(&p50), "{p50}");
        let p99 = h.quantile_ms(0.99);
        assert!((9.9..=10.0).contains(&p99), "{p99}");
        assert_eq!(h.quantile_ms(1.0), 10.0);
        assert_eq!(h.max_ms(), 10.0);
    }

    #[test]
    fn odd_durations_land_in_the_edge_buckets() {
        let mut h = Histogram::default();
        h.record(f64::NAN);
        h.record(-1.0);
        h.record(1e9);
        assert_eq!(h.count(), 3);
        assert_eq!(h.max_ms(), 1e9);
        assert_eq!(h.quantile_ms(1.0), 1e9);
        assert!(h.quantile_ms(0.3) <= LOW_MS);
        assert_eq!(Histogram::default().quantile_ms(0.99), 0.0);
    }

    fn budgets() -> Budgets {
        Budgets {
            deadline_ms: 100.0,
            ingest_ms: 5.0,
            pose_ms: 5.0,
            method_a_ms: 40.0,
            method_b_ms: 40.0,
            output_ms: 10.0,
        }
    }

    #[test]
    fn method_b_is_skipped_when_it_would_not_fit_and_decimated_when_behind() {
        let b = budgets();
        let mut p = Policy::default();
        // Nothing known yet: B runs.
        assert!(!p.before_method_b(&b, 90.0, false));
        p.method_b_took(30.0);
        assert!(!p.before_method_b(&b, 60.0, false));
        assert!(p.before_method_b(&b, 75.0, false));
        // Behind the LiDAR: every other frame.
        let runs: Vec<bool> = (0..4).map(|_| p.before_method_b(&b, 0.0, true)).collect();
        assert_eq!(runs, [false, true, false, true]);
        assert!(!p.before_method_b(&b, 0.0, false));
    }

    #[test]
    fn one_slow_method_b_frame_does_not_shut_it_out() {
        // The 18,000-frame soak on a loaded machine: one 364 ms Method B frame, and the old
        // policy skipped Method B for the rest of the run.
        let b = Budgets {
            deadline_ms: 250.0,
            ..budgets()
        };
        let mut p = Policy::default();
        for _ in 0..20 {
            p.method_b_took(8.0);
        }
        p.method_b_took(364.0);
        let skipped = (0..20)
            .take_while(|_| p.before_method_b(&b, 1.0, false))
            .count();
        assert!(
            (1..=5).contains(&skipped),
            "tried again after {skipped} frames"
        );
    }

    #[test]
    fn the_cloud_shrinks_after_method_a_overran_its_budget() {
        let b = budgets();
        let mut p = Policy::default();
        assert!(!p.before_method_a(&b));
        p.method_a_took(41.0);
        assert!(p.before_method_a(&b));
        p.method_a_took(10.0);
        assert!(!p.before_method_a(&b));
    }

    #[test]
    fn the_table_has_every_stage_and_the_verdicts() {
        let b = budgets();
        let mut r = DeadlineRecord::default();
        let t = FrameTimes {
            ingest: 0.1,
            pose: 0.01,
            method_a: Some(50.0),
            method_b: None,
            output: 0.02,
            total: 120.0,
        };
        r.record(&t, &b, true, false);
        let power = PowerVerdict {
            mean_w: Some(4.0),
            peak_w: Some(11.0),
            budget_w: 10.0,
            source: "model".into(),
        };
        let s = table(&r, &b, &power);
        for st in Stage::ALL {
            assert!(s.contains(&format!("| {} |", st.name())), "{s}");
        }
        assert!(s.contains("| method_b | 0 |"), "{s}");
        assert!(
            s.contains("| method_a | 1 | 50.000 | 50.000 | 50.000 | 40 | 1 |"),
            "{s}"
        );
        assert!(s.contains("1 missed, 0 degraded"), "{s}");
        assert!(
            s.contains("peaks over the 10 W budget (source: model)"),
            "{s}"
        );
    }
}
