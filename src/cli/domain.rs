//! `macdec domain`: the policy's domain here against robots already listening elsewhere.

use anyhow::{Context, Result};

use super::bounds::parse_timeout_secs;
use super::episodes::{EpisodeArgs, EpisodePrinter};

#[derive(clap::Args)]
// The robots must serve this very policy: said where `domain --help` describes --policy.
// (`mut_arg` moves the argument to the end; moving --robots after it keeps the usage line's
// order `--policy <POLICY> --robots <ROBOTS>`.)
#[command(mut_arg("policy", |a| a.help(
    "Policy directory the robots run (their `info` must report its manifest)"
)))]
#[command(mut_arg("robots", |a| a))]
pub(super) struct DomainArgs {
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Comma-separated robot addresses in agent order, e.g. 127.0.0.1:7000,127.0.0.1:7001.
    // Listed right after --policy in the help, where it was before --policy moved to EpisodeArgs.
    #[arg(long, value_delimiter = ',', required = true, display_order = 0)]
    robots: Vec<std::net::SocketAddr>,
    /// Seconds to wait for a robot to accept the connection, and for each reply: the whole
    /// reply must arrive within this many seconds of its request (1 to 86400).
    #[arg(long, default_value_t = 30, value_parser = parse_timeout_secs)]
    timeout_secs: u64,
}

/// Play the episodes against robots listening at `--robots` and print each one's line.
pub(super) fn run(args: DomainArgs) -> Result<()> {
    let mut run = args.episodes.load()?;
    let mut printer = EpisodePrinter::new(args.episodes.trajectories);
    crate::deploy::remote::run_with_robots_at(
        &run.manifest,
        &args.robots,
        args.episodes.episodes,
        &mut run.rng,
        std::time::Duration::from_secs(args.timeout_secs),
        |trace| printer.print(trace),
    )
    .with_context(|| {
        format!(
            "running {} against its robots",
            args.episodes.policy.display()
        )
    })?;
    let place = format!("with {} remote robot(s)", run.manifest.agents.len());
    eprintln!("{}", printer.summary(&run, &place));
    Ok(())
}
