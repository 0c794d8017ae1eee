//! The `macdec` command line: parse, call the library, report. No logic lives here.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Parser, Subcommand, ValueEnum};

#[derive(Parser)]
#[command(
    name = "macdec",
    version,
    about = "Macro-action multi-agent deep RL (MacDec-MADDRQN, ICRA 2020)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Replay a macro-action log and print the trajectory as JSON lines.
    Replay {
        /// JSON file: {"env": "box-pushing", "grid": 10, "horizon": 100, "steps": [[a0, a1], ...]}
        #[arg(long)]
        actions: PathBuf,
        /// Also print an ASCII picture of the state after every step (to stderr).
        #[arg(long)]
        verbose: bool,
    },
    /// Measure speed.
    Bench {
        /// What to measure.
        what: BenchTarget,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum BenchTarget {
    /// Environment primitive steps per second with random macro-actions (single thread).
    Envs,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Replay { actions, verbose } => replay(&actions, verbose),
        Command::Bench { what } => match what {
            BenchTarget::Envs => bench_envs(),
        },
    }
}

fn replay(path: &Path, verbose: bool) -> Result<()> {
    use macdec::envs::replay::{parse_replay, run_replay};
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading replay file {}", path.display()))?;
    let file = parse_replay(&text).with_context(|| format!("parsing {}", path.display()))?;
    let replay =
        run_replay(&file, verbose).with_context(|| format!("replaying {}", path.display()))?;
    let mut out = std::io::stdout().lock();
    for frame in &replay.frames {
        serde_json::to_writer(&mut out, &frame.line)?;
        writeln!(out)?;
        if let Some(picture) = &frame.picture {
            out.flush()?;
            eprintln!("{picture}");
        }
    }
    if replay.unused_steps > 0 {
        eprintln!(
            "note: the episode ended with {} rows of `steps` unused",
            replay.unused_steps
        );
    }
    Ok(())
}

fn bench_envs() -> Result<()> {
    const MIN_STEPS: u64 = 20_000_000;
    println!("environment primitive steps/s, random macro-actions, single thread, >= {MIN_STEPS} steps each");
    for (name, spec) in macdec::envs::bench::bench_suite() {
        let r = macdec::envs::bench::bench_env(name, spec, MIN_STEPS)
            .with_context(|| format!("benchmarking {name}"))?;
        println!(
            "{:<34} {:>12.0} steps/s  ({} steps, {} episodes, {:.2} s)",
            r.name, r.steps_per_second, r.steps, r.episodes, r.seconds
        );
    }
    Ok(())
}
