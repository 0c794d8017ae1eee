//! Documented upper bounds on every size a config or flag controls (README "Limits and
//! guarantees").
//!
//! Each bound is far above the paper's settings and low enough that a run cannot abort the
//! process on allocation: a value beyond one is a config error naming the key, found before any
//! run starts, instead of an out-of-memory abort that takes every parallel run down with it.

/// Runs one invocation may expand to (methods x sweep points x seeds).
pub const MAX_RUNS: usize = 100_000;
/// Seeds in one `--seeds` value or `seeds` list.
pub const MAX_SEEDS: usize = 10_000;
/// Largest run seed: a TOML integer is a signed 64-bit one, and every run records its seed in
/// its `config.toml`.
pub const MAX_SEED: u64 = i64::MAX as u64;
/// Environments an actor-critic run steps in lockstep, `n_env` (published: at most 48).
pub use crate::algos::actor_critic::config::MAX_N_ENV;
/// The bounds of every family's config (checked by each family's `check`).
pub use crate::algos::config_checks::{
    MAX_BATCH_ELEMENTS, MAX_EVAL_NUM_EPI, MAX_EVAL_ROWS, MAX_TOTAL_EPI,
};
/// The value family's window, batch and replay bounds.
pub use crate::algos::value::config::{MAX_BATCH_SIZE, MAX_REPLAY_RECORDS, MAX_TRACE_LEN};
/// Box Pushing grid side (paper: 10 and 30); the domain checks it (`envs/box_pushing`).
pub use crate::envs::box_pushing::MAX_GRID_DIM;
/// Episode horizon in primitive steps, `env_terminate_step` (paper: 100 to 200); every domain
/// spec is held to it (`envs::domain`).
pub use crate::envs::domain::MAX_HORIZON;

/// Worker threads for `runs` runs when `requested` were asked for: at most one per run.
pub fn worker_threads(requested: usize, runs: usize) -> usize {
    requested.min(runs).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workers_never_exceed_the_runs() {
        assert_eq!(worker_threads(100_000, 3), 3);
        assert_eq!(worker_threads(2, 3), 2);
        assert_eq!(worker_threads(8, 0), 1);
    }
}
