//! The Method A classifier at run time: a StandardScaler and a random forest, evaluated over
//! `const` tables ([`crate::forest_tables`]). `no_std`, no allocation, no floating-point
//! surprises: the only arithmetic is the scaler's `(x − mean) / scale` in `f32`, the same
//! operations the trainer used to choose the thresholds (IEEE 754 gives the same bits on the
//! host and on a Pi), then comparisons and a sum of leaf probabilities.

use perception::class::ObjectClass;
use perception::features::N_FEATURES;
use perception::method_a::Classifier;

/// Labels the forest tells apart: the three furniture classes and "none of them".
pub const N_LABELS: usize = 4;
/// The forest's labels, in output order.
pub const LABELS: [Option<ObjectClass>; N_LABELS] = [
    Some(ObjectClass::Chair),
    Some(ObjectClass::Box),
    Some(ObjectClass::Desk),
    None,
];
/// Label names as the training data spells them.
pub const LABEL_NAMES: [&str; N_LABELS] = ["chair", "box", "desk", "none"];

/// Marks a leaf in [`Node::feature`].
pub const LEAF: u8 = u8::MAX;

/// One tree node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// Feature compared, or [`LEAF`].
    pub feature: u8,
    /// Go left when the scaled feature is `<=` this.
    pub threshold: f32,
    /// Left child (index in [`ForestTables::nodes`]), or the leaf's row in `leaves`.
    pub left: u16,
    /// Right child.
    pub right: u16,
}

/// A trained forest.
#[derive(Debug, Clone, Copy)]
pub struct ForestTables {
    /// Scaler means.
    pub mean: [f32; N_FEATURES],
    /// Scaler scales (population standard deviations; 1 where a feature was constant).
    pub scale: [f32; N_FEATURES],
    /// Every tree's nodes, trees one after another.
    pub nodes: &'static [Node],
    /// The root of each tree.
    pub roots: &'static [u16],
    /// Class probabilities of each leaf.
    pub leaves: &'static [[f32; N_LABELS]],
    /// Which frame the features must be computed in.
    pub object_frame: bool,
}

/// Scales a feature vector as the trainer did.
pub fn scale(
    mean: &[f32; N_FEATURES],
    scale: &[f32; N_FEATURES],
    x: &[f32; N_FEATURES],
) -> [f32; N_FEATURES] {
    let mut out = [0.0; N_FEATURES];
    for i in 0..N_FEATURES {
        out[i] = (x[i] - mean[i]) / scale[i];
    }
    out
}

impl ForestTables {
    /// Mean class probabilities over the trees. A malformed table (a child index out of range,
    /// a loop) ends that tree's walk and the tree does not vote; it cannot panic.
    pub fn predict_proba(&self, x: &[f32; N_FEATURES]) -> [f32; N_LABELS] {
        let z = scale(&self.mean, &self.scale, x);
        let mut sum = [0.0f32; N_LABELS];
        let mut voters = 0u32;
        for &root in self.roots {
            let mut at = root as usize;
            for _ in 0..64 {
                let Some(n) = self.nodes.get(at) else { break };
                if n.feature == LEAF {
                    if let Some(p) = self.leaves.get(n.left as usize) {
                        for (s, v) in sum.iter_mut().zip(p) {
                            *s += v;
                        }
                        voters += 1;
                    }
                    break;
                }
                let v = z.get(n.feature as usize).copied().unwrap_or(0.0);
                at = if v <= n.threshold { n.left } else { n.right } as usize;
            }
        }
        if voters > 0 {
            for s in &mut sum {
                *s /= voters as f32;
            }
        }
        sum
    }

    /// The most probable label (ties: the lower index) and its probability.
    pub fn predict(&self, x: &[f32; N_FEATURES]) -> (usize, f32) {
        let p = self.predict_proba(x);
        let mut best = 0;
        for k in 1..N_LABELS {
            if p[k] > p[best] {
                best = k;
            }
        }
        (best, p[best])
    }
}

impl Classifier for ForestTables {
    fn classify(&self, features: &[f32; N_FEATURES]) -> (Option<ObjectClass>, f32) {
        let (k, p) = self.predict(features);
        (LABELS[k], p)
    }
}

/// The forest compiled into umbra.
pub fn forest() -> &'static ForestTables {
    &crate::forest_tables::FOREST
}

#[cfg(test)]
mod test {
    use super::*;

    static NODES: [Node; 3] = [
        Node {
            feature: 0,
            threshold: 0.0,
            left: 1,
            right: 2,
        },
        Node {
            feature: LEAF,
            threshold: 0.0,
            left: 0,
            right: 0,
        },
        Node {
            feature: LEAF,
            threshold: 0.0,
            left: 1,
            right: 0,
        },
    ];
    static LEAVES: [[f32; N_LABELS]; 2] = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.25, 0.75]];
    static BAD: [Node; 1] = [Node {
        feature: 0,
        threshold: 0.0,
        left: 0,
        right: 0,
    }];

    fn tables(nodes: &'static [Node]) -> ForestTables {
        ForestTables {
            mean: [1.0; N_FEATURES],
            scale: [2.0; N_FEATURES],
            nodes,
            roots: &[0],
            leaves: &LEAVES,
            object_frame: true,
        }
    }

    #[test]
    fn walks_to_the_right_leaf() {
        let t = tables(&NODES);
        let mut x = [0.0; N_FEATURES];
        assert_eq!(t.predict(&x), (0, 1.0));
        x[0] = 1.5; // scaled 0.25 > 0
        assert_eq!(t.predict(&x), (3, 0.75));
        assert_eq!(t.classify(&x), (None, 0.75));
    }

    #[test]
    fn malformed_tables_do_not_panic() {
        let t = tables(&BAD);
        assert_eq!(t.predict_proba(&[0.0; N_FEATURES]), [0.0; N_LABELS]);
        let nan = [f32::NAN; N_FEATURES];
        let _ = tables(&NODES).predict(&nan);
    }

    #[test]
    fn compiled_forest_is_well_formed() {
        let f = forest();
        assert!(!f.roots.is_empty());
        for n in f.nodes {
            if n.feature == LEAF {
                assert!((n.left as usize) < f.leaves.len());
            } else {
                assert!((n.feature as usize) < N_FEATURES);
                assert!((n.left as usize) < f.nodes.len() && (n.right as usize) < f.nodes.len());
                assert!(n.threshold.is_finite());
            }
        }
        for p in f.leaves {
            let s: f32 = p.iter().sum();
            assert!((s - 1.0).abs() < 1e-4, "{p:?}");
        }
    }
}
