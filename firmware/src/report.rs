//! `umbra report OUT.jsonl`: the deadline and power table of a finished run, rebuilt from its
//! output lines.
//!
//! The lines carry every stage time the run recorded (`timing_ms`), the misses and degraded
//! flags, the policy's cumulative counters (`faults`) and the watts with their source, so the
//! table is the one the run printed at its end: the same histograms fed the same numbers.

use std::io::BufRead as _;
use std::path::Path;

use crate::config::Config;
use crate::deadline::{DeadlineRecord, FrameTimes, PowerVerdict, table};

/// Reads a run's JSON Lines and renders its table. Stage budgets come from `cfg` (the run's
/// configuration) or, without it, the default shares of the lines' deadline.
pub fn from_jsonl(path: &Path, cfg: Option<&Config>) -> Result<String, String> {
    let name = path.display();
    let file = std::fs::File::open(path).map_err(|e| format!("{name}: cannot open: {e}"))?;
    let mut record = DeadlineRecord::default();
    let mut deadline = None;
    let (mut sum, mut n, mut peak) = (0.0, 0u64, 0.0f64);
    let mut source = String::from("none");
    let mut last_faults = serde_json::Value::Null;
    let mut lines = Vec::new();
    for (i, line) in std::io::BufReader::new(file).lines().enumerate() {
        let line = line.map_err(|e| format!("{name}: line {}: {e}", i + 1))?;
        if line.trim().is_empty() {
            continue;
        }
        let v: serde_json::Value = serde_json::from_str(&line)
            .map_err(|e| format!("{name}: line {}: not JSON: {e}", i + 1))?;
        let num = |v: &serde_json::Value, key: &str| -> Result<f64, String> {
            v.get(key)
                .and_then(|x| x.as_f64())
                .ok_or_else(|| format!("{name}: line {}: no number `{key}`", i + 1))
        };
        let t = v
            .get("timing_ms")
            .ok_or_else(|| format!("{name}: line {}: no `timing_ms`", i + 1))?;
        let times = FrameTimes {
            ingest: num(t, "ingest")?,
            pose: num(t, "pose")?,
            method_a: t.get("method_a").and_then(|x| x.as_f64()),
            method_b: t.get("method_b").and_then(|x| x.as_f64()),
            output: t.get("output").and_then(|x| x.as_f64()).unwrap_or(0.0),
            total: num(t, "total")?,
        };
        let d = num(&v, "deadline_ms")?;
        deadline.get_or_insert(d);
        let flag = |key: &str| v.get(key).and_then(|x| x.as_bool()).unwrap_or(false);
        lines.push((times, flag("deadline_missed"), flag("degraded")));
        if let Some(w) = v.get("power_w").and_then(|x| x.as_f64()) {
            sum += w;
            n += 1;
            peak = peak.max(w);
        }
        if let Some(s) = v.get("power_source").and_then(|x| x.as_str()) {
            s.clone_into(&mut source);
        }
        if let Some(f) = v.get("faults") {
            last_faults = f.clone();
        }
    }
    let Some(deadline) = deadline else {
        return Err(format!("{name}: no output lines"));
    };
    let mut cfg = cfg.cloned().unwrap_or_default();
    cfg.runtime.deadline_ms = deadline;
    let budgets = cfg.budgets();
    for (times, missed, degraded) in &lines {
        record.record(times, &budgets, *missed, *degraded);
    }
    let count = |key: &str| last_faults.get(key).and_then(|x| x.as_u64()).unwrap_or(0);
    record.method_b_skipped = count("method_b_skipped");
    record.cloud_shrunk = count("cloud_shrunk");
    record.behind_lidar = count("behind_lidar");
    let power = PowerVerdict {
        mean_w: (n > 0).then(|| sum / n as f64),
        peak_w: (n > 0).then_some(peak),
        budget_w: cfg.power.budget_w,
        source,
    };
    Ok(table(&record, &budgets, &power))
}
