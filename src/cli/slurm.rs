//! `macdec slurm`: a Slurm job-array script that trains an experiment's runs, one task each.

use crate::experiment::cluster::slurm::{job_script, SlurmOptions};
use crate::experiment::run::results_tree;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

use super::selection::Selection;

#[derive(clap::Args)]
pub(super) struct SlurmArgs {
    #[command(flatten)]
    select: Selection,
    /// Results root shared by the cluster's nodes.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Wall-clock limit per array task.
    #[arg(long, default_value = "12:00:00")]
    time: String,
    /// Memory per array task.
    #[arg(long, default_value = "4G")]
    mem: String,
    /// Extra #SBATCH lines, e.g. --sbatch=--partition=cpu (repeatable).
    #[arg(long = "sbatch", value_name = "LINE", allow_hyphen_values = true)]
    sbatch: Vec<String>,
    /// Each task also logs TensorBoard scalars below this directory, shared by the nodes (as
    /// `macdec train --tensorboard`).
    #[arg(long, value_name = "DIR")]
    tensorboard: Option<PathBuf>,
}

/// Print the job-array script; the array tasks rerun this selection with `--run-index`.
pub(super) fn run(args: SlurmArgs) -> Result<()> {
    print!("{}", script(args)?);
    Ok(())
}

/// The job-array script of `args`.
fn script(args: SlurmArgs) -> Result<String> {
    let sel = args.select;
    let mut train_args = Vec::new();
    if let Some(m) = &sel.methods {
        train_args.extend(["--methods".to_string(), m.join(",")]);
    }
    if let Some(s) = &sel.seeds {
        train_args.extend(["--seeds".to_string(), s.clone()]);
    }
    for item in &sel.set {
        train_args.extend(["--set".to_string(), item.clone()]);
    }
    let config = sel
        .config
        .as_deref()
        .context("slurm needs --config FILE (the experiment the array tasks train)")?;
    let experiment = sel.load()?;
    let labels: Vec<String> = experiment
        .runs()?
        .iter()
        .map(|r| results_tree::run_label(&r.curve_name(), r.seed))
        .collect();
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    if let Some(dir) = &args.tensorboard {
        let dir = absolute(dir);
        let dir = dir
            .to_str()
            .with_context(|| format!("--tensorboard {}: not a UTF-8 path", dir.display()))?;
        train_args.extend(["--tensorboard".to_string(), dir.to_string()]);
    }
    let config = absolute(config);
    let out = absolute(&args.out);
    let binary = std::env::current_exe().context("locating the macdec binary")?;
    Ok(job_script(
        &experiment.name,
        &labels,
        &SlurmOptions {
            config: &config,
            out: &out,
            binary: &binary,
            train_args,
            time: &args.time,
            mem: &args.mem,
            extra_sbatch: args.sbatch,
        },
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, error_text};
    use crate::cli::Command;

    fn parse(flags: &[&str]) -> SlurmArgs {
        match accepted("slurm", flags) {
            Command::Slurm(args) => args,
            _ => unreachable!("`slurm` parses as Command::Slurm"),
        }
    }

    #[test]
    fn slurm_asks_12_hours_and_4g_per_task_into_results_by_default() {
        let args = parse(&["--config", "e.toml"]);
        assert_eq!(args.select.config, Some(PathBuf::from("e.toml")));
        assert_eq!(args.out, PathBuf::from("results"));
        assert_eq!(args.time, "12:00:00");
        assert_eq!(args.mem, "4G");
        assert!(args.sbatch.is_empty());
        assert_eq!(args.tensorboard, None);
    }

    #[test]
    fn slurm_passes_an_absolute_tensorboard_dir_to_every_task() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("e.toml");
        std::fs::write(&config, "methods = [\"our1\"]\nseeds = \"0..2\"\n").unwrap();
        let tb = dir.path().join("tb logs");
        let args = parse(&[
            "--config",
            config.to_str().unwrap(),
            "--tensorboard",
            tb.to_str().unwrap(),
        ]);
        assert_eq!(args.tensorboard.as_deref(), Some(tb.as_path()));
        // The script quotes the path (it holds a space); the tasks train with the flag.
        let script = script(args).unwrap();
        let quoted = crate::experiment::cluster::slurm::shell_quote(tb.to_str().unwrap());
        assert!(
            script.contains(&format!(" --tensorboard {quoted} --jobs 1 ")),
            "{script}"
        );
    }

    #[test]
    fn slurm_sbatch_lines_may_start_with_hyphens_and_repeat() {
        let args = parse(&["--sbatch=--partition=cpu", "--sbatch", "--qos=long"]);
        assert_eq!(args.sbatch, ["--partition=cpu", "--qos=long"]);
    }

    #[test]
    fn slurm_needs_a_config_file() {
        let args = parse(&["--methods", "our1"]);
        assert_eq!(
            error_text(run(args)),
            "Error: slurm needs --config FILE (the experiment the array tasks train)"
        );
    }
}
