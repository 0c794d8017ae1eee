//! Speed measurement support: run uniformly random macro-actions for a number of primitive steps
//! (the benchmark, target >= 100x the Python reference's ~60k steps/s).

use std::time::Instant;

use rand::Rng;
use rand::SeedableRng;

use super::{Warehouse, WarehouseParams};
use crate::envs::{EnvError, EnvRng, MacroEnv};

/// What a random run did; the sums make the work observable (and checkable) to the caller.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RandomRunStats {
    /// Primitive steps taken.
    pub steps: u64,
    /// Episodes finished (reset after each `done`).
    pub episodes: u64,
    /// Sum of all step rewards.
    pub total_reward: f64,
}

/// Step `env` for `n_steps` primitive steps, each free agent drawing a uniform macro-action from
/// `rng` (busy agents get 0, ignored), resetting whenever an episode ends. The env's own random
/// draws (Warehouse noise) come from the same stream. Works for any [`MacroEnv`].
pub fn run_random_macro_actions<E: MacroEnv>(
    env: &mut E,
    n_steps: u64,
    rng: &mut EnvRng,
) -> Result<RandomRunStats, EnvError> {
    let n_actions = env.n_actions().to_vec();
    let mut actions = vec![0usize; n_actions.len()];
    let mut stats = RandomRunStats {
        steps: 0,
        episodes: 0,
        total_reward: 0.0,
    };
    env.reset(rng);
    while stats.steps < n_steps {
        for (i, a) in actions.iter_mut().enumerate() {
            *a = if env.is_free(i) {
                rng.gen_range(0..n_actions[i])
            } else {
                0
            };
        }
        let out = env.step(&actions, rng)?;
        stats.steps += 1;
        stats.total_reward += out.reward;
        if out.done {
            stats.episodes += 1;
            env.reset(rng);
        }
    }
    Ok(stats)
}

/// Primitive Warehouse steps per second with random macro-actions (single thread), and the run's
/// statistics. `seed` seeds the ChaCha8 stream.
pub fn measure_random_steps_per_sec(
    params: WarehouseParams,
    n_steps: u64,
    seed: u64,
) -> Result<(f64, RandomRunStats), EnvError> {
    let mut env = Warehouse::new(params)?;
    let mut rng = EnvRng::seed_from_u64(seed);
    let start = Instant::now();
    let stats = run_random_macro_actions(&mut env, n_steps, &mut rng)?;
    let secs = start.elapsed().as_secs_f64();
    Ok((stats.steps as f64 / secs.max(1e-9), stats))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_run_takes_exactly_the_requested_steps() {
        let mut env = Warehouse::paper(150).unwrap();
        let mut rng = EnvRng::seed_from_u64(1);
        let stats = run_random_macro_actions(&mut env, 3_000, &mut rng).unwrap();
        assert_eq!(stats.steps, 3_000);
        assert!(stats.episodes >= 3_000 / 150);
        // Every step costs at least 1, and at most 3 deliveries per episode.
        assert!(stats.total_reward <= -3_000.0 + 300.0 * (stats.episodes as f64 + 1.0));
    }

    /// Run with: cargo test --release warehouse_steps_per_sec -- --ignored --nocapture
    #[test]
    #[ignore]
    fn warehouse_steps_per_sec() {
        let n = 50_000_000;
        for (name, params) in [
            ("paper (no noise)", WarehouseParams::default()),
            (
                "noise 0.1",
                WarehouseParams {
                    tb_move_noisy: 0.1,
                    ..WarehouseParams::default()
                },
            ),
        ] {
            let (rate, stats) = measure_random_steps_per_sec(params, n, 42).unwrap();
            println!(
                "WTD {name}: {rate:.3e} primitive steps/s ({} steps, {} episodes)",
                stats.steps, stats.episodes
            );
        }
    }
}
