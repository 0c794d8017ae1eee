//! `macdec eval`: a policy directory's episodes in this process, no robot processes.

use anyhow::{Context, Result};

use super::episodes::{EpisodeArgs, EpisodePrinter};

#[derive(clap::Args)]
pub(super) struct EvalArgs {
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Sample each macro-action from the actors' distributions (MacroMARL's evaluation protocol)
    /// instead of taking the greedy one; actor policies only.
    #[arg(long)]
    sample: bool,
}

/// Play the episodes in this process and print each one's line, then the summary.
pub(super) fn run(args: EvalArgs) -> Result<()> {
    let sample = args.sample;
    let args = args.episodes;
    let mut run = args.load()?;
    let mut printer = EpisodePrinter::new(args.trajectories);
    let choice = if sample {
        crate::deploy::drive::local_eval::Choice::Sampled
    } else {
        crate::deploy::drive::local_eval::Choice::Greedy
    };
    crate::deploy::drive::local_eval::eval_policy(
        &run.manifest,
        &run.verified,
        args.episodes,
        choice,
        &mut run.rng,
        |trace| printer.print(trace),
    )
    .with_context(|| format!("evaluating {}", args.policy.display()))?;
    eprintln!(
        "{}, mean undiscounted {:.4}",
        printer.summary(&run, "in-process"),
        printer.mean_undiscounted()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;
    use std::path::PathBuf;

    fn parse(flags: &[&str]) -> EvalArgs {
        let argv = [&["--policy", "p"], flags].concat();
        match accepted("eval", &argv) {
            Command::Eval(args) => args,
            _ => unreachable!("`eval` parses as Command::Eval"),
        }
    }

    #[test]
    fn eval_is_greedy_over_one_episode_by_default() {
        assert_refused(
            "eval",
            &[],
            ErrorKind::MissingRequiredArgument,
            "--policy <POLICY>",
        );
        let args = parse(&[]);
        assert_eq!(args.episodes.policy, PathBuf::from("p"));
        assert_eq!(args.episodes.episodes, 1);
        assert_eq!(args.episodes.seed, None);
        assert!(!args.sample && !args.episodes.trajectories);
        assert!(parse(&["--sample"]).sample);
    }

    #[test]
    fn eval_episodes_are_bounded_and_takes_no_timeout() {
        assert_eq!(parse(&["--episodes", "100000"]).episodes.episodes, 100_000);
        let argv = ["--policy", "p", "--episodes", "0"];
        assert_refused(
            "eval",
            &argv,
            ErrorKind::ValueValidation,
            "must be at least 1",
        );
        let argv = ["--policy", "p", "--timeout-secs", "5"];
        assert_refused(
            "eval",
            &argv,
            ErrorKind::UnknownArgument,
            "'--timeout-secs'",
        );
    }

    #[test]
    fn eval_of_a_missing_policy_names_it() {
        let dir = tempfile::tempdir().unwrap();
        let policy = dir.path().join("none");
        let Command::Eval(args) = accepted("eval", &["--policy", policy.to_str().unwrap()]) else {
            unreachable!("`eval` parses as Command::Eval")
        };
        let text = crate::cli::tests::error_text(run(args));
        let expected = format!("Error: loading policy {}", policy.display());
        assert!(text.starts_with(&expected), "{text}");
    }
}
