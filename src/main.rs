//! The `macdec` command line: parse, call the library, report. No logic lives here.

use anyhow::Result;
use clap::{Parser, Subcommand, ValueEnum};

use macdec::bench::nets;
use macdec::nn::demo;

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
    /// The learning engine on a toy memory task: an LSTM Q-net learns delayed recall.
    Demo {
        /// Number of Adam steps.
        #[arg(long, default_value_t = demo::DemoConfig::default().steps)]
        steps: usize,
        /// Seed of the run.
        #[arg(long, default_value_t = 0)]
        seed: u64,
    },
    /// Time a hot path.
    Bench {
        /// What to time.
        what: BenchWhat,
        /// Timed iterations per configuration.
        #[arg(long, default_value_t = 200)]
        iters: usize,
        /// Only the configuration with this name (e.g. torch-wtd).
        #[arg(long)]
        only: Option<String>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum BenchWhat {
    /// One Q-net training update (forward, backward, Adam) at the paper's shapes, 1 thread.
    Nets,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Demo { steps, seed } => {
            let cfg = demo::DemoConfig {
                steps,
                seed,
                ..demo::DemoConfig::default()
            };
            println!(
                "delayed recall with an LSTM Q-net: {} steps, batch {}, seed {} \
                 (a net without memory cannot go below {:.4})",
                cfg.steps,
                cfg.batch,
                cfg.seed,
                demo::MEMORYLESS_LOSS
            );
            let t0 = std::time::Instant::now();
            demo::run(&cfg, |step, loss| {
                println!("step {step:>6}  loss {loss:.5}")
            })?;
            println!("done in {:.1} s", t0.elapsed().as_secs_f64());
        }
        Command::Bench {
            what: BenchWhat::Nets,
            iters,
            only,
        } => {
            let mut results = Vec::new();
            let chosen = nets::SHAPES
                .iter()
                .filter(|s| only.as_deref().is_none_or(|o| o == s.name));
            for shape in chosen {
                results.push(nets::bench_shape(shape, iters, iters.div_ceil(10).max(3)));
            }
            print!("{}", nets::format_table(&results));
        }
    }
    Ok(())
}
