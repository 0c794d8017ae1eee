//! A terminal summary of learning curves after `macdec train`: mean greedy return over seeds at
//! evenly spaced evaluation points, with a bar per point.

use crate::experiment::config::RunSpec;
use crate::experiment::metrics::{self, METRICS_FILE};
use std::collections::BTreeMap;
use std::path::Path;

/// Rows printed per curve.
const POINTS: usize = 12;

/// Mean eval return over runs at each evaluation index both runs have. `curves`: one metrics
/// series (episode, return) per seed.
pub fn mean_curve(curves: &[Vec<(u64, f64)>]) -> Vec<(u64, f64, usize)> {
    let len = curves.iter().map(Vec::len).max().unwrap_or(0);
    (0..len)
        .map(|i| {
            let present: Vec<&(u64, f64)> = curves.iter().filter_map(|c| c.get(i)).collect();
            let mean = present.iter().map(|p| p.1).sum::<f64>() / present.len() as f64;
            (present[0].0, mean, present.len())
        })
        .collect()
}

/// Print each curve of `runs` found under `results` as a small table with bars.
pub fn print_curves(results: &Path, runs: &[RunSpec]) -> Result<(), metrics::MetricsError> {
    let mut by_curve: BTreeMap<String, Vec<Vec<(u64, f64)>>> = BTreeMap::new();
    for run in runs {
        let path = run.dir(results).join(METRICS_FILE);
        if !path.exists() {
            continue;
        }
        let rows = metrics::read(&path)?;
        by_curve
            .entry(format!("{}/{}", run.experiment, run.curve_name()))
            .or_default()
            .push(rows.iter().map(|r| (r.episode, r.eval_return)).collect());
    }
    for (name, curves) in by_curve {
        let mean = mean_curve(&curves);
        if mean.is_empty() {
            continue;
        }
        let lo = mean.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
        let hi = mean.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
        println!("\n{name}: mean greedy return over {} seed(s)", curves.len());
        println!("{:>9}  {:>9}  ", "episode", "return");
        let stride = mean.len().div_ceil(POINTS).max(1);
        let picks = (0..mean.len())
            .step_by(stride)
            .chain(std::iter::once(mean.len() - 1));
        let mut last = usize::MAX;
        for i in picks {
            if i == last {
                continue;
            }
            last = i;
            let (episode, ret, _) = mean[i];
            let width = if hi > lo {
                ((ret - lo) / (hi - lo) * 40.0).round() as usize
            } else {
                0
            };
            println!("{episode:>9}  {ret:>9.2}  {}", "#".repeat(width));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_curve_averages_the_runs_present_at_each_point() {
        let a = vec![(0, 1.0), (10, 3.0), (20, 5.0)];
        let b = vec![(0, 3.0), (10, 5.0)];
        assert_eq!(
            mean_curve(&[a, b]),
            vec![(0, 2.0, 2), (10, 4.0, 2), (20, 5.0, 1)]
        );
    }
}
