//! The probability of improvement of rliable (Agarwal et al. 2021, §4.3): how likely a run of
//! method X scores above a run of method Y, a comparison that says nothing about by how much
//! and so is not swayed by a few extreme runs.

use super::bootstrap::{percentile_intervals, stream};
use crate::plot::summary::CsvRow;
use serde::Serialize;

/// P(X > Y): over every pair of an X run and a Y run, 1 when X's score is higher, 1/2 on a
/// tie, 0 otherwise, averaged (the Mann-Whitney U statistic over n m, as rliable's
/// `probability_of_improvement` computes it per task). `None` when either has no runs.
pub fn probability_of_improvement(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.is_empty() || y.is_empty() {
        return None;
    }
    let wins: f64 = x
        .iter()
        .flat_map(|a| y.iter().map(move |b| (a, b)))
        .map(|(a, b)| match a.partial_cmp(b) {
            Some(std::cmp::Ordering::Greater) => 1.0,
            Some(std::cmp::Ordering::Equal) => 0.5,
            _ => 0.0,
        })
        .sum();
    Some(wins / (x.len() * y.len()) as f64)
}

/// One row of `<block>_improvement.csv`: P(method_x > method_y) with its 95% interval.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImprovementRow {
    /// The method whose runs should score higher (its directory name).
    pub method_x: String,
    /// The method it is compared with.
    pub method_y: String,
    /// P(X > Y) over the runs found.
    pub probability: f64,
    /// The interval's lower bound: X's and Y's runs resampled independently (rliable's
    /// `StratifiedIndependentBootstrap`).
    pub ci_low: f64,
    /// The interval's upper bound.
    pub ci_high: f64,
}

impl CsvRow for ImprovementRow {
    const HEADER: &'static [&'static str] =
        &["method_x", "method_y", "probability", "ci_low", "ci_high"];
}

/// P(X > Y) with its interval for every ordered pair of distinct methods that both have runs,
/// in the order given. `methods` holds each method's name and scores; the interval of a pair
/// draws from the stream `improvement/<block>/<x>/<y>`.
pub fn pairwise(
    block: &str,
    methods: &[(String, Vec<f64>)],
    resamples: usize,
    seed: u64,
) -> Vec<ImprovementRow> {
    let mut rows = Vec::new();
    for (x_name, x) in methods {
        for (y_name, y) in methods {
            if x_name == y_name {
                continue;
            }
            let Some(probability) = probability_of_improvement(x, y) else {
                continue;
            };
            let mut rng = stream(seed, &format!("improvement/{block}/{x_name}/{y_name}"));
            let ci = percentile_intervals(&[x.len(), y.len()], resamples, &mut rng, |idx| {
                let xs: Vec<f64> = idx[0].iter().map(|&i| x[i]).collect();
                let ys: Vec<f64> = idx[1].iter().map(|&i| y[i]).collect();
                vec![probability_of_improvement(&xs, &ys).expect("both resamples have runs")]
            })[0];
            rows.push(ImprovementRow {
                method_x: x_name.clone(),
                method_y: y_name.clone(),
                probability,
                ci_low: ci.low,
                ci_high: ci.high,
            });
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_count_half_and_wins_whole() {
        // Pairs (x, y): (1,0) win, (1,1) tie, (1,2) loss, (3,0) (3,1) (3,2) wins: 4.5 / 6.
        assert_eq!(
            probability_of_improvement(&[1.0, 3.0], &[0.0, 1.0, 2.0]),
            Some(4.5 / 6.0)
        );
        assert_eq!(probability_of_improvement(&[5.0], &[5.0]), Some(0.5));
        assert_eq!(probability_of_improvement(&[], &[1.0]), None);
    }

    #[test]
    fn the_two_directions_add_up_to_one() {
        let x = [1.0, 4.0, 4.0, 9.0];
        let y = [2.0, 4.0, 8.0];
        let p = probability_of_improvement(&x, &y).unwrap();
        let q = probability_of_improvement(&y, &x).unwrap();
        assert!((p + q - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_method_above_every_run_of_another_has_probability_one_with_no_spread() {
        let methods = vec![
            ("a".to_string(), vec![10.0, 11.0, 12.0]),
            ("b".to_string(), vec![0.0, 1.0]),
        ];
        let rows = pairwise("blk", &methods, 200, 0);
        assert_eq!(rows.len(), 2);
        assert_eq!(
            (rows[0].method_x.as_str(), rows[0].method_y.as_str()),
            ("a", "b")
        );
        assert_eq!(
            (rows[0].probability, rows[0].ci_low, rows[0].ci_high),
            (1.0, 1.0, 1.0)
        );
        assert_eq!(
            (rows[1].probability, rows[1].ci_low, rows[1].ci_high),
            (0.0, 0.0, 0.0)
        );
    }

    #[test]
    fn overlapping_methods_get_an_interval_around_their_probability() {
        let methods = vec![
            ("a".to_string(), (0..10).map(f64::from).collect()),
            ("b".to_string(), (3..13).map(f64::from).collect()),
        ];
        let rows = pairwise("blk", &methods, 1000, 0);
        let r = &rows[0];
        // a > b: a run at v beats the b runs 3..v-1, so 1 + 2 + ... + 6 = 21 of 100 pairs win;
        // 7 values are shared, 7 ties: (21 + 3.5) / 100.
        assert_eq!(r.probability, 0.245);
        assert!(
            r.ci_low < r.probability && r.probability < r.ci_high,
            "{r:?}"
        );
        assert!(r.ci_low > 0.0 && r.ci_high < 0.6, "{r:?}");
    }
}
