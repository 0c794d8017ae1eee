//! `macdec deploy`: the policy's domain here and one `macdec robot` process per agent over
//! loopback TCP.

use anyhow::{Context, Result};

use super::bounds::parse_timeout_secs;
use super::episodes::{EpisodeArgs, EpisodePrinter};

#[derive(clap::Args)]
pub(super) struct DeployArgs {
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Seconds to wait for a robot to start, and for each reply: the whole reply must arrive
    /// within this many seconds of its request (1 to 86400).
    #[arg(long, default_value_t = 30, value_parser = parse_timeout_secs)]
    timeout_secs: u64,
    /// Robots run the deterministic stand-in policy (tests).
    #[arg(long, hide = true)]
    mock: bool,
}

/// Start one robot process per agent, play the episodes against them and print each one's line.
pub(super) fn run(args: DeployArgs) -> Result<()> {
    use crate::deploy::drive::processes::deploy_streaming;
    let mut run = args.episodes.load()?;
    let exe = std::env::current_exe().context("locating the macdec executable")?;
    let extra: Vec<String> = if args.mock {
        vec!["--mock".into()]
    } else {
        vec![]
    };
    let mut printer = EpisodePrinter::new(args.episodes.trajectories);
    deploy_streaming(
        &exe,
        &args.episodes.policy,
        &run.manifest,
        &extra,
        args.episodes.episodes,
        &mut run.rng,
        std::time::Duration::from_secs(args.timeout_secs),
        |trace| printer.print(trace),
    )
    .with_context(|| format!("deploying {}", args.episodes.policy.display()))?;
    let place = format!("with {} robot process(es)", run.manifest.agents.len());
    eprintln!("{}", printer.summary(&run, &place));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;
    use std::path::PathBuf;

    fn parse(flags: &[&str]) -> DeployArgs {
        let argv = [&["--policy", "p"], flags].concat();
        match accepted("deploy", &argv) {
            Command::Deploy(args) => args,
            _ => unreachable!("`deploy` parses as Command::Deploy"),
        }
    }

    fn refused(flags: &[&str], message: &str) {
        let argv = [&["--policy", "p"], flags].concat();
        assert_refused("deploy", &argv, ErrorKind::ValueValidation, message);
    }

    #[test]
    fn deploy_plays_one_episode_of_the_run_s_seed_with_30_s_per_reply() {
        assert_refused(
            "deploy",
            &[],
            ErrorKind::MissingRequiredArgument,
            "--policy <POLICY>",
        );
        let args = parse(&[]);
        assert_eq!(args.episodes.policy, PathBuf::from("p"));
        assert_eq!(args.episodes.episodes, 1);
        assert_eq!(args.episodes.seed, None);
        assert!(!args.episodes.trajectories);
        assert_eq!(args.timeout_secs, 30);
        assert!(!args.mock);
        let args = parse(&["--episodes", "5", "--seed", "9", "--trajectories", "--mock"]);
        assert_eq!((args.episodes.episodes, args.episodes.seed), (5, Some(9)));
        assert!(args.episodes.trajectories && args.mock);
    }

    #[test]
    fn deploy_timeout_is_one_second_to_a_day() {
        assert_eq!(parse(&["--timeout-secs", "1"]).timeout_secs, 1);
        assert_eq!(parse(&["--timeout-secs", "86400"]).timeout_secs, 86_400);
        refused(
            &["--timeout-secs", "0"],
            "a timeout of 0 s gives no robot time to answer",
        );
        refused(
            &["--timeout-secs", "86401"],
            "at most 86400 s (one day), got 86401",
        );
    }

    #[test]
    fn deploy_episodes_are_bounded_like_eval_num_epi() {
        assert_eq!(parse(&["--episodes", "100000"]).episodes.episodes, 100_000);
        refused(&["--episodes", "0"], "must be at least 1");
        refused(
            &["--episodes", "100001"],
            "must be at most 100000, got 100001",
        );
    }
}
