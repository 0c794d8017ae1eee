//! Putting a method's runs on shared x positions, so a statistic across runs can be taken
//! point by point (the sample-efficiency curves) and every run exports the same steps
//! (marl-eval needs as many logged steps in every run).

use crate::curve_stats::interpolate;

/// The most points a curve is drawn with: enough for a smooth line, and a bound on the
/// bootstrap's work per curve (resamples x points x runs).
pub const CURVE_POINTS: usize = 101;

/// `k` indices into `0..n`, evenly spaced and rounded to the nearest, always the first and
/// the last: a run's evaluations thinned to `k` without favouring any stage of training.
/// All of `0..n` when `k >= n`; none when either is 0.
pub fn even_indices(n: usize, k: usize) -> Vec<usize> {
    match (n, k) {
        (0, _) | (_, 0) => Vec::new(),
        (n, k) if k >= n => (0..n).collect(),
        (_, 1) => vec![0],
        // Round i (n - 1) / (k - 1) to the nearest, in integers.
        (n, k) => (0..k)
            .map(|i| (i * (n - 1) + (k - 1) / 2) / (k - 1))
            .collect(),
    }
}

/// Runs' values at shared x positions.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// The x positions, ascending.
    pub x: Vec<f64>,
    /// `values[run][point]`: each run's value at each x.
    pub values: Vec<Vec<f64>>,
    /// Whether values were interpolated (the runs were evaluated at different x).
    pub interpolated: bool,
}

/// Put `runs` (each a list of `(x, value)` with x non-decreasing) on shared x positions. When
/// every run was evaluated at the same x (episodes, in every committed tree), those x, thinned
/// to [`CURVE_POINTS`] by [`even_indices`], with the runs' own values. Otherwise (environment
/// steps differ from run to run) [`CURVE_POINTS`] evenly spaced x over the range every run
/// covers, each run linearly interpolated between its neighbouring evaluations. `None` for no
/// runs, an empty run, or runs whose ranges do not overlap.
pub fn common_grid(runs: &[Vec<(f64, f64)>]) -> Option<Grid> {
    let first = runs.first()?;
    if runs.iter().any(Vec::is_empty) {
        return None;
    }
    let same_x = runs
        .iter()
        .all(|r| r.len() == first.len() && r.iter().zip(first).all(|(a, b)| a.0 == b.0));
    if same_x {
        let keep = even_indices(first.len(), CURVE_POINTS);
        return Some(Grid {
            x: keep.iter().map(|&i| first[i].0).collect(),
            values: runs
                .iter()
                .map(|r| keep.iter().map(|&i| r[i].1).collect())
                .collect(),
            interpolated: false,
        });
    }
    let lo = runs
        .iter()
        .map(|r| r[0].0)
        .fold(f64::NEG_INFINITY, f64::max);
    let hi = runs
        .iter()
        .map(|r| r[r.len() - 1].0)
        .fold(f64::INFINITY, f64::min);
    if lo > hi {
        return None;
    }
    let x: Vec<f64> = (0..CURVE_POINTS)
        .map(|i| lo + (hi - lo) * i as f64 / (CURVE_POINTS - 1) as f64)
        .collect();
    let values = runs
        .iter()
        .map(|r| x.iter().map(|&at| interpolate(r, at)).collect())
        .collect();
    Some(Grid {
        x,
        values,
        interpolated: true,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn even_indices_keep_the_ends_and_spread_the_rest() {
        assert_eq!(even_indices(5, 3), [0, 2, 4]);
        // 417 evaluations thinned to 400 (bp6's Mac-IAC against Mac-CAC): ends kept.
        let idx = even_indices(417, 400);
        assert_eq!((idx.len(), idx[0], idx[399]), (400, 0, 416));
        assert!(idx.windows(2).all(|w| w[0] < w[1] && w[1] - w[0] <= 2));
        // 0, 9 x 1/3 = 3, 6, 9: exact thirds.
        assert_eq!(even_indices(10, 4), [0, 3, 6, 9]);
        // 0, 2.5 -> 3 (half rounds up), 5.
        assert_eq!(even_indices(6, 3), [0, 3, 5]);
        assert_eq!(even_indices(3, 10), [0, 1, 2]);
        assert_eq!(even_indices(7, 1), [0]);
        assert!(even_indices(0, 3).is_empty() && even_indices(3, 0).is_empty());
    }

    #[test]
    fn runs_on_the_same_x_keep_their_values() {
        let a = vec![(0.0, 1.0), (10.0, 2.0), (20.0, 3.0)];
        let b = vec![(0.0, 5.0), (10.0, 6.0), (20.0, 7.0)];
        let g = common_grid(&[a, b]).unwrap();
        assert_eq!(g.x, [0.0, 10.0, 20.0]);
        assert_eq!(g.values, [vec![1.0, 2.0, 3.0], vec![5.0, 6.0, 7.0]]);
        assert!(!g.interpolated);
    }

    #[test]
    fn long_runs_on_the_same_x_are_thinned_to_the_curve_points() {
        let run: Vec<(f64, f64)> = (0..1001).map(|i| (i as f64, 2.0 * i as f64)).collect();
        let g = common_grid(&[run.clone(), run]).unwrap();
        assert_eq!(g.x.len(), CURVE_POINTS);
        assert_eq!((g.x[0], g.x[1], g.x[100]), (0.0, 10.0, 1000.0));
        assert_eq!(g.values[1][1], 20.0);
    }

    #[test]
    fn runs_on_different_x_are_interpolated_over_their_shared_range() {
        // a covers 0..=100, b 50..=200: the shared range is 50..=100.
        let a = vec![(0.0, 0.0), (100.0, 100.0)];
        let b = vec![(50.0, 10.0), (150.0, 30.0), (200.0, 0.0)];
        let g = common_grid(&[a, b]).unwrap();
        assert!(g.interpolated);
        assert_eq!(g.x.len(), CURVE_POINTS);
        assert_eq!((g.x[0], g.x[100]), (50.0, 100.0));
        // x = 75 (point 50): a on its line, 75; b a quarter of the way from 10 to 30, 15.
        assert_eq!(g.x[50], 75.0);
        assert_eq!(g.values[0][50], 75.0);
        assert_eq!(g.values[1][50], 15.0);
        assert_eq!(g.values[1][0], 10.0);
    }

    #[test]
    fn disjoint_or_empty_runs_have_no_grid() {
        let a = vec![(0.0, 0.0), (10.0, 1.0)];
        let b = vec![(20.0, 0.0), (30.0, 1.0)];
        assert_eq!(common_grid(&[a.clone(), b]), None);
        assert_eq!(common_grid(&[a, Vec::new()]), None);
        assert_eq!(common_grid(&[]), None);
    }
}
