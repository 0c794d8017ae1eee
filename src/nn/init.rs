//! Weight initialization as the reference does it (`docs/ALGORITHMS.md` §2.2), drawn from the
//! caller's seeded stream.

use ndarray::{Array1, Array2};
use rand::distributions::{Distribution, Uniform};
use rand_chacha::ChaCha8Rng;

/// PyTorch `calculate_gain('leaky_relu')` with its default slope 0.01: sqrt(2 / (1 + 0.01^2)).
pub const LEAKY_RELU_GAIN: f64 = 1.414_142_856_997_835_4;

/// Xavier-uniform [fan_out, fan_in]: U(-b, b), b = gain * sqrt(6 / (fan_in + fan_out)), drawn
/// in row-major order.
pub fn xavier_uniform(
    fan_out: usize,
    fan_in: usize,
    gain: f64,
    rng: &mut ChaCha8Rng,
) -> Array2<f32> {
    let bound = gain * (6.0 / (fan_in + fan_out) as f64).sqrt();
    uniform2(fan_out, fan_in, bound as f32, rng)
}

/// [rows, cols] from U(-bound, bound), row-major draw order.
pub fn uniform2(rows: usize, cols: usize, bound: f32, rng: &mut ChaCha8Rng) -> Array2<f32> {
    let d = Uniform::new(-bound, bound);
    Array2::from_shape_simple_fn((rows, cols), || d.sample(rng))
}

/// \[n\] from U(-bound, bound).
pub fn uniform1(n: usize, bound: f32, rng: &mut ChaCha8Rng) -> Array1<f32> {
    let d = Uniform::new(-bound, bound);
    Array1::from_shape_simple_fn(n, || d.sample(rng))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn leaky_relu_gain_matches_pytorch() {
        assert!((LEAKY_RELU_GAIN - (2.0f64 / (1.0 + 0.01 * 0.01)).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn xavier_draws_fill_the_bound_and_stay_inside_it() {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let w = xavier_uniform(64, 32, LEAKY_RELU_GAIN, &mut rng);
        let b = (LEAKY_RELU_GAIN * (6.0f64 / 96.0).sqrt()) as f32;
        let max = w.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        assert!(max <= b && max > 0.98 * b, "max {max}, bound {b}");
        // variance of U(-b, b) is b^2 / 3
        let var = w.iter().map(|v| v * v).sum::<f32>() / w.len() as f32;
        assert!((var / (b * b / 3.0) - 1.0).abs() < 0.05, "variance {var}");
    }
}
