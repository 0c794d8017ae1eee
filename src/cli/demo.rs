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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> DemoArgs {
        match accepted("demo", flags) {
            Command::Demo(args) => args,
            _ => unreachable!("`demo` parses as Command::Demo"),
        }
    }

    #[test]
    fn demo_defaults_to_the_demo_config_s_steps_and_seed_0() {
        let args = parse(&[]);
        assert_eq!(args.steps, demo::DemoConfig::default().steps);
        assert_eq!(args.steps, 1500);
        assert_eq!(args.seed, 0);
        let args = parse(&["--steps", "20", "--seed", "7"]);
        assert_eq!((args.steps, args.seed), (20, 7));
    }

    #[test]
    fn demo_refuses_steps_and_seeds_that_are_not_whole_numbers() {
        assert_refused("demo", &["--steps", "x"], ErrorKind::ValueValidation, "'x'");
        assert_refused(
            "demo",
            &["--seed", "1.5"],
            ErrorKind::ValueValidation,
            "'1.5'",
        );
    }
}
