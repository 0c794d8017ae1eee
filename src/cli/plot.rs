//! `macdec plot`: learning curves (PNG + SVG) and summary tables from a results tree.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub(super) struct PlotArgs {
    /// Results root: <results>/<experiment>/<curve>/seed-<k>/metrics.csv.
    #[arg(long, default_value = "results")]
    results: PathBuf,
    /// Where the figures and <experiment>_summary.csv files go (default: the results root,
    /// as `train` does; only an explicit `--out plots` redraws the committed figures).
    #[arg(long)]
    out: Option<PathBuf>,
    /// The metrics.csv column to plot: eval_return, or any other (env_steps, updates, a
    /// method family's own such as loss or epsilon); files become <experiment>_<metric>.*.
    #[arg(long, default_value = "eval_return")]
    metric: String,
    /// The return to draw: `discounted` (eval_return) or `undiscounted`
    /// (eval_return_undiscounted, the summed team reward later papers report); instead of
    /// --metric.
    #[arg(long = "y", value_parser = crate::plot::axis::YAxis::parse, conflicts_with = "metric")]
    y_axis: Option<crate::plot::axis::YAxis>,
    /// What the curves are drawn against: `episode`, `env_steps`, or `acac_timesteps` (ACAC's
    /// Timesteps: steps of finished training episodes, what ACAC's logs count); along steps,
    /// runs are interpolated between their evaluations and files get an `_<axis>` suffix.
    #[arg(long = "x", default_value = "episode", value_parser = crate::plot::axis::XAxis::parse)]
    x_axis: crate::plot::axis::XAxis,
    /// Centred moving average before drawing and reading "95% of optimal first at":
    /// `auto` (half window = evaluation points / 40, at most 10: 21 points on long runs,
    /// none under 40 points), `0` (none), an odd number of evaluation points (`21`), or
    /// training episodes (`2000ep`).
    #[arg(long, default_value = "auto", value_parser = crate::curve_stats::Smoothing::parse)]
    smooth: crate::curve_stats::Smoothing,
    /// A TOML file naming outside runs (another code's per-seed logs, e.g. ACAC's) to draw
    /// beside our curves, with --y undiscounted and --x env_steps (--x acac_timesteps for
    /// ACAC's logs); every run of such an experiment
    /// is then read up to the smallest last step any run reached, so the tables compare equal
    /// budgets (README "Beside another code's logs").
    #[arg(long)]
    beside: Option<PathBuf>,
}

/// Draw the figures (into the results root unless `--out` says otherwise) and print the tables.
pub(super) fn run(args: PlotArgs) -> Result<()> {
    let PlotArgs {
        results,
        out,
        metric,
        y_axis,
        x_axis,
        smooth,
        beside,
    } = args;
    let out = out.unwrap_or_else(|| results.clone());
    let options = crate::plot::PlotOptions {
        metric: y_axis.map_or(metric, |y| y.column().to_string()),
        smoothing: smooth,
        x: x_axis,
        beside,
    };
    plot(&results, &out, &options)
}

fn plot(results: &Path, out: &Path, options: &crate::plot::PlotOptions) -> Result<()> {
    let report = crate::plot::plot_results_with(results, out, options)
        .with_context(|| format!("plotting {} into {}", results.display(), out.display()))?;
    for note in &report.notes {
        eprintln!("{note}");
    }
    for p in &report.plots {
        eprintln!(
            "wrote {}, {}, {}, {}",
            p.png.display(),
            p.svg.display(),
            p.summary_csv.display(),
            p.tests_csv.display()
        );
    }
    print!("{}", report.markdown());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use crate::curve_stats::Smoothing;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> PlotArgs {
        match accepted("plot", flags) {
            Command::Plot(args) => args,
            _ => unreachable!("`plot` parses as Command::Plot"),
        }
    }

    #[test]
    fn plot_draws_eval_return_of_results_with_auto_smoothing_by_default() {
        let args = parse(&[]);
        assert_eq!(args.results, PathBuf::from("results"));
        assert_eq!(args.out, None);
        assert_eq!(args.metric, "eval_return");
        assert_eq!(args.smooth, Smoothing::Auto);
    }

    #[test]
    fn plot_smooth_takes_none_odd_points_or_episodes() {
        assert_eq!(parse(&["--smooth", "0"]).smooth, Smoothing::NONE);
        assert_eq!(parse(&["--smooth", "21"]).smooth, Smoothing::Points(21));
        assert_eq!(
            parse(&["--smooth", "2000ep"]).smooth,
            Smoothing::Episodes(2000)
        );
        assert_refused(
            "plot",
            &["--smooth", "4"],
            ErrorKind::ValueValidation,
            "`4` is even (use 3 or 5)",
        );
        assert_refused(
            "plot",
            &["--smooth", "foo"],
            ErrorKind::ValueValidation,
            "`foo` is not a smoothing",
        );
    }

    #[test]
    fn plot_takes_an_x_axis_and_a_y_axis_but_not_y_with_metric() {
        use crate::plot::axis::{XAxis, YAxis};
        let args = parse(&[]);
        assert_eq!((args.x_axis, args.y_axis), (XAxis::Episode, None));
        let args = parse(&["--x", "env_steps", "--y", "undiscounted"]);
        assert_eq!(args.x_axis, XAxis::EnvSteps);
        assert_eq!(args.y_axis, Some(YAxis::Undiscounted));
        assert_refused(
            "plot",
            &["--y", "undiscounted", "--metric", "loss"],
            ErrorKind::ArgumentConflict,
            "--metric",
        );
        assert_refused(
            "plot",
            &["--x", "steps"],
            ErrorKind::ValueValidation,
            "`steps` is not an x axis",
        );
    }
}
