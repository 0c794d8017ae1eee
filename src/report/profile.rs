//! Performance profiles (rliable, Agarwal et al. 2021, §4.2; Dolan and Moré 2002): for every
//! threshold tau, the fraction of a method's runs scoring above it. The whole distribution of
//! run scores at a glance: a curve above another everywhere dominates it stochastically.

use super::bootstrap::{percentile_intervals, stream, Interval};

/// Thresholds per profile.
pub const PROFILE_POINTS: usize = 101;

/// The fraction of `scores` strictly above each of `taus` (rliable's run-score distribution,
/// `score > tau`). Empty scores give 0 everywhere.
pub fn fraction_above(scores: &[f64], taus: &[f64]) -> Vec<f64> {
    let n = scores.len().max(1) as f64;
    taus.iter()
        .map(|&tau| scores.iter().filter(|&&s| s > tau).count() as f64 / n)
        .collect()
}

/// The thresholds one block's profiles share: [`PROFILE_POINTS`] evenly spaced over every
/// score of every method, widened to take in 0 and 1 when scores are normalised by the
/// optimum (so the figure always shows where runs reach it). A single score value is padded
/// by 1 each side so the profile still falls from 1 to 0.
pub fn taus(all_scores: &[f64], normalised: bool) -> Vec<f64> {
    let mut lo = all_scores.iter().copied().fold(f64::INFINITY, f64::min);
    let mut hi = all_scores.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if normalised {
        lo = lo.min(0.0);
        hi = hi.max(1.0);
    }
    if !lo.is_finite() || !hi.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    if lo == hi {
        (lo, hi) = (lo - 1.0, hi + 1.0);
    }
    (0..PROFILE_POINTS)
        .map(|i| lo + (hi - lo) * i as f64 / (PROFILE_POINTS - 1) as f64)
        .collect()
}

/// One method's profile: the fraction of its runs above each threshold, and the interval of
/// each fraction over resampled runs (stream `profile/<block>/<method>`).
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// The fraction above each threshold.
    pub fractions: Vec<f64>,
    /// Its 95% interval, threshold by threshold.
    pub intervals: Vec<Interval>,
}

/// The profile of `scores` over `taus` with bootstrap bands.
pub fn profile(
    block: &str,
    method: &str,
    scores: &[f64],
    taus: &[f64],
    resamples: usize,
    seed: u64,
) -> Profile {
    let mut rng = stream(seed, &format!("profile/{block}/{method}"));
    let intervals = percentile_intervals(&[scores.len()], resamples, &mut rng, |idx| {
        let drawn: Vec<f64> = idx[0].iter().map(|&i| scores[i]).collect();
        fraction_above(&drawn, taus)
    });
    Profile {
        fractions: fraction_above(scores, taus),
        intervals,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fraction_counts_runs_strictly_above() {
        let scores = [0.2, 0.5, 0.5, 1.0];
        assert_eq!(
            fraction_above(&scores, &[0.0, 0.2, 0.5, 0.9, 1.0]),
            [1.0, 0.75, 0.25, 0.25, 0.0]
        );
        assert_eq!(fraction_above(&[], &[0.0]), [0.0]);
    }

    #[test]
    fn normalised_thresholds_take_in_zero_and_one() {
        let t = taus(&[0.3, 0.6], true);
        assert_eq!((t.len(), t[0], t[100]), (PROFILE_POINTS, 0.0, 1.0));
        let t = taus(&[-0.5, 1.5], true);
        assert_eq!((t[0], t[100]), (-0.5, 1.5));
        // Raw returns span their own range; one value is padded.
        let t = taus(&[10.0, 30.0], false);
        assert_eq!((t[0], t[50], t[100]), (10.0, 20.0, 30.0));
        let t = taus(&[5.0], false);
        assert_eq!((t[0], t[100]), (4.0, 6.0));
    }

    #[test]
    fn a_profile_band_is_zero_wide_where_every_resample_agrees() {
        // Below every score all resamples give 1, above every score 0.
        let scores = [1.0, 2.0, 3.0, 4.0];
        let p = profile("b", "m", &scores, &[0.0, 2.5, 9.0], 500, 0);
        assert_eq!(p.fractions, [1.0, 0.5, 0.0]);
        assert_eq!(
            p.intervals[0],
            Interval {
                low: 1.0,
                high: 1.0
            }
        );
        assert_eq!(
            p.intervals[2],
            Interval {
                low: 0.0,
                high: 0.0
            }
        );
        let mid = p.intervals[1];
        assert!(mid.low < 0.5 && 0.5 < mid.high, "{mid:?}");
    }
}
