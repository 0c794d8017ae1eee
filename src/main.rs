//! The `macdec` command line: parse, call the library, report. No logic lives here.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use macdec::algos::method::Method;
use macdec::experiment::config::{Experiment, Overrides, DEFAULT_EXPERIMENT};
use macdec::experiment::runner::{run_all, RunStatus, RunnerOptions};
use macdec::experiment::seeds::parse_seeds;
use macdec::experiment::train_run::train_run;
use std::path::{Path, PathBuf};

#[derive(Parser)]
#[command(
    name = "macdec",
    version,
    about = "Macro-action multi-agent deep RL (MacDec-MADDRQN, ICRA 2020)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Train methods on an experiment config, one run per (method, variant, seed), in parallel.
    Train(TrainArgs),
}

#[derive(clap::Args)]
struct TrainArgs {
    /// Experiment TOML (see experiments/); without it, a short built-in Box Pushing 10x10 run.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Comma-separated methods: dec-hddrqn, cen-ddrqn, our1, our1-r, our2.
    #[arg(long, value_delimiter = ',')]
    methods: Option<Vec<String>>,
    /// Seeds: a range `0..40` (end exclusive) or a list `0,3,7`.
    #[arg(long)]
    seeds: Option<String>,
    /// Runs in parallel (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Results root: runs go to <out>/<experiment>/<method>/seed-<k>/.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Override a config key, e.g. total_epi=300 or dec-hddrqn.init_h=0.3 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Recompute runs that already finished (their directories are replaced).
    #[arg(long)]
    force: bool,
    /// No progress bars; one line per finished run.
    #[arg(long)]
    quiet: bool,
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Train(args) => train(args),
    }
}

fn train(args: TrainArgs) -> Result<()> {
    let methods = args
        .methods
        .map(|names| {
            names
                .iter()
                .map(|n| n.parse::<Method>())
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()?;
    let seeds = args.seeds.as_deref().map(parse_seeds).transpose()?;
    let overrides = Overrides {
        methods,
        seeds,
        set: args.set,
    };
    let experiment = match &args.config {
        Some(path) => Experiment::load(path, &overrides)
            .with_context(|| format!("loading {}", path.display()))?,
        None => Experiment::parse(
            DEFAULT_EXPERIMENT,
            Path::new("<built-in default>"),
            "quickstart_bp10",
            &overrides,
        )?,
    };
    let runs = experiment.runs()?;
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let opts = RunnerOptions {
        out: args.out.clone(),
        jobs,
        force: args.force,
        quiet: args.quiet,
    };
    eprintln!(
        "{}: {} run(s) ({} method(s) x {} seed(s)), {} at a time, results in {}",
        experiment.name,
        runs.len(),
        experiment.methods.len(),
        experiment.seeds.len(),
        jobs,
        args.out.join(&experiment.name).display()
    );
    let force = args.force;
    let statuses = run_all(&runs, &opts, |spec, dir, progress| {
        train_run(spec, dir, progress, force).map_err(|e| e.to_string())
    });
    let failed = statuses
        .iter()
        .filter(|s| matches!(s, RunStatus::Failed(_)))
        .count();
    let skipped = statuses
        .iter()
        .filter(|s| matches!(s, RunStatus::Skipped))
        .count();
    if skipped > 0 {
        eprintln!("{skipped} run(s) already finished, skipped (use --force to recompute)");
    }
    macdec::experiment::report::print_curves(&args.out, &runs)?;
    if failed > 0 {
        bail!("{failed} of {} run(s) failed", runs.len());
    }
    Ok(())
}
