//! `macdec report`: rliable's aggregate statistics with bootstrap intervals, performance
//! profiles, sample-efficiency curves and marl-eval's JSON, from a results tree.

use crate::report::bootstrap::{DEFAULT_RESAMPLES, MAX_RESAMPLES};
use crate::report::{ReportOptions, XAxis};
use anyhow::{Context, Result};
use std::path::PathBuf;

#[derive(clap::Args)]
pub(super) struct ReportArgs {
    /// Results root: <results>/<block>/<method>/seed-<k>/metrics.csv (or .csv.gz); each
    /// experiment directory is a block.
    #[arg(long)]
    results: PathBuf,
    /// Where <block>_aggregate.csv, <block>_improvement.csv, the figures and
    /// <block>_marl_eval.json go.
    #[arg(long)]
    out: PathBuf,
    /// Bootstrap resamples per confidence interval (1 to 100000).
    #[arg(long, default_value_t = DEFAULT_RESAMPLES, value_parser = parse_resamples)]
    resamples: usize,
    /// Seed of the bootstrap: the same seed gives the same intervals, bit for bit.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// The sample-efficiency curves' x axis: `episode`, `env_steps` or `acac_timesteps`.
    #[arg(long = "x", default_value = "episode", value_parser = XAxis::parse)]
    x_axis: XAxis,
    /// Report only this block (repeat for several); default: every block with runs.
    #[arg(long = "block")]
    blocks: Vec<String>,
}

fn parse_resamples(text: &str) -> Result<usize, String> {
    super::bounds::bounded_count(text, MAX_RESAMPLES)
}

/// Write the report's files into `--out` and print its tables.
pub(super) fn run(args: ReportArgs) -> Result<()> {
    let ReportArgs {
        results,
        out,
        resamples,
        seed,
        x_axis,
        blocks,
    } = args;
    let options = ReportOptions {
        resamples,
        seed,
        x_axis,
        blocks,
    };
    let report = crate::report::report_results(&results, &out, &options)
        .with_context(|| format!("reporting {} into {}", results.display(), out.display()))?;
    for note in &report.notes {
        eprintln!("{note}");
    }
    for b in &report.blocks {
        let mut files = vec![b.aggregate_csv.clone(), b.improvement_csv.clone()];
        files.extend(b.figures.iter().cloned());
        files.push(b.marl_eval_json.clone());
        let shown: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
        eprintln!("wrote {}", shown.join(", "));
    }
    print!("{}", report.markdown());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> ReportArgs {
        match accepted("report", flags) {
            Command::Report(args) => args,
            _ => unreachable!("`report` parses as Command::Report"),
        }
    }

    #[test]
    fn report_defaults_to_2000_resamples_seed_0_against_episodes_every_block() {
        let args = parse(&["--results", "r", "--out", "o"]);
        assert_eq!(
            (args.results, args.out),
            (PathBuf::from("r"), PathBuf::from("o"))
        );
        assert_eq!((args.resamples, args.seed), (2000, 0));
        assert_eq!(args.x_axis, XAxis::Episode);
        assert!(args.blocks.is_empty());
    }

    #[test]
    fn report_takes_env_steps_seeds_and_several_blocks() {
        let args = parse(&[
            "--results",
            "r",
            "--out",
            "o",
            "--x",
            "env_steps",
            "--seed",
            "7",
            "--block",
            "bp6",
            "--block",
            "wh_a",
            "--resamples",
            "100000",
        ]);
        assert_eq!(args.x_axis, XAxis::EnvSteps);
        assert_eq!((args.seed, args.resamples), (7, 100_000));
        assert_eq!(args.blocks, ["bp6", "wh_a"]);
    }

    #[test]
    fn report_refuses_no_resamples_too_many_and_an_unknown_axis() {
        let base = ["--results", "r", "--out", "o"];
        let with = |extra: &[&'static str]| [&base[..], extra].concat();
        assert_refused(
            "report",
            &with(&["--resamples", "0"]),
            ErrorKind::ValueValidation,
            "must be at least 1",
        );
        assert_refused(
            "report",
            &with(&["--resamples", "100001"]),
            ErrorKind::ValueValidation,
            "must be at most 100000, got 100001",
        );
        assert_refused(
            "report",
            &with(&["--x", "time"]),
            ErrorKind::ValueValidation,
            "`time` is not an x axis",
        );
        assert_refused(
            "report",
            &["--out", "o"],
            ErrorKind::MissingRequiredArgument,
            "--results",
        );
    }
}
