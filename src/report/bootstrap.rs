//! Stratified bootstrap confidence intervals (rliable's `StratifiedBootstrap`, Agarwal et al.
//! 2021, §4): resample runs with replacement within each stratum, recompute the statistic on
//! every resample, and take the 2.5th and 97.5th percentiles of the recomputed values as the
//! 95% interval (the percentile method rliable asks `arch` for).
//!
//! Reproducible bit for bit: each interval draws from its own ChaCha8 stream, keyed by the
//! user's seed and the interval's name ([`stream`]), so neither the order quantities are
//! computed in, nor the thread count, nor another method added to a block moves a number.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The coverage of every interval: 95%.
pub const CONFIDENCE: f64 = 0.95;

/// The most resamples `--resamples` takes: 50 times the default 2000, far past where the
/// percentiles stop moving, and a bound so a typo cannot run for hours.
pub const MAX_RESAMPLES: usize = 100_000;

/// The default resample count (`--resamples`).
pub const DEFAULT_RESAMPLES: usize = 2000;

/// A confidence interval: the bootstrap distribution's percentiles at (1 - [`CONFIDENCE`]) / 2
/// and (1 + [`CONFIDENCE`]) / 2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// The lower bound.
    pub low: f64,
    /// The upper bound.
    pub high: f64,
}

/// The random stream of one named interval: ChaCha8 seeded with `seed`, on the stream numbered
/// by the 64-bit FNV-1a hash of `key` (`aggregate/bp6/mac-iac`). A stable hash, so the same
/// key draws the same numbers on every platform and in every release.
pub fn stream(seed: u64, key: &str) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(fnv1a(key));
    rng
}

/// 64-bit FNV-1a of the key's bytes.
fn fnv1a(key: &str) -> u64 {
    key.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// One stratified resample: for each stratum of `sizes[i]` runs, `sizes[i]` run indices drawn
/// uniformly with replacement (a stratum of one run always resamples itself).
pub fn resample(sizes: &[usize], rng: &mut ChaCha8Rng) -> Vec<Vec<usize>> {
    sizes
        .iter()
        // Drawn as u64 so 32- and 64-bit builds draw the same indices.
        .map(|&n| {
            (0..n)
                .map(|_| rng.gen_range(0..n as u64) as usize)
                .collect()
        })
        .collect()
}

/// Percentile intervals of the numbers `statistic` returns, over `resamples` stratified
/// resamples of strata of `sizes` runs. `statistic` receives, per stratum, the resampled run
/// indices and returns the same count of numbers each time (all the metrics of a method, a
/// curve's points): one interval each, in that order, all from the same resamples.
///
/// Panics if `resamples` is 0 (the report's options refuse it) or if `statistic` returns
/// different counts on different resamples (a bug).
pub fn percentile_intervals(
    sizes: &[usize],
    resamples: usize,
    rng: &mut ChaCha8Rng,
    mut statistic: impl FnMut(&[Vec<usize>]) -> Vec<f64>,
) -> Vec<Interval> {
    assert!(resamples > 0, "a bootstrap needs at least one resample");
    let mut draws: Vec<Vec<f64>> = Vec::new();
    for _ in 0..resamples {
        let values = statistic(&resample(sizes, rng));
        if draws.is_empty() {
            draws = vec![Vec::with_capacity(resamples); values.len()];
        }
        assert_eq!(values.len(), draws.len(), "a statistic of fixed length");
        for (column, v) in draws.iter_mut().zip(values) {
            column.push(v);
        }
    }
    let tail = (1.0 - CONFIDENCE) / 2.0;
    draws
        .into_iter()
        .map(|mut column| {
            column.sort_by(f64::total_cmp);
            Interval {
                low: percentile(&column, tail),
                high: percentile(&column, 1.0 - tail),
            }
        })
        .collect()
}

/// The `q` quantile (0..=1) of ascending `sorted` values, interpolated linearly between the
/// two nearest ranks as `numpy.percentile` does by default: rank q (n - 1). NaN for no values.
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    let Some(last) = sorted.len().checked_sub(1) else {
        return f64::NAN;
    };
    let rank = q.clamp(0.0, 1.0) * last as f64;
    let below = rank.floor() as usize;
    let above = (below + 1).min(last);
    let weight = rank - below as f64;
    if weight == 0.0 {
        sorted[below]
    } else {
        sorted[below] + weight * (sorted[above] - sorted[below])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::scores::{iqm, mean};

    fn mean_of(scores: &[f64]) -> impl FnMut(&[Vec<usize>]) -> Vec<f64> + '_ {
        move |idx| {
            let drawn: Vec<f64> = idx[0].iter().map(|&i| scores[i]).collect();
            vec![mean(&drawn).unwrap()]
        }
    }

    #[test]
    fn percentile_interpolates_between_ranks_like_numpy() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        // np.percentile([1,2,3,4,5], 2.5) = 1 + 0.1 * (2 - 1) = 1.1; 97.5 -> 4.9.
        assert!((percentile(&v, 0.025) - 1.1).abs() < 1e-12);
        assert!((percentile(&v, 0.975) - 4.9).abs() < 1e-12);
        assert_eq!(percentile(&v, 0.5), 3.0);
        assert_eq!(percentile(&v, 0.0), 1.0);
        assert_eq!(percentile(&v, 1.0), 5.0);
        assert_eq!(percentile(&[7.0], 0.975), 7.0);
        assert!(percentile(&[], 0.5).is_nan());
    }

    #[test]
    fn a_one_run_stratum_has_a_zero_width_interval() {
        let scores = [42.0];
        let mut rng = stream(0, "k");
        let ci = percentile_intervals(&[1], 500, &mut rng, mean_of(&scores));
        assert_eq!(
            ci,
            [Interval {
                low: 42.0,
                high: 42.0
            }]
        );
    }

    #[test]
    fn equal_runs_have_a_zero_width_interval_and_the_iqm_theirs() {
        let scores = [3.5; 6];
        let mut rng = stream(7, "k");
        let ci = percentile_intervals(&[6], 200, &mut rng, |idx| {
            let drawn: Vec<f64> = idx[0].iter().map(|&i| scores[i]).collect();
            vec![iqm(&drawn).unwrap()]
        });
        assert_eq!(
            ci,
            [Interval {
                low: 3.5,
                high: 3.5
            }]
        );
    }

    #[test]
    fn the_same_seed_and_key_give_the_same_interval_and_others_differ() {
        let scores: Vec<f64> = (0..10).map(|i| (i * i) as f64).collect();
        let ci = |seed, key| {
            percentile_intervals(&[10], 300, &mut stream(seed, key), mean_of(&scores))[0]
        };
        assert_eq!(ci(0, "a"), ci(0, "a"));
        assert_ne!(ci(0, "a"), ci(1, "a"));
        assert_ne!(ci(0, "a"), ci(0, "b"));
    }

    #[test]
    fn the_interval_brackets_the_mean_of_a_spread_sample() {
        let scores: Vec<f64> = (0..20).map(f64::from).collect();
        let ci = percentile_intervals(&[20], 2000, &mut stream(0, "x"), mean_of(&scores))[0];
        // Mean 9.5, sample sd 5.92, so the standard error is 1.32 and a 95% interval about
        // 9.5 +- 2.6 (the bootstrap's own se is sqrt((n-1)/n) of that).
        assert!(ci.low < 9.5 && 9.5 < ci.high, "{ci:?}");
        assert!(
            (ci.low - 6.9).abs() < 0.5 && (ci.high - 12.1).abs() < 0.5,
            "{ci:?}"
        );
    }

    #[test]
    fn resampling_two_strata_draws_within_each() {
        // Two runs at 0 and two at 100; resampled within each stratum, a stratum's mean is
        // its own, however the draws fall.
        let a = [0.0, 0.0];
        let b = [100.0, 100.0, 100.0];
        let ci = percentile_intervals(&[2, 3], 100, &mut stream(3, "s"), |idx| {
            let ma: Vec<f64> = idx[0].iter().map(|&i| a[i]).collect();
            let mb: Vec<f64> = idx[1].iter().map(|&i| b[i]).collect();
            assert!(idx[0].iter().all(|&i| i < 2) && idx[1].iter().all(|&i| i < 3));
            vec![mean(&ma).unwrap(), mean(&mb).unwrap()]
        });
        assert_eq!(
            ci[0],
            Interval {
                low: 0.0,
                high: 0.0
            }
        );
        assert_eq!(
            ci[1],
            Interval {
                low: 100.0,
                high: 100.0
            }
        );
    }

    #[test]
    fn a_hand_computed_bootstrap_of_two_runs() {
        // Runs {0, 1}: each resample of two draws has mean 0, 0.5 or 1 with probabilities
        // 1/4, 1/2, 1/4. With 4000 resamples the 2.5th percentile sits among the zeros and
        // the 97.5th among the ones.
        let scores = [0.0, 1.0];
        let ci = percentile_intervals(&[2], 4000, &mut stream(0, "two"), mean_of(&scores))[0];
        assert_eq!(
            ci,
            Interval {
                low: 0.0,
                high: 1.0
            }
        );
        // Every index drawn is one of the stratum's.
        let mut rng = stream(0, "two");
        let counts = (0..4000).fold([0usize; 2], |mut c, _| {
            for i in &resample(&[2], &mut rng)[0] {
                c[*i] += 1;
            }
            c
        });
        assert_eq!(counts[0] + counts[1], 8000);
        assert!((counts[0] as f64 / 8000.0 - 0.5).abs() < 0.03, "{counts:?}");
    }

    #[test]
    fn fnv1a_matches_the_reference_vectors() {
        // From the FNV reference: FNV-1a 64 of "" and of "a".
        assert_eq!(fnv1a(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a("a"), 0xaf63_dc4c_8601_ec8c);
    }
}
