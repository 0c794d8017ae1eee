//! The numbers a reader wants beside a figure: per curve, how many seeds, how many finished, where
//! the smoothed curve ends, and how long a run took. Written as `<experiment>_summary.csv` and
//! printed as a Markdown table for the README.

use super::error::PlotError;
use super::welch::welch_greater;
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
    /// Mean over the `final_n` runs of their final returns (the mean of a run's last 10% of
    /// evaluations, [`crate::plot::stats::final_return`]).
    pub final_mean: f64,
    /// Standard error (ddof 1) of that mean; 0 for one run.
    pub final_se: f64,
    /// Runs that reach the last evaluation episode, over which the final return is taken
    /// (less than `seeds` when some are unfinished).
    pub final_n: usize,
    /// The first episode at which the smoothed mean curve (the one drawn, `smoothing_points`
    /// wide) reaches 95% of the optimal return (empty if it never does or the optimum is
    /// unknown).
    pub reach95_episode: Option<u64>,
    /// Area under the (unsmoothed) mean curve over its episode span: its average height.
    pub mean_over_training: f64,
    /// The optimal return drawn as the reference line, if known.
    pub optimal: Option<f64>,
    /// Mean wall-clock minutes of the finished runs (None when none finished).
    pub run_minutes: Option<f64>,
    /// (Last, so the earlier columns keep their places.) Mean over the `final_n` runs of each run's best single evaluation
    /// ([`crate::plot::stats::best_return`]): the level of a best-snapshot policy, the kind the
    /// reference saves and its authors ship.
    pub best_mean: f64,
    /// (After `best_mean`, for the same reason.) The centred moving average's window in
    /// evaluation points of the drawn curve that `reach95_episode` reads; 1 = not smoothed.
    pub smoothing_points: usize,
    /// The `final_n` runs' final returns, for the tests between curves.
    #[serde(skip)]
    pub final_returns: Vec<f64>,
    /// The same runs' own means over training
    /// ([`crate::curve_stats::run_mean_over_training`]), for the tests of which curve learns
    /// earlier.
    #[serde(skip)]
    pub training_means: Vec<f64>,
}

/// One-sided Welch t-tests between two curves, H1 "A above B": on the runs' final returns (the
/// first three numbers) and on their means over training (the `_over_training` ones: which
/// curve learns earlier, per seed rather than from the mean curve).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairTest {
    /// Curve A, the one H1 says is higher.
    pub curve_a: String,
    /// Curve B.
    pub curve_b: String,
    /// Welch's t on the final returns.
    pub t: f64,
    /// Welch-Satterthwaite degrees of freedom, final returns.
    pub df: f64,
    /// One-sided p-value of "A above B", final returns.
    pub p_a_greater: f64,
    /// Welch's t on the means over training.
    pub t_over_training: f64,
    /// Degrees of freedom, means over training.
    pub df_over_training: f64,
    /// One-sided p-value of "A above B", means over training.
    pub p_a_greater_over_training: f64,
}

/// Every ordered pair of curves that can be tested (two or more runs each).
pub fn pairwise_tests(rows: &[CurveSummary]) -> Vec<PairTest> {
    let mut tests = Vec::new();
    for a in rows {
        for b in rows {
            if a.curve == b.curve {
                continue;
            }
            let finals = welch_greater(&a.final_returns, &b.final_returns);
            let training = welch_greater(&a.training_means, &b.training_means);
            if let (Some(w), Some(v)) = (finals, training) {
                tests.push(PairTest {
                    curve_a: a.curve.clone(),
                    curve_b: b.curve.clone(),
                    t: w.t,
                    df: w.df,
                    p_a_greater: w.p_greater,
                    t_over_training: v.t,
                    df_over_training: v.df,
                    p_a_greater_over_training: v.p_greater,
                });
            }
        }
    }
    tests
}

/// A row type of a CSV file plot writes: its column names, so a file with no rows (an
/// experiment with one curve has no Welch tests) still has its header.
pub trait CsvRow: Serialize {
    /// The columns, in the order serde writes the fields (checked by the tests).
    const HEADER: &'static [&'static str];
}

impl CsvRow for CurveSummary {
    const HEADER: &'static [&'static str] = &[
        "curve",
        "legend",
        "seeds",
        "finished",
        "final_episode",
        "final_mean",
        "final_se",
        "final_n",
        "reach95_episode",
        "mean_over_training",
        "optimal",
        "run_minutes",
        "best_mean",
        "smoothing_points",
    ];
}

impl CsvRow for PairTest {
    const HEADER: &'static [&'static str] = &[
        "curve_a",
        "curve_b",
        "t",
        "df",
        "p_a_greater",
        "t_over_training",
        "df_over_training",
        "p_a_greater_over_training",
    ];
}

/// Write `rows` as CSV to `path` (atomically), header first, also when there are no rows.
pub fn write_csv<T: CsvRow>(path: &Path, rows: &[T]) -> Result<(), PlotError> {
    let write_err = |source| PlotError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    w.write_record(T::HEADER)
        .map_err(|e| write_err(std::io::Error::other(e)))?;
    for r in rows {
        w.serialize(r)
            .map_err(|e| write_err(std::io::Error::other(e)))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| write_err(std::io::Error::other(e.to_string())))?;
    crate::files::atomic::write_atomic(path, &bytes).map_err(write_err)
}

/// A Markdown table of one experiment's curves, headed by its title, then the matrix of
/// one-sided Welch p-values between them.
pub fn markdown_table(title: &str, rows: &[CurveSummary], tests: &[PairTest]) -> String {
    let mut s = format!(
        "### {title}\n\n| method | seeds (finished) | final episode | final return (mean ± SE) | best evaluation (mean) | 95% of optimal first at ({}) | mean over training | optimal | minutes per run |\n|---|---|---|---|---|---|---|---|---|\n",
        reach_curve(rows)
    );
    for r in rows {
        let optimal = r.optimal.map_or("n/a".into(), format_return);
        let minutes = r.run_minutes.map_or("n/a".into(), |m| format_number(m, 1));
        let two = |v: f64| format_number(v, 2);
        let at = if r.final_n < r.seeds {
            format!(" (n = {})", r.final_n)
        } else {
            String::new()
        };
        let reach = match (r.optimal, r.reach95_episode) {
            (None, _) => "n/a".to_string(),
            (Some(_), None) => "never".to_string(),
            (Some(_), Some(e)) => e.to_string(),
        };
        s.push_str(&format!(
            "| {} | {} ({}) | {} | {} ± {}{at} | {} | {reach} | {} | {optimal} | {minutes} |\n",
            r.legend,
            r.seeds,
            r.finished,
            r.final_episode,
            two(r.final_mean),
            two(r.final_se),
            two(r.best_mean),
            two(r.mean_over_training)
        ));
    }
    if !tests.is_empty() {
        p_matrix(
            &mut s,
            "One-sided Welch t-tests on final returns: p-value of \"row above column\".",
            rows,
            tests,
            |t| t.p_a_greater,
        );
        p_matrix(
            &mut s,
            "The same on each run's mean over training (how early a method learns, per seed).",
            rows,
            tests,
            |t| t.p_a_greater_over_training,
        );
    }
    s
}

/// Which curve the "95% of optimal first at" column reads: the mean over seeds as drawn, with
/// its smoothing window (one for all rows, or per row in the summary CSV).
pub fn reach_curve(rows: &[CurveSummary]) -> String {
    let mut windows: Vec<usize> = rows.iter().map(|r| r.smoothing_points).collect();
    windows.sort_unstable();
    windows.dedup();
    match windows.as_slice() {
        [] | [1] => "unsmoothed mean".to_string(),
        [w] => format!("mean smoothed over {w} evaluations"),
        _ => "smoothed mean, window per curve in the summary CSV".to_string(),
    }
}

/// Append one matrix of p-values (row above column) under its heading line.
fn p_matrix(
    s: &mut String,
    heading: &str,
    rows: &[CurveSummary],
    tests: &[PairTest],
    p: impl Fn(&PairTest) -> f64,
) {
    s.push_str(&format!("\n{heading}\n\n| p(row > column) |"));
    for r in rows {
        s.push_str(&format!(" {} |", r.legend));
    }
    s.push_str(&format!("\n|---|{}\n", "---|".repeat(rows.len())));
    for a in rows {
        s.push_str(&format!("| {} |", a.legend));
        for b in rows {
            let cell = tests
                .iter()
                .find(|t| t.curve_a == a.curve && t.curve_b == b.curve)
                .map_or("-".to_string(), |t| format_p(p(t)));
            s.push_str(&format!(" {cell} |"));
        }
        s.push('\n');
    }
}

/// A p-value for display: three significant digits, tiny ones in scientific notation.
pub fn format_p(p: f64) -> String {
    if p < 1e-3 {
        format!("{p:.1e}")
    } else {
        format!("{p:.3}")
    }
}

/// A return for display: whole numbers without decimals (262), others with two (80.71).
pub fn format_return(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < WIDE {
        format!("{v:.0}")
    } else {
        format_number(v, 2)
    }
}

/// From this magnitude on, numbers are shown in scientific notation.
const WIDE: f64 = 1e9;

/// A number for a table cell with `decimals` decimals, at most about 16 characters wide
/// whatever its size: 1e300 (a diverged run, a crafted metrics file) as `1.00e300`, not as 301
/// digits; NaN and infinities as such.
pub fn format_number(v: f64, decimals: usize) -> String {
    if !v.is_finite() {
        format!("{v}")
    } else if v.abs() >= WIDE {
        format!("{v:.decimals$e}")
    } else {
        format!("{v:.decimals$}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(curve: &str, legend: &str, finals: &[f64], training: &[f64]) -> CurveSummary {
        let (mean, se) = crate::plot::stats::mean_and_se(finals).unwrap();
        CurveSummary {
            curve: curve.into(),
            legend: legend.into(),
            seeds: 3,
            finished: 2,
            final_episode: 1500,
            final_mean: mean,
            final_se: se,
            final_n: finals.len(),
            best_mean: 81.25,
            reach95_episode: Some(420),
            mean_over_training: 55.5,
            optimal: Some(80.71093744250365),
            run_minutes: Some(12.34),
            smoothing_points: 21,
            final_returns: finals.to_vec(),
            training_means: training.to_vec(),
        }
    }

    /// Our-1 ends above Dec-HDDRQN but learns later (means over training 25 against 65).
    fn ends_higher_learns_later() -> [CurveSummary; 2] {
        [
            row("our1", "Our-1", &[80.0, 79.0], &[20.0, 30.0]),
            row("dec-hddrqn", "Dec-HDDRQN", &[10.0, 30.0], &[60.0, 70.0]),
        ]
    }

    #[test]
    fn markdown_shows_final_return_reach_area_and_p_values() {
        let rows = ends_higher_learns_later();
        let tests = pairwise_tests(&rows);
        assert_eq!(tests.len(), 2);
        let md = markdown_table("fig4a", &rows, &tests);
        assert!(md.starts_with("### fig4a\n"));
        assert!(
            md.contains(
                "| Our-1 | 3 (2) | 1500 | 79.50 ± 0.50 (n = 2) | 81.25 | 420 | 55.50 | 80.71 | 12.3 |"
            ),
            "{md}"
        );
        let our1_row = md.lines().find(|l| l.starts_with("| Our-1 | - |")).unwrap();
        let p: f64 = our1_row.split('|').nth(3).unwrap().trim().parse().unwrap();
        assert!(p > 0.0 && p < 0.1, "{md}");
        let dec_row = md
            .lines()
            .find(|l| l.starts_with("| Dec-HDDRQN |") && l.ends_with("- |"))
            .unwrap();
        let q: f64 = dec_row.split('|').nth(2).unwrap().trim().parse().unwrap();
        assert!((p + q - 1.0).abs() < 2e-3, "{md}");
        // The second matrix tests means over training, where Our-1 (25) is below Dec-HDDRQN (65).
        let over_training = md
            .split("mean over training (")
            .nth(1)
            .expect("second matrix");
        let our1_row = over_training
            .lines()
            .find(|l| l.starts_with("| Our-1 | - |"))
            .unwrap();
        let p: f64 = our1_row.split('|').nth(3).unwrap().trim().parse().unwrap();
        assert!(p > 0.9, "{md}");
    }

    #[test]
    fn welch_csv_has_both_tests_per_ordered_pair() {
        let tests = pairwise_tests(&ends_higher_learns_later());
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("w.csv");
        write_csv(&p, &tests).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next(),
            Some("curve_a,curve_b,t,df,p_a_greater,t_over_training,df_over_training,p_a_greater_over_training")
        );
        assert_eq!(lines.count(), 2);
        assert!(tests[0].p_a_greater < 0.1 && tests[0].p_a_greater_over_training > 0.9);
    }

    #[test]
    fn csv_has_a_header_and_empty_fields_for_unknowns() {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("s.csv");
        let mut r = row("our1", "Our-1", &[1.0], &[1.0]);
        r.optimal = None;
        r.run_minutes = None;
        r.reach95_episode = None;
        write_csv(&p, &[r]).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(
            text,
            "curve,legend,seeds,finished,final_episode,final_mean,final_se,final_n,reach95_episode,mean_over_training,optimal,run_minutes,best_mean,smoothing_points\n\
             our1,Our-1,3,2,1500,1.0,0.0,1,,55.5,,,81.25,21\n"
        );
    }

    #[test]
    fn the_header_lists_the_serialized_fields_in_order() {
        fn serde_header<T: CsvRow>(row: &T) -> String {
            let mut w = csv::Writer::from_writer(Vec::new());
            w.serialize(row).unwrap();
            let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
            text.lines().next().unwrap().to_string()
        }
        let rows = ends_higher_learns_later();
        assert_eq!(serde_header(&rows[0]), CurveSummary::HEADER.join(","));
        let test = &pairwise_tests(&rows)[0];
        assert_eq!(serde_header(test), PairTest::HEADER.join(","));
    }

    #[test]
    fn a_welch_csv_without_tests_still_has_its_header() {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("w.csv");
        write_csv::<PairTest>(&p, &[]).unwrap();
        assert_eq!(
            std::fs::read_to_string(&p).unwrap(),
            format!("{}\n", PairTest::HEADER.join(","))
        );
    }

    #[test]
    fn huge_and_odd_numbers_keep_a_sane_width_in_markdown() {
        let mut r = row("our1", "Our-1", &[1e300, 1e300], &[1.0, 1.0]);
        r.best_mean = -1e200;
        r.mean_over_training = f64::NAN;
        r.optimal = Some(1e250);
        r.run_minutes = Some(1e100);
        let md = markdown_table("x", &[r], &[]);
        let line = md.lines().find(|l| l.starts_with("| Our-1 |")).unwrap();
        assert!(line.len() < 160, "{line}");
        assert!(
            line.contains("1.00e300 ±") && line.contains("-1.00e200"),
            "{line}"
        );
        assert!(
            line.contains("| NaN |") && line.contains("1.00e250") && line.contains("1.0e100"),
            "{line}"
        );
        assert_eq!(format_return(262.0), "262");
        assert_eq!(format_return(-3e15), "-3.00e15");
    }

    #[test]
    fn whole_returns_print_without_decimals() {
        assert_eq!(format_return(262.0), "262");
        assert_eq!(format_return(41.75397237445474), "41.75");
        assert_eq!(format_p(0.01234), "0.012");
        assert_eq!(format_p(2.5e-7), "2.5e-7");
    }
}
