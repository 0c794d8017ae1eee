//! A terminal summary of learning curves after `macdec train`: mean evaluation return over seeds
//! (greedy for the value methods, sampled for the actor-critic ones) at evenly spaced evaluation
//! points, with a bar per point.

use crate::curve_stats::aggregate;
use crate::experiment::definition::config::RunSpec;
use crate::experiment::run::metrics;
use std::collections::BTreeMap;
use std::path::Path;

/// Rows printed per curve.
const POINTS: usize = 12;

/// Print each curve of `runs` found under `results` as a small table with bars.
pub fn print_curves(results: &Path, runs: &[RunSpec]) -> Result<(), metrics::MetricsError> {
    let mut by_curve: BTreeMap<String, Vec<Vec<(u64, f64)>>> = BTreeMap::new();
    for run in runs {
        let Some(path) = metrics::locate(&run.dir(results)) else {
            continue;
        };
        let rows = metrics::read(&path)?.rows;
        by_curve
            .entry(format!("{}/{}", run.experiment, run.curve_name()))
            .or_default()
            .push(rows.iter().map(|r| (r.episode, r.eval_return)).collect());
    }
    for (name, curves) in by_curve {
        let runs: Vec<&[(u64, f64)]> = curves.iter().map(Vec::as_slice).collect();
        let mean = aggregate(&runs);
        if mean.is_empty() {
            continue;
        }
        let lo = mean.iter().map(|p| p.mean).fold(f64::INFINITY, f64::min);
        let hi = mean
            .iter()
            .map(|p| p.mean)
            .fold(f64::NEG_INFINITY, f64::max);
        println!(
            "\n{name}: mean evaluation return (eval_return) over {} seed(s)",
            curves.len()
        );
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
            let (episode, ret) = (mean[i].episode, mean[i].mean);
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
