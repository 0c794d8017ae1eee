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
    use crate::deploy::processes::deploy_streaming;
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
