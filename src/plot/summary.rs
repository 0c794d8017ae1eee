//! The numbers a reader wants beside a figure: per curve, how many seeds, how many finished, where
//! the smoothed curve ends, and how long a run took. Written as `<experiment>_summary.csv` and
//! printed as a Markdown table for the README.

use super::error::PlotError;
use serde::Serialize;
use std::path::Path;

/// One row of the summary: one curve of one experiment.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurveSummary {
    /// The curve's directory name (`our1`, `our1@trace_len=10`).
    pub curve: String,
    /// The paper's legend name (with the sweep point).
    pub legend: String,
    /// Runs found (seeds).
    pub seeds: usize,
    /// Runs with a `finished` marker.
    pub finished: usize,
    /// The last evaluation episode of the curve (over all runs).
    pub final_episode: u64,
    /// The smoothed mean at the last evaluation point (spec 7.2 smoothing, truncated window).
    pub final_mean: f64,
    /// The smoothed standard error at the last evaluation point.
    pub final_se: f64,
    /// Runs that reach the last evaluation point (less than `seeds` when some are unfinished).
    pub final_n: usize,
    /// The optimal return drawn as the reference line, if known.
    pub optimal: Option<f64>,
    /// Mean wall-clock minutes of the finished runs (None when none finished).
    pub run_minutes: Option<f64>,
}

/// Write the summary rows as CSV to `path` (atomically).
pub fn write_csv(path: &Path, rows: &[CurveSummary]) -> Result<(), PlotError> {
    let write_err = |source| PlotError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)
            .map_err(|e| write_err(std::io::Error::other(e)))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| write_err(std::io::Error::other(e.to_string())))?;
    crate::experiment::atomic::write_atomic(path, &bytes).map_err(write_err)
}

/// A Markdown table of one experiment's curves, headed by its title:
/// final return as mean ± SE beside the optimal return.
pub fn markdown_table(title: &str, rows: &[CurveSummary]) -> String {
    let mut s = format!(
        "### {title}\n\n| method | seeds (finished) | final episode | final return (mean ± SE) | optimal | minutes per run |\n|---|---|---|---|---|---|\n"
    );
    for r in rows {
        let optimal = r.optimal.map_or("n/a".into(), format_return);
        let minutes = r.run_minutes.map_or("n/a".into(), |m| format!("{m:.1}"));
        let at = if r.final_n < r.seeds {
            format!(" (n = {} at the end)", r.final_n)
        } else {
            String::new()
        };
        s.push_str(&format!(
            "| {} | {} ({}) | {} | {:.2} ± {:.2}{at} | {optimal} | {minutes} |\n",
            r.legend, r.seeds, r.finished, r.final_episode, r.final_mean, r.final_se
        ));
    }
    s
}

/// A return for display: whole numbers without decimals (262), others with two (80.71).
pub fn format_return(v: f64) -> String {
    if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v:.2}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row() -> CurveSummary {
        CurveSummary {
            curve: "our1".into(),
            legend: "Our-1".into(),
            seeds: 3,
            finished: 2,
            final_episode: 1500,
            final_mean: 78.456,
            final_se: 1.234,
            final_n: 2,
            optimal: Some(80.71093744250365),
            run_minutes: Some(12.34),
        }
    }

    #[test]
    fn markdown_row_shows_mean_se_optimal_and_partial_counts() {
        let md = markdown_table("fig4a", &[row()]);
        assert!(md.starts_with("### fig4a\n"));
        assert!(
            md.contains(
                "| Our-1 | 3 (2) | 1500 | 78.46 ± 1.23 (n = 2 at the end) | 80.71 | 12.3 |"
            ),
            "{md}"
        );
    }

    #[test]
    fn csv_has_a_header_and_empty_fields_for_unknowns() {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("s.csv");
        let mut r = row();
        r.optimal = None;
        r.run_minutes = None;
        write_csv(&p, &[r]).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(
            text,
            "curve,legend,seeds,finished,final_episode,final_mean,final_se,final_n,optimal,run_minutes\n\
             our1,Our-1,3,2,1500,78.456,1.234,2,,\n"
        );
    }

    #[test]
    fn whole_returns_print_without_decimals() {
        assert_eq!(format_return(262.0), "262");
        assert_eq!(format_return(41.75397237445474), "41.75");
    }
}
