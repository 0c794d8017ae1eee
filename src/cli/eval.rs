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
        crate::deploy::local_eval::Choice::Sampled
    } else {
        crate::deploy::local_eval::Choice::Greedy
    };
    crate::deploy::local_eval::eval_policy(
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
