//! `macdec demo`: the learning engine on a toy memory task (delayed recall with an LSTM Q-net).

use crate::nn::demo;
use anyhow::Result;

#[derive(clap::Args)]
pub(super) struct DemoArgs {
    /// Number of Adam steps.
    #[arg(long, default_value_t = demo::DemoConfig::default().steps)]
    steps: usize,
    /// Seed of the run.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

/// Train the toy task, printing the loss as it falls.
pub(super) fn run(args: DemoArgs) -> Result<()> {
    let DemoArgs { steps, seed } = args;
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
    Ok(())
}
