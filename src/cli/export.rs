//! `macdec export`: a trained run's decentralized nets as a policy directory for robots.

use crate::experiment::run::results_tree;
use anyhow::{Context, Result};
use std::path::PathBuf;

#[derive(clap::Args)]
pub(super) struct ExportArgs {
    /// A run directory: <results>/<experiment>/<method>/seed-<k>.
    #[arg(long)]
    run: PathBuf,
    /// The policy directory to write.
    #[arg(long)]
    out: PathBuf,
}

/// Export the run's policy files, warning when its training has not finished.
pub(super) fn run(args: ExportArgs) -> Result<()> {
    let ExportArgs { run, out } = args;
    let (run, out) = (run.as_path(), out.as_path());
    let manifest = crate::deploy::policy::export::export_run(run, out)
        .with_context(|| format!("exporting {} to {}", run.display(), out.display()))?;
    if !results_tree::is_finished(run) {
        eprintln!(
            "warning: {} has not finished training: exported its nets after {} episodes",
            run.display(),
            manifest.run.episodes_trained
        );
    }
    eprintln!(
        "exported {} agent(s) of {} ({} seed {}, {} episodes trained) to {}",
        manifest.agents.len(),
        manifest.env.name(),
        manifest.run.method,
        manifest.run.seed,
        manifest.run.episodes_trained,
        out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    #[test]
    fn export_needs_a_run_and_an_out_directory() {
        assert_refused(
            "export",
            &["--out", "p"],
            ErrorKind::MissingRequiredArgument,
            "--run <RUN>",
        );
        assert_refused(
            "export",
            &["--run", "r"],
            ErrorKind::MissingRequiredArgument,
            "--out <OUT>",
        );
        let Command::Export(args) = accepted("export", &["--run", "r", "--out", "p"]) else {
            unreachable!("`export` parses as Command::Export")
        };
        assert_eq!(
            (args.run, args.out),
            (PathBuf::from("r"), PathBuf::from("p"))
        );
    }
}
