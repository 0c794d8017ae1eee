//! `macdec bench`: speed of the environments, the nets, the recurrent layer and whole training.

use crate::bench::nets;
use anyhow::{Context, Result};
use clap::ValueEnum;

#[derive(clap::Args)]
pub(super) struct BenchArgs {
    /// What to measure.
    what: BenchTarget,
    /// Timed iterations per configuration (nets).
    #[arg(long, default_value_t = 200)]
    iters: usize,
    /// Only the configuration with this name (nets: e.g. torch-wtd; train: e.g. "bp10 our1").
    #[arg(long)]
    only: Option<String>,
    /// Training episodes per run (train).
    #[arg(long, default_value_t = 200)]
    episodes: usize,
}

#[derive(Clone, Copy, ValueEnum)]
enum BenchTarget {
    /// Environment primitive steps per second with random macro-actions (single thread).
    Envs,
    /// One Q-net training update (forward, backward, Adam) at the paper's shapes, 1 thread.
    Nets,
    /// Whole training (first --episodes episodes) of every method on BP 10x10 and WTD, 1 thread;
    /// then two BP Our-1 runs at once on two threads against one alone.
    Train,
    /// The recurrent layer alone: GRU beside LSTM, forward + backward over sequences at the
    /// nets' shapes, 1 thread, time per step and per flop.
    Gru,
}

/// Run the chosen measurement and print its table.
pub(super) fn run(args: BenchArgs) -> Result<()> {
    let BenchArgs {
        what,
        iters,
        only,
        episodes,
    } = args;
    match what {
        BenchTarget::Train => bench_train(only.as_deref(), episodes),
        BenchTarget::Envs => bench_envs(),
        BenchTarget::Gru => {
            print!("{}", crate::bench::gru::run(only.as_deref(), iters));
            Ok(())
        }
        BenchTarget::Nets => {
            let results: Vec<_> = nets::SHAPES
                .iter()
                .filter(|s| only.as_deref().is_none_or(|o| o == s.name))
                .map(|shape| nets::bench_shape(shape, iters, iters.div_ceil(10).max(3)))
                .collect();
            print!("{}", nets::format_table(&results));
            Ok(())
        }
    }
}

fn bench_train(only: Option<&str>, episodes: usize) -> Result<()> {
    use crate::bench::train;
    let mut rows = Vec::new();
    for (env, method) in train::suite() {
        if only.is_some_and(|o| o != train::name(&env, method)) {
            continue;
        }
        let row = train::bench_train(env, method, episodes)?;
        eprintln!("{}: {:.1} s", row.name, row.seconds);
        rows.push(row);
    }
    print!("{}", train::format_table(&rows));
    if only.is_none() {
        // Two runs on two threads should take no longer than one alone (no shared state).
        let our1: crate::algos::families::Method = "our1".parse().expect("a method");
        let one = train::bench_train(crate::envs::box_pushing::paper_spec(10), our1, episodes)?;
        let (a, b) = rayon::join(
            || train::bench_train(crate::envs::box_pushing::paper_spec(10), our1, episodes),
            || train::bench_train(crate::envs::box_pushing::paper_spec(10), our1, episodes),
        );
        let (a, b) = (a?, b?);
        println!(
            "\nbp10 our1 alone: {:.1} s; two at once on two threads: {:.1} s and {:.1} s (ratio {:.2})",
            one.seconds,
            a.seconds,
            b.seconds,
            a.seconds.max(b.seconds) / one.seconds
        );
    }
    Ok(())
}

fn bench_envs() -> Result<()> {
    const MIN_STEPS: u64 = 20_000_000;
    println!("environment primitive steps/s, random macro-actions, single thread, >= {MIN_STEPS} steps each");
    for (name, spec) in crate::envs::bench::bench_suite() {
        let r = crate::envs::bench::bench_env(name, spec, MIN_STEPS)
            .with_context(|| format!("benchmarking {name}"))?;
        println!(
            "{:<34} {:>12.0} steps/s  ({} steps, {} episodes, {:.2} s)",
            r.name, r.steps_per_second, r.steps, r.episodes, r.seconds
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> BenchArgs {
        match accepted("bench", flags) {
            Command::Bench(args) => args,
            _ => unreachable!("`bench` parses as Command::Bench"),
        }
    }

    #[test]
    fn bench_names_what_to_measure() {
        assert_refused("bench", &[], ErrorKind::MissingRequiredArgument, "<WHAT>");
        assert!(matches!(parse(&["envs"]).what, BenchTarget::Envs));
        assert!(matches!(parse(&["nets"]).what, BenchTarget::Nets));
        assert!(matches!(parse(&["train"]).what, BenchTarget::Train));
        assert!(matches!(parse(&["gru"]).what, BenchTarget::Gru));
        assert_refused("bench", &["lstm"], ErrorKind::InvalidValue, "'lstm'");
    }

    #[test]
    fn bench_times_200_iterations_and_200_episodes_of_everything_by_default() {
        let args = parse(&["nets"]);
        assert_eq!((args.iters, args.episodes, args.only), (200, 200, None));
        let args = parse(&["train", "--only", "bp10 our1", "--episodes", "20"]);
        assert_eq!(args.only.as_deref(), Some("bp10 our1"));
        assert_eq!(args.episodes, 20);
        assert_refused(
            "bench",
            &["nets", "--iters", "x"],
            ErrorKind::ValueValidation,
            "'x'",
        );
    }
}
