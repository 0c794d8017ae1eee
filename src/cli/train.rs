//! `macdec train`: train an experiment's runs in parallel, then report their curves and draw
//! the figures.

use crate::experiment::run::runner::{RunStatus, RunnerOptions};
use crate::experiment::run::stop::StopSignal;
use crate::experiment::run::train_all::train_all;
use anyhow::{bail, Context, Result};
use std::path::PathBuf;

use super::bounds::at_least_one;
use super::selection::Selection;

#[derive(clap::Args)]
pub(super) struct TrainArgs {
    #[command(flatten)]
    select: Selection,
    /// Runs in parallel (default: the number of cores; never more than the runs).
    #[arg(long, value_parser = at_least_one)]
    jobs: Option<usize>,
    /// Results root: runs go to <out>/<experiment>/<method>/seed-<k>/.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Recompute runs that already finished (their directories are replaced).
    #[arg(long)]
    force: bool,
    /// No progress bars; one line per finished run.
    #[arg(long)]
    quiet: bool,
    /// Where the learning-curve figures go after training (default: the results root --out, as
    /// <out>/<experiment>.png, so side runs never overwrite committed figures).
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Do not draw figures after training.
    #[arg(long)]
    no_plot: bool,
    /// Run only the run with this index in the experiment's run list (Slurm array tasks).
    #[arg(long)]
    run_index: Option<usize>,
    /// Also log every evaluation as TensorBoard scalars while training, one run per directory
    /// <DIR>/<experiment>/<method>/seed-<k>/ (view with `tensorboard --logdir DIR`). Step is the
    /// episode; tags are the metrics.csv columns. Not part of a run's identity.
    #[arg(long, value_name = "DIR")]
    tensorboard: Option<PathBuf>,
}

/// Train the selected runs (or one, with `--run-index`), report their curves and draw figures.
pub(super) fn run(args: TrainArgs) -> Result<()> {
    let experiment = args.select.load()?;
    let mut runs = experiment.runs()?;
    if let Some(i) = args.run_index {
        if i >= runs.len() {
            bail!(
                "--run-index {i}: the experiment has {} runs (0..{})",
                runs.len(),
                runs.len()
            );
        }
        runs = vec![runs.swap_remove(i)];
    }
    let jobs = crate::experiment::definition::limits::worker_threads(
        args.jobs
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        runs.len(),
    );
    if let Some(dir) = &args.tensorboard {
        crate::experiment::run::tensorboard::check_root(dir)
            .with_context(|| format!("--tensorboard {}", dir.display()))?;
    }
    let opts = RunnerOptions {
        out: args.out.clone(),
        jobs,
        force: args.force,
        quiet: args.quiet,
        tensorboard: args.tensorboard.clone(),
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
    if let Some(dir) = &args.tensorboard {
        eprintln!(
            "  TensorBoard logs in {} (view with: tensorboard --logdir {})",
            dir.join(&experiment.name).display(),
            dir.display()
        );
    }
    let selected = |curve: &String| experiment.methods.iter().any(|m| m.name() == curve);
    for (curve, home) in experiment.shared_curves.iter().filter(|(c, _)| selected(c)) {
        eprintln!(
            "  {curve}: shared with {home}, runs in {}",
            args.out.join(home).join(curve).display()
        );
    }
    experiment
        .write_shared_curves(&args.out)
        .with_context(|| format!("recording the shared curves in {}", args.out.display()))?;
    let statuses = train_all(&runs, &opts, args.force, &StopSignal::new());
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
    let busy = statuses
        .iter()
        .filter(|s| matches!(s, RunStatus::Busy))
        .count();
    if busy > 0 {
        eprintln!("{busy} run(s) left to other processes training them");
    }
    // A refused run's directory holds another run's curve, a busy one a curve still growing:
    // show neither as this command's.
    let shown: Vec<_> = runs
        .iter()
        .zip(&statuses)
        .filter(|(_, s)| !matches!(s, RunStatus::Failed(_) | RunStatus::Busy))
        .map(|(r, _)| r.clone())
        .collect();
    crate::experiment::run::report::print_curves(&args.out, &shown)?;
    if !args.no_plot {
        let plots = args.plots.as_deref().unwrap_or(&args.out);
        match crate::plot::plot_results(&args.out, plots) {
            Ok(report) => {
                for p in report
                    .plots
                    .iter()
                    .filter(|p| p.experiment == experiment.name)
                {
                    eprintln!(
                        "learning curves: {} and {}",
                        p.png.display(),
                        p.svg.display()
                    );
                }
            }
            Err(e) => eprintln!("note: no figure drawn: {e}"),
        }
    }
    if failed > 0 {
        bail!("{failed} of {} run(s) failed", runs.len());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused, error_text};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> TrainArgs {
        match accepted("train", flags) {
            Command::Train(args) => args,
            _ => unreachable!("`train` parses as Command::Train"),
        }
    }

    #[test]
    fn train_defaults_to_the_built_in_run_into_results() {
        let args = parse(&[]);
        assert_eq!(args.select.config, None);
        assert_eq!(args.select.methods, None);
        assert_eq!(args.select.seeds, None);
        assert!(args.select.set.is_empty());
        assert_eq!(args.jobs, None);
        assert_eq!(args.out, PathBuf::from("results"));
        assert!(!args.force && !args.quiet && !args.no_plot);
        assert_eq!(args.plots, None);
        assert_eq!(args.run_index, None);
        assert_eq!(args.tensorboard, None);
    }

    #[test]
    fn train_selection_flags_split_methods_and_repeat_set() {
        let args = parse(&[
            "--config",
            "experiments/fig4a.toml",
            "--methods",
            "our1,dec-hddrqn",
            "--seeds",
            "0..3",
            "--set",
            "total_epi=300",
            "--set",
            "our1.l_rate=0.001",
        ]);
        assert_eq!(
            args.select.config,
            Some(PathBuf::from("experiments/fig4a.toml"))
        );
        assert_eq!(
            args.select.methods,
            Some(vec!["our1".to_string(), "dec-hddrqn".to_string()])
        );
        assert_eq!(args.select.seeds.as_deref(), Some("0..3"));
        assert_eq!(args.select.set, ["total_epi=300", "our1.l_rate=0.001"]);
    }

    #[test]
    fn train_jobs_is_at_least_one() {
        assert_eq!(parse(&["--jobs", "4"]).jobs, Some(4));
        let v = ErrorKind::ValueValidation;
        assert_refused("train", &["--jobs", "0"], v, "must be at least 1");
        assert_refused(
            "train",
            &["--jobs", "many"],
            v,
            "expected a positive integer",
        );
    }

    #[test]
    fn a_tensorboard_dir_that_is_a_file_is_refused_before_anything_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        let file = dir.path().join("tb");
        std::fs::write(&file, "").unwrap();
        let args = parse(&[
            "--out",
            out.to_str().unwrap(),
            "--no-plot",
            "--tensorboard",
            file.to_str().unwrap(),
        ]);
        assert_eq!(args.tensorboard.as_deref(), Some(file.as_path()));
        let e = error_text(run(args));
        assert!(
            e.starts_with(&format!("Error: --tensorboard {}", file.display()))
                && e.contains("exists and is not a directory"),
            "{e}"
        );
        assert!(!out.exists(), "nothing is written before the refusal");
    }

    #[test]
    fn train_run_index_past_the_last_run_is_refused_before_training() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        let args = parse(&[
            "--out",
            out.to_str().unwrap(),
            "--no-plot",
            "--run-index",
            "2",
        ]);
        assert_eq!(args.run_index, Some(2));
        // The built-in experiment trains two runs.
        assert_eq!(
            error_text(run(args)),
            "Error: --run-index 2: the experiment has 2 runs (0..2)"
        );
        assert!(!out.exists(), "nothing is written before the refusal");
    }
}
