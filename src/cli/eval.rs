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

/// Play the episodes in this process and print each one's line, then the summary. The policy
/// acts with the nets its evaluations used: each agent's own, or its centralized net for the
/// team (Cen-DDRQN, Mac-CAC), which only `eval` and `render` can run.
pub(super) fn run(args: EvalArgs) -> Result<()> {
    use crate::deploy::drive::local_eval::Choice;
    use crate::deploy::drive::team::eval_team;
    let sample = args.sample;
    let args = args.episodes;
    let choice = if sample {
        Choice::Sampled
    } else {
        Choice::Greedy
    };
    let (mut run, mut team) = args.load_team(choice)?;
    let mut printer = EpisodePrinter::new(args.trajectories);
    eval_team(
        &run.manifest,
        &mut team,
        args.episodes,
        &mut run.rng,
        |trace| printer.print(trace),
    )
    .with_context(|| format!("evaluating {}", args.policy.display()))?;
    let place = match team {
        crate::deploy::drive::team::Team::Agents(_) => "in-process".to_string(),
        crate::deploy::drive::team::Team::Central(c) => {
            format!("in-process, acting centrally with its {}", c.kind_name())
        }
    };
    eprintln!(
        "{}, mean undiscounted {:.4}",
        printer.summary(&run, &place),
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
