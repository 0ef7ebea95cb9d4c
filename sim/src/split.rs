//! Which split each scenario of a dataset lands in, and each scenario's own seed: whole
//! scenarios, never frames, so no world is both trained and tested on.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

/// Dataset split.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Split {
    /// 85 %.
    Train,
    /// 10 %.
    Val,
    /// 5 %.
    Test,
}

impl Split {
    /// Folder name.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Val => "val",
            Split::Test => "test",
        }
    }
}

/// The split of every scenario: a seeded shuffle, then 5 % test and 10 % val (each at least
/// one scenario when there are three or more), the rest train.
pub fn splits(scenarios: usize, seed: u64) -> Vec<Split> {
    let mut order: Vec<usize> = (0..scenarios).collect();
    order.shuffle(&mut ChaCha8Rng::seed_from_u64(seed ^ 0x5_9117));
    let at_least = |share: f64| {
        let n = (scenarios as f64 * share).round() as usize;
        if scenarios >= 3 { n.max(1) } else { n }
    };
    let (n_test, n_val) = (at_least(0.05), at_least(0.10));
    let mut out = vec![Split::Train; scenarios];
    for (rank, &i) in order.iter().enumerate() {
        out[i] = if rank < n_test {
            Split::Test
        } else if rank < n_test + n_val {
            Split::Val
        } else {
            Split::Train
        };
    }
    out
}

/// Seed of scenario `i` (SplitMix64 of the master seed and the index).
pub fn scenario_seed(seed: u64, i: usize) -> u64 {
    let mut z = seed ^ (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
