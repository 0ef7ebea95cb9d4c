//! Training the Method A forest (host only, `std`): StandardScaler + random forest (bootstrap,
//! CART on Gini impurity, `max_features` features drawn per split), and emitting the result as
//! the Rust `const` tables of [`crate::forest_tables`].
//!
//! Why our own trainer rather than scikit-learn, smartcore or linfa: the trees must come out
//! as constant tables that a test regenerates from the committed training data on every CI run
//! and compares byte for byte. That needs a trainer that is bit-reproducible on every machine
//! (one seeded SplitMix64 stream, `f32` arithmetic identical to the run-time scaler, stable
//! tie-breaking) and whose tree structure is public. scikit-learn would put Python into CI;
//! smartcore keeps its tree nodes private; linfa's trees have no per-split feature sampling.
//! A depth-6, 50-tree CART forest is about 200 lines.
//!
//! Training data is CSV with a header; the columns used are `label` (`chair`, `box`, `desk`,
//! `none`) and nine feature columns `o_<name>` (object frame) or `a_<name>` (map axes), names
//! as in [`perception::features::FEATURE_NAMES`].

use std::fmt::Write as _;

use perception::features::{FEATURE_NAMES, N_FEATURES};

use crate::forest::{LABEL_NAMES, LEAF, N_LABELS, Node, scale};

/// Trainer settings (the study's: 50 trees, depth 6; √9 = 3 features a split).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrainConfig {
    /// Trees.
    pub trees: usize,
    /// Deepest split level (a depth-6 tree has at most 64 leaves).
    pub max_depth: usize,
    /// Features tried per split.
    pub max_features: usize,
    /// Seed of the bootstrap and feature draws.
    pub seed: u64,
    /// Features in the object's frame (`o_` columns) or the map axes (`a_`).
    pub object_frame: bool,
}

impl Default for TrainConfig {
    fn default() -> Self {
        TrainConfig {
            trees: 50,
            max_depth: 6,
            max_features: 3,
            seed: 1,
            object_frame: true,
        }
    }
}

/// Feature vectors with labels.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Dataset {
    /// Features.
    pub x: Vec<[f32; N_FEATURES]>,
    /// Label index into [`LABEL_NAMES`].
    pub y: Vec<u8>,
}

/// Parses training CSV; the error names the line and column at fault.
pub fn read_csv(text: &str, object_frame: bool) -> Result<Dataset, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty file")?.split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| format!("no column `{name}`"))
    };
    let label_col = col("label")?;
    let prefix = if object_frame { "o_" } else { "a_" };
    let mut cols = [0usize; N_FEATURES];
    for (c, name) in cols.iter_mut().zip(FEATURE_NAMES) {
        *c = col(&format!("{prefix}{name}"))?;
    }
    let mut d = Dataset::default();
    for (i, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split(',').collect();
        let at = |c: usize| {
            f.get(c)
                .copied()
                .ok_or(format!("line {}: too few columns", i + 2))
        };
        let label = at(label_col)?;
        let y = LABEL_NAMES
            .iter()
            .position(|n| *n == label)
            .ok_or(format!("line {}: unknown label `{label}`", i + 2))?;
        let mut x = [0.0f32; N_FEATURES];
        for (v, &c) in x.iter_mut().zip(&cols) {
            let s = at(c)?;
            *v = s
                .parse()
                .map_err(|_| format!("line {}: `{s}` is not a number", i + 2))?;
            if !v.is_finite() {
                return Err(format!("line {}: `{s}` is not finite", i + 2));
            }
        }
        d.x.push(x);
        d.y.push(y as u8);
    }
    Ok(d)
}

/// A trained forest, ready to emit or to use in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Trained {
    /// Scaler means.
    pub mean: [f32; N_FEATURES],
    /// Scaler scales.
    pub scale: [f32; N_FEATURES],
    /// Nodes of all trees.
    pub nodes: Vec<Node>,
    /// Roots.
    pub roots: Vec<u16>,
    /// Leaf probabilities.
    pub leaves: Vec<[f32; N_LABELS]>,
    /// Frame of the features.
    pub object_frame: bool,
}

impl Trained {
    /// Leaks the tables into a `'static` forest (host tools that train and evaluate in one run).
    pub fn leak(self) -> crate::forest::ForestTables {
        crate::forest::ForestTables {
            mean: self.mean,
            scale: self.scale,
            nodes: Box::leak(self.nodes.into_boxed_slice()),
            roots: Box::leak(self.roots.into_boxed_slice()),
            leaves: Box::leak(self.leaves.into_boxed_slice()),
            object_frame: self.object_frame,
        }
    }
}

/// SplitMix64: one reproducible stream for every draw.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

fn gini(c: &[u32; N_LABELS], n: u32) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let n = f64::from(n);
    1.0 - c.iter().map(|&k| (f64::from(k) / n).powi(2)).sum::<f64>()
}

struct Builder<'a> {
    z: &'a [[f32; N_FEATURES]],
    y: &'a [u8],
    cfg: &'a TrainConfig,
    rng: Rng,
    nodes: Vec<Node>,
    leaves: Vec<[f32; N_LABELS]>,
}

impl Builder<'_> {
    fn leaf(&mut self, idx: &[usize]) -> u16 {
        let mut c = [0u32; N_LABELS];
        for &i in idx {
            c[self.y[i] as usize] += 1;
        }
        let n = idx.len().max(1) as f32;
        self.leaves.push(c.map(|k| k as f32 / n));
        self.nodes.push(Node {
            feature: LEAF,
            threshold: 0.0,
            left: (self.leaves.len() - 1) as u16,
            right: 0,
        });
        (self.nodes.len() - 1) as u16
    }

    fn grow(&mut self, idx: &mut [usize], depth: usize) -> u16 {
        let mut c = [0u32; N_LABELS];
        for &i in idx.iter() {
            c[self.y[i] as usize] += 1;
        }
        let pure = c.iter().filter(|&&k| k > 0).count() <= 1;
        if depth >= self.cfg.max_depth || pure || idx.len() < 2 {
            return self.leaf(idx);
        }
        // Draw the features to try (partial Fisher–Yates).
        let mut feats: [usize; N_FEATURES] = core::array::from_fn(|i| i);
        let k = self.cfg.max_features.clamp(1, N_FEATURES);
        for i in 0..k {
            let j = i + self.rng.below(N_FEATURES - i);
            feats.swap(i, j);
        }
        let n = idx.len() as u32;
        let mut best: Option<(f64, usize, f32)> = None;
        for &f in &feats[..k] {
            idx.sort_by(|&a, &b| self.z[a][f].total_cmp(&self.z[b][f]).then(a.cmp(&b)));
            let mut left = [0u32; N_LABELS];
            for s in 0..idx.len() - 1 {
                left[self.y[idx[s]] as usize] += 1;
                let (a, b) = (self.z[idx[s]][f], self.z[idx[s + 1]][f]);
                if a == b {
                    continue;
                }
                let nl = s as u32 + 1;
                let mut right = c;
                for (r, l) in right.iter_mut().zip(&left) {
                    *r -= l;
                }
                let imp = (f64::from(nl) * gini(&left, nl)
                    + f64::from(n - nl) * gini(&right, n - nl))
                    / f64::from(n);
                if best.is_none_or(|(bi, _, _)| imp < bi) {
                    let mut t = a + (b - a) / 2.0;
                    if t >= b || t < a {
                        t = a;
                    }
                    best = Some((imp, f, t));
                }
            }
        }
        let Some((imp, f, t)) = best else {
            return self.leaf(idx);
        };
        if imp >= gini(&c, n) {
            return self.leaf(idx);
        }
        idx.sort_by(|&a, &b| self.z[a][f].total_cmp(&self.z[b][f]).then(a.cmp(&b)));
        let split = idx.partition_point(|&i| self.z[i][f] <= t);
        let at = self.nodes.len();
        self.nodes.push(Node {
            feature: f as u8,
            threshold: t,
            left: 0,
            right: 0,
        });
        let (l, r) = idx.split_at_mut(split);
        let left = self.grow(l, depth + 1);
        let right = self.grow(r, depth + 1);
        self.nodes[at].left = left;
        self.nodes[at].right = right;
        at as u16
    }
}

/// Fits the scaler and the forest.
pub fn train(d: &Dataset, cfg: &TrainConfig) -> Trained {
    let n = d.x.len();
    let mut mean = [0.0f32; N_FEATURES];
    let mut sc = [1.0f32; N_FEATURES];
    if n > 0 {
        for f in 0..N_FEATURES {
            let m = d.x.iter().map(|x| f64::from(x[f])).sum::<f64>() / n as f64;
            let v =
                d.x.iter()
                    .map(|x| (f64::from(x[f]) - m).powi(2))
                    .sum::<f64>()
                    / n as f64;
            mean[f] = m as f32;
            let s = v.sqrt() as f32;
            sc[f] = if s > 0.0 && s.is_finite() { s } else { 1.0 };
        }
    }
    let z: Vec<[f32; N_FEATURES]> = d.x.iter().map(|x| scale(&mean, &sc, x)).collect();
    let mut b = Builder {
        z: &z,
        y: &d.y,
        cfg,
        rng: Rng(cfg.seed),
        nodes: Vec::new(),
        leaves: Vec::new(),
    };
    let mut roots = Vec::new();
    for _ in 0..cfg.trees {
        let mut idx: Vec<usize> = (0..n).map(|_| b.rng.below(n.max(1))).collect();
        if n == 0 {
            idx.clear();
        }
        roots.push(b.grow(&mut idx, 0));
    }
    Trained {
        mean,
        scale: sc,
        nodes: b.nodes,
        roots,
        leaves: b.leaves,
        object_frame: cfg.object_frame,
    }
}

fn bits(v: f32) -> String {
    format!("f32::from_bits({:#010x})", v.to_bits())
}

/// The Rust source of `forest_tables.rs` for `t`; `how` says how to regenerate it.
pub fn emit_rust(t: &Trained, how: &str) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "//! The Method A forest as constant tables. Generated; do not edit.\n//!\n//! Regenerate with `{how}`.\n//! {} trees, {} nodes, {} leaves; features in the {} frame. A test retrains from the\n//! committed data and compares this file byte for byte.\n",
        t.roots.len(),
        t.nodes.len(),
        t.leaves.len(),
        if t.object_frame {
            "object's own"
        } else {
            "map-axis"
        }
    );
    let _ = writeln!(s, "use crate::forest::{{ForestTables, LEAF, Node}};\n");
    let arr = |v: &[f32]| v.iter().map(|x| bits(*x)).collect::<Vec<_>>().join(", ");
    let _ = writeln!(s, "/// The forest compiled into umbra.");
    let _ = writeln!(s, "pub static FOREST: ForestTables = ForestTables {{");
    let _ = writeln!(s, "    mean: [{}],", arr(&t.mean));
    let _ = writeln!(s, "    scale: [{}],", arr(&t.scale));
    let _ = writeln!(
        s,
        "    nodes: &NODES,\n    roots: &ROOTS,\n    leaves: &LEAVES,"
    );
    let _ = writeln!(s, "    object_frame: {},\n}};\n", t.object_frame);
    let roots: Vec<String> = t.roots.iter().map(|r| r.to_string()).collect();
    let _ = writeln!(
        s,
        "static ROOTS: [u16; {}] = [{}];\n",
        t.roots.len(),
        roots.join(", ")
    );
    let _ = writeln!(s, "static NODES: [Node; {}] = [", t.nodes.len());
    for n in &t.nodes {
        let f = if n.feature == LEAF {
            "LEAF".to_string()
        } else {
            n.feature.to_string()
        };
        let _ = writeln!(
            s,
            "    Node {{ feature: {f}, threshold: {}, left: {}, right: {} }},",
            bits(n.threshold),
            n.left,
            n.right
        );
    }
    let _ = writeln!(s, "];\n");
    let _ = writeln!(s, "static LEAVES: [[f32; 4]; {}] = [", t.leaves.len());
    for l in &t.leaves {
        let _ = writeln!(s, "    [{}],", arr(l));
    }
    let _ = writeln!(s, "];");
    s
}

#[cfg(test)]
mod test {
    use super::*;

    fn toy() -> Dataset {
        // Class = which quadrant of (f0, f1); the rest noise-free constants.
        let mut d = Dataset::default();
        for i in 0..400u32 {
            let a = (i % 20) as f32 / 20.0;
            let b = (i / 20) as f32 / 20.0;
            let mut x = [0.5f32; N_FEATURES];
            x[0] = a;
            x[1] = b;
            d.x.push(x);
            d.y.push(match (a < 0.5, b < 0.5) {
                (true, true) => 0,
                (false, true) => 1,
                (true, false) => 2,
                _ => 3,
            });
        }
        d
    }

    #[test]
    fn learns_quadrants_and_is_reproducible() {
        let d = toy();
        let cfg = TrainConfig {
            max_features: 9,
            ..TrainConfig::default()
        };
        let t = train(&d, &cfg);
        assert_eq!(t, train(&d, &cfg));
        let f = t.clone().leak();
        let correct =
            d.x.iter()
                .zip(&d.y)
                .filter(|(x, y)| f.predict(x).0 == **y as usize)
                .count();
        assert_eq!(correct, d.x.len());
        let src = emit_rust(&t, "test");
        assert!(src.contains("pub static FOREST"));
    }

    #[test]
    fn csv_errors_name_the_line() {
        let mut head = String::from("label");
        for p in ["o_", "a_"] {
            for n in FEATURE_NAMES {
                head.push_str(&format!(",{p}{n}"));
            }
        }
        let row = |label: &str, v: &str| format!("{label}{}", format!(",{v}").repeat(18));
        let ok = format!("{head}\n{}\n", row("chair", "1.5"));
        let d = read_csv(&ok, true).unwrap();
        assert_eq!((d.x.len(), d.y[0]), (1, 0));
        let bad = format!("{head}\n{}\n", row("sofa", "1"));
        assert!(read_csv(&bad, true).unwrap_err().contains("line 2"));
        let nan = format!("{head}\n{}\n", row("box", "NaN"));
        assert!(read_csv(&nan, false).unwrap_err().contains("not finite"));
        assert!(read_csv("", true).is_err());
        // No data: a forest of leaves that still predicts something.
        let t = train(&Dataset::default(), &TrainConfig::default());
        assert_eq!(t.roots.len(), 50);
    }
}
