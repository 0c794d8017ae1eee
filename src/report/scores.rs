//! The point estimates of rliable (Agarwal et al., *Deep Reinforcement Learning at the Edge of
//! the Statistical Precipice*, NeurIPS 2021) that Gorsane et al. (NeurIPS 2022) adopt for
//! cooperative MARL: interquartile mean, mean, median and optimality gap of a set of run
//! scores. Pure functions on numbers; `report::aggregate` applies them to a block's runs and
//! `report::bootstrap` to resamples of them.

/// The interquartile mean: the mean of the middle half of the scores, robust to a few
/// outlying runs yet using more of them than the median. Exactly rliable's
/// `scipy.stats.trim_mean(scores, proportiontocut=0.25)`: sort, drop `int(0.25 n)` scores
/// from each end (so nothing is dropped below 4 runs, and a fractional quarter is rounded
/// down, never interpolated), average the rest. `None` for no scores.
pub fn iqm(scores: &[f64]) -> Option<f64> {
    let sorted = sorted(scores);
    // int(0.25 * n) in scipy; 0.25 * n is exact in f64 for any realistic n, so it is n / 4.
    let cut = sorted.len() / 4;
    mean(&sorted[cut..sorted.len() - cut])
}

/// The arithmetic mean; `None` for no scores.
pub fn mean(scores: &[f64]) -> Option<f64> {
    (!scores.is_empty()).then(|| scores.iter().sum::<f64>() / scores.len() as f64)
}

/// The median as numpy computes it: the middle score, or the mean of the two middle ones for
/// an even count. `None` for no scores.
pub fn median(scores: &[f64]) -> Option<f64> {
    let sorted = sorted(scores);
    let n = sorted.len();
    match n {
        0 => None,
        n if n % 2 == 1 => Some(sorted[n / 2]),
        n => Some((sorted[n / 2 - 1] + sorted[n / 2]) / 2.0),
    }
}

/// The optimality gap of scores normalised by the optimum (score / optimum): how far, on
/// average, runs fall short of optimal, counting a run above it as no shortfall, so a method
/// cannot make up for failed runs with lucky ones. rliable's `aggregate_optimality_gap` with
/// gamma = 1: mean over runs of max(0, 1 - normalised score). `None` for no scores.
pub fn optimality_gap(normalised: &[f64]) -> Option<f64> {
    let shortfalls: Vec<f64> = normalised.iter().map(|s| (1.0 - s).max(0.0)).collect();
    mean(&shortfalls)
}

/// The scores in ascending order (a total order, so a NaN cannot make the sort panic).
pub fn sorted(scores: &[f64]) -> Vec<f64> {
    let mut sorted = scores.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one_to(n: u32) -> Vec<f64> {
        (1..=n).map(f64::from).collect()
    }

    #[test]
    fn iqm_of_one_to_eight_is_the_mean_of_three_to_six() {
        // n = 8: int(0.25 * 8) = 2 cut from each end, (3 + 4 + 5 + 6) / 4 = 4.5.
        assert_eq!(iqm(&one_to(8)), Some(4.5));
        // Order does not matter.
        assert_eq!(iqm(&[8.0, 1.0, 7.0, 2.0, 6.0, 3.0, 5.0, 4.0]), Some(4.5));
    }

    #[test]
    fn iqm_rounds_the_quarter_down_as_trim_mean_does() {
        // n = 5: int(1.25) = 1 cut each end, (2 + 3 + 4) / 3 = 3.
        assert_eq!(iqm(&[1.0, 2.0, 3.0, 4.0, 100.0]), Some(3.0));
        // n = 7: int(1.75) = 1, not 2: (2 + 3 + 4 + 5 + 6) / 5 = 4.
        assert_eq!(iqm(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 1000.0]), Some(4.0));
        // n = 10: int(2.5) = 2, (3 + ... + 8) / 6 = 5.5.
        assert_eq!(iqm(&one_to(10)), Some(5.5));
        // Below four runs nothing is cut: the IQM is the mean.
        assert_eq!(iqm(&[1.0, 2.0, 30.0]), Some(11.0));
        assert_eq!(iqm(&[7.0]), Some(7.0));
        assert_eq!(iqm(&[]), None);
    }

    #[test]
    fn iqm_ignores_an_outlier_the_mean_does_not() {
        let scores = [10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 1e6];
        // Cut 2 each end: (12 + 13 + 14 + 15) / 4 = 13.5.
        assert_eq!(iqm(&scores), Some(13.5));
        assert!(mean(&scores).unwrap() > 1e5);
    }

    #[test]
    fn median_takes_the_middle_or_the_mean_of_the_two_middles() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        assert_eq!(mean(&[1.0, 2.0, 6.0]), Some(3.0));
        assert_eq!(mean(&[]), None);
    }

    #[test]
    fn optimality_gap_counts_shortfalls_only() {
        // Shortfalls 1 - 0.5 = 0.5, 1 - 1 = 0, none above 1: (0.5 + 0 + 0) / 3.
        assert_eq!(optimality_gap(&[0.5, 1.0, 1.5]), Some(0.5 / 3.0));
        // A negative normalised score is more than the whole optimum short.
        assert_eq!(optimality_gap(&[-1.0]), Some(2.0));
        assert_eq!(optimality_gap(&[]), None);
    }
}
