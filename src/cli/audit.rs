//! `macdec audit`: retrain finished runs from their recorded config and compare their metrics.

use anyhow::{bail, Result};
use std::path::PathBuf;

#[derive(clap::Args)]
pub(super) struct AuditArgs {
    /// Results root holding finished runs: <results>/<experiment>/<curve>/seed-<k>/.
    #[arg(long, default_value = "reproduction")]
    results: PathBuf,
    /// How many finished runs to retrain, chosen at random (ignored with --run).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Retrain exactly these run directories instead (repeatable).
    #[arg(long)]
    run: Vec<PathBuf>,
    /// Seed of the random choice (default: from the clock; printed so a choice can be repeated).
    #[arg(long)]
    seed: Option<u64>,
    /// Runs retrained in parallel (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
}

/// Retrain the chosen runs in parallel, one line each; fails if any differs or cannot be retrained.
pub(super) fn run(args: AuditArgs) -> Result<()> {
    use crate::experiment::cluster::audit::{audit_all, choose, finished_runs, AuditOutcome};
    use crate::experiment::run::provenance::Provenance;
    let dirs = if args.run.is_empty() {
        let all = finished_runs(&args.results)?;
        if all.is_empty() {
            bail!("{}: no finished runs to audit", args.results.display());
        }
        if args.runs == 0 {
            bail!("--runs must be at least 1");
        }
        let seed = args.seed.unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs())
        });
        let chosen = choose(&all, args.runs, seed);
        eprintln!(
            "auditing {} of {} finished run(s) under {} (choice seed {seed})",
            chosen.len(),
            all.len(),
            args.results.display()
        );
        chosen
    } else {
        args.run.clone()
    };
    let here = Provenance::current();
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let results = audit_all(&dirs, jobs, |r| match r {
        Ok(a) => {
            println!("{}", a.line());
            if let Some(p) = &a.provenance {
                if !crate::autograd::kernels::same_arithmetic(&p.kernel_path, &here.kernel_path) {
                    println!(
                        "  note: trained on the {} kernel path, retrained on {}: rounding may differ",
                        p.kernel_path, here.kernel_path
                    );
                }
            }
        }
        Err((dir, e)) => println!("{}: CANNOT AUDIT: {e}", dir.display()),
    });
    let differ = results
        .iter()
        .filter(|r| matches!(r, Ok(a) if !matches!(a.outcome, AuditOutcome::Identical { .. })))
        .count();
    let unaudited = results.iter().filter(|r| r.is_err()).count();
    match (differ, unaudited) {
        (0, 0) => {}
        (d, 0) => bail!("{d} of {} audited run(s) differ", results.len()),
        (0, u) => bail!("{u} of {} run(s) could not be audited", results.len()),
        (d, u) => bail!(
            "{d} of {} run(s) differ and {u} could not be audited",
            results.len()
        ),
    }
    println!("all {} audited run(s) identical", results.len());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused, error_text};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> AuditArgs {
        match accepted("audit", flags) {
            Command::Audit(args) => args,
            _ => unreachable!("`audit` parses as Command::Audit"),
        }
    }

    #[test]
    fn audit_retrains_three_runs_of_reproduction_by_default() {
        let args = parse(&[]);
        assert_eq!(args.results, PathBuf::from("reproduction"));
        assert_eq!(args.runs, 3);
        assert!(args.run.is_empty());
        assert_eq!((args.seed, args.jobs), (None, None));
        let args = parse(&["--run", "a/seed-0", "--run", "b/seed-1", "--seed", "5"]);
        assert_eq!(
            args.run,
            [PathBuf::from("a/seed-0"), PathBuf::from("b/seed-1")]
        );
        assert_eq!(args.seed, Some(5));
        assert_refused("audit", &["--runs", "x"], ErrorKind::ValueValidation, "'x'");
    }

    #[test]
    fn audit_of_a_tree_without_finished_runs_fails_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let args = parse(&["--results", dir.path().to_str().unwrap()]);
        assert_eq!(
            error_text(run(args)),
            format!("Error: {}: no finished runs to audit", dir.path().display())
        );
    }
}
