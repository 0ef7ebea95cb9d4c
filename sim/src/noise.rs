//! The simulator's noise: approximately normal, σ = 1, bounded to ±3 (the sum of three
//! independent U(−1, 1): variance 3 · 1/3 = 1). Bounded so that no draw produces an absurd
//! reading; cheap and reproducible from any seeded generator.

use rand::Rng;

/// One draw, σ = 1, in [−3, 3].
pub fn unit(rng: &mut impl Rng) -> f32 {
    (0..3).map(|_| rng.random_range(-1.0..1.0f32)).sum()
}

#[cfg(test)]
mod test {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn unit_variance_and_bounds() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let n = 200_000;
        let xs: Vec<f32> = (0..n).map(|_| unit(&mut rng)).collect();
        let mean = xs.iter().sum::<f32>() / n as f32;
        let var = xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f32>() / n as f32;
        assert!(
            mean.abs() < 0.01 && (var - 1.0).abs() < 0.02,
            "mean {mean}, var {var}"
        );
        assert!(xs.iter().all(|x| x.abs() <= 3.0));
    }
}
