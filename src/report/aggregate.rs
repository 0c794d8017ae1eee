//! The rows of `<block>_aggregate.csv`: per method, the IQM, mean, median and (with a known
//! optimum) optimality gap of its runs' final returns, each with a 95% stratified-bootstrap
//! interval, as Gorsane et al. (NeurIPS 2022) ask every cooperative-MARL result to report.

use super::block::{Block, MethodScores};
use super::bootstrap::{percentile_intervals, stream};
use super::scores::{iqm, mean, median, optimality_gap};
use crate::plot::summary::CsvRow;
use serde::Serialize;

/// The aggregate metrics, in the order rows are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// Interquartile mean of the final returns ([`iqm`]).
    Iqm,
    /// Mean of the final returns.
    Mean,
    /// Median of the final returns.
    Median,
    /// Optimality gap of the final returns divided by the optimum ([`optimality_gap`]): a
    /// fraction of the optimum, 0 when every run reaches it.
    OptimalityGap,
}

impl Metric {
    /// Every metric, in row order.
    pub const ALL: [Metric; 4] = [
        Metric::Iqm,
        Metric::Mean,
        Metric::Median,
        Metric::OptimalityGap,
    ];

    /// The name in the CSV's `metric` column.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Iqm => "iqm",
            Metric::Mean => "mean",
            Metric::Median => "median",
            Metric::OptimalityGap => "optimality_gap",
        }
    }

    /// The metric of `scores` (final returns) and, for the gap, of `normalised` (the same
    /// divided by the optimum). `None` without scores, or for the gap without an optimum.
    fn of(self, scores: &[f64], normalised: Option<&[f64]>) -> Option<f64> {
        match self {
            Metric::Iqm => iqm(scores),
            Metric::Mean => mean(scores),
            Metric::Median => median(scores),
            Metric::OptimalityGap => optimality_gap(normalised?),
        }
    }
}

/// One row of `<block>_aggregate.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AggregateRow {
    /// The block (experiment directory).
    pub block: String,
    /// The method (curve directory name).
    pub method: String,
    /// `iqm`, `mean`, `median` or `optimality_gap`.
    pub metric: String,
    /// The metric over the method's scored runs: a return, or for the gap a fraction of the
    /// optimum.
    pub value: f64,
    /// The 95% interval's lower bound (runs resampled with replacement within the block and
    /// method).
    pub ci_low: f64,
    /// Its upper bound.
    pub ci_high: f64,
    /// The runs scored.
    pub n_runs: usize,
}

impl CsvRow for AggregateRow {
    const HEADER: &'static [&'static str] = &[
        "block", "method", "metric", "value", "ci_low", "ci_high", "n_runs",
    ];
}

/// The aggregate rows of every method of `block` with runs: its metrics computed on the same
/// `resamples` resamples of its runs (stream `aggregate/<block>/<method>`). Without a known
/// optimum there are no optimality-gap rows.
pub fn rows(block: &Block, resamples: usize, seed: u64) -> Vec<AggregateRow> {
    block
        .methods
        .iter()
        .filter(|m| !m.scores.is_empty())
        .flat_map(|m| method_rows(&block.name, m, resamples, seed))
        .collect()
}

fn method_rows(block: &str, m: &MethodScores, resamples: usize, seed: u64) -> Vec<AggregateRow> {
    let metrics: Vec<Metric> = Metric::ALL
        .into_iter()
        .filter(|metric| *metric != Metric::OptimalityGap || m.normalised.is_some())
        .collect();
    let values: Vec<f64> = metrics
        .iter()
        .map(|metric| {
            metric
                .of(&m.scores, m.normalised.as_deref())
                .expect("scores are not empty and the gap is asked for only with an optimum")
        })
        .collect();
    let mut rng = stream(seed, &format!("aggregate/{block}/{}", m.curve.name));
    let intervals = percentile_intervals(&[m.scores.len()], resamples, &mut rng, |idx| {
        let drawn: Vec<f64> = idx[0].iter().map(|&i| m.scores[i]).collect();
        let drawn_normalised: Option<Vec<f64>> = m
            .normalised
            .as_ref()
            .map(|n| idx[0].iter().map(|&i| n[i]).collect());
        metrics
            .iter()
            .map(|metric| {
                metric
                    .of(&drawn, drawn_normalised.as_deref())
                    .expect("a resample has as many runs as the method")
            })
            .collect()
    });
    metrics
        .iter()
        .zip(values)
        .zip(intervals)
        .map(|((metric, value), ci)| AggregateRow {
            block: block.to_string(),
            method: m.curve.name.clone(),
            metric: metric.name().to_string(),
            value,
            ci_low: ci.low,
            ci_high: ci.high,
            n_runs: m.scores.len(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::discover::{discover, tests::write_run};
    use crate::report::block::score;

    /// Runs of 10 evaluations whose last (the final return, ceil(10 / 10) = 1) is `last`.
    fn write_scores(root: &std::path::Path, curve: &str, finals: &[f64]) {
        let bp10 = crate::envs::box_pushing::paper_spec(10);
        for (seed, &last) in finals.iter().enumerate() {
            let pts: Vec<(u64, f64)> = (0..10)
                .map(|i| (i * 10, if i == 9 { last } else { 0.0 }))
                .collect();
            write_run(root, "b", curve, seed as u64, &pts, bp10.clone(), true);
        }
    }

    fn value(rows: &[AggregateRow], method: &str, metric: &str) -> AggregateRow {
        rows.iter()
            .find(|r| r.method == method && r.metric == metric)
            .unwrap_or_else(|| panic!("no {method} {metric} in {rows:?}"))
            .clone()
    }

    #[test]
    fn hand_computed_metrics_of_eight_runs() {
        let t = tempfile::tempdir().unwrap();
        let opt = crate::plot::setting::BP10_OPTIMAL;
        // Final returns 1..7 and the optimum itself.
        let finals = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, opt];
        write_scores(t.path(), "our1", &finals);
        let d = discover(t.path()).unwrap();
        let block = score(&d.experiments[0], &mut Vec::new());
        let rows = rows(&block, 500, 0);
        assert_eq!(rows.len(), 4);
        assert_eq!(
            rows.iter().map(|r| r.metric.as_str()).collect::<Vec<_>>(),
            ["iqm", "mean", "median", "optimality_gap"]
        );
        // IQM: 2 cut each end, (3 + 4 + 5 + 6) / 4.
        assert_eq!(value(&rows, "our1", "iqm").value, 4.5);
        assert_eq!(value(&rows, "our1", "median").value, 4.5);
        let mean = value(&rows, "our1", "mean");
        assert!((mean.value - (28.0 + opt) / 8.0).abs() < 1e-12);
        assert_eq!(mean.n_runs, 8);
        // Gap: seven runs short by 1 - k / opt, the optimal one by nothing.
        let gap = value(&rows, "our1", "optimality_gap");
        let expected = (1..=7).map(|k| 1.0 - k as f64 / opt).sum::<f64>() / 8.0;
        assert!((gap.value - expected).abs() < 1e-12, "{gap:?}");
        for r in &rows {
            assert!(r.ci_low <= r.value && r.value <= r.ci_high, "{r:?}");
            assert!(r.ci_low < r.ci_high, "eight distinct runs spread: {r:?}");
        }
    }

    #[test]
    fn one_run_gives_zero_width_intervals_and_the_seed_moves_the_others() {
        let t = tempfile::tempdir().unwrap();
        write_scores(t.path(), "our1", &[42.0]);
        write_scores(t.path(), "our2", &[1.0, 5.0, 9.0, 20.0, 30.0]);
        let d = discover(t.path()).unwrap();
        let block = score(&d.experiments[0], &mut Vec::new());
        let a = rows(&block, 400, 0);
        let one = value(&a, "our1", "iqm");
        assert_eq!((one.value, one.ci_low, one.ci_high), (42.0, 42.0, 42.0));
        assert_eq!(a, rows(&block, 400, 0), "the same seed, the same numbers");
        let b = rows(&block, 400, 1);
        assert_ne!(value(&a, "our2", "mean"), value(&b, "our2", "mean"));
        assert_eq!(
            value(&a, "our2", "mean").value,
            value(&b, "our2", "mean").value
        );
    }

    #[test]
    fn the_header_lists_the_serialized_fields_in_order() {
        let row = AggregateRow {
            block: "b".into(),
            method: "m".into(),
            metric: "iqm".into(),
            value: 1.5,
            ci_low: 1.0,
            ci_high: 2.0,
            n_runs: 3,
        };
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(&row).unwrap();
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        assert_eq!(
            text,
            "block,method,metric,value,ci_low,ci_high,n_runs\nb,m,iqm,1.5,1.0,2.0,3\n"
        );
        assert_eq!(AggregateRow::HEADER.join(","), text.lines().next().unwrap());
    }
}
