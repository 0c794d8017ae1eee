//! Documented upper bounds on every size a config or flag controls (README "Limits and
//! guarantees").
//!
//! Each bound is far above the paper's settings and low enough that a run cannot abort the
//! process on allocation: a value beyond one is a config error naming the key, found before any
//! run starts, instead of an out-of-memory abort that takes every parallel run down with it.

use crate::algos::hyper::{AcConfig, ValueConfig};

/// Runs one invocation may expand to (methods x sweep points x seeds).
pub const MAX_RUNS: usize = 100_000;
/// Seeds in one `--seeds` value or `seeds` list.
pub const MAX_SEEDS: usize = 10_000;
/// Largest run seed: a TOML integer is a signed 64-bit one, and every run records its seed in
/// its `config.toml`.
pub const MAX_SEED: u64 = i64::MAX as u64;
/// Box Pushing grid side (paper: 10 and 30); the domain checks it (`envs/box_pushing`).
pub use crate::envs::box_pushing::MAX_GRID_DIM;
/// Episode horizon in primitive steps, `env_terminate_step` (paper: 100 to 200); every domain
/// spec is held to it (`envs::domain`).
pub use crate::envs::domain::MAX_HORIZON;
/// Window length `trace_len` and minimum kept records `sub_trace_len` (paper: 15 and 45).
pub const MAX_TRACE_LEN: usize = 100_000;
/// Sequences per batch, `batch_size` (paper: 128 and 16).
pub const MAX_BATCH_SIZE: usize = 65_536;
/// Width of any net layer, `*_mlp_layer_size` and `*_rnn_h_size` (paper: 32 and 64); policy
/// files are held to it too.
pub use crate::nn::MAX_NET_WIDTH;
/// Elements of one batch activation: batch_size x sequence length x widest layer
/// (2^28 f32 = 1 GiB; paper: about 1.5e5).
pub const MAX_BATCH_ELEMENTS: u128 = 1 << 28;
/// Records the replay buffer may hold when full: replay_buffer_size x sequence length
/// (paper: 1.2e6).
pub const MAX_REPLAY_RECORDS: u128 = 1 << 26;
/// Training episodes, `total_epi` (paper: 40000).
pub const MAX_TOTAL_EPI: usize = 100_000_000;
/// Evaluation rows a run keeps, total_epi / eval_freq (paper: 4000).
pub const MAX_EVAL_ROWS: usize = 1_000_000;
/// Greedy episodes per evaluation, `eval_num_epi` (paper: 1 and 20).
pub const MAX_EVAL_NUM_EPI: usize = 100_000;
/// Environments an actor-critic run steps in lockstep, `n_env` (published: at most 48).
pub use crate::algos::actor_critic::config::MAX_N_ENV;

/// Check a resolved config's sizes against the bounds above, for a domain whose episodes last at
/// most `horizon` primitive steps. Returns the key and why.
pub fn check_sizes(c: &ValueConfig, horizon: usize) -> Result<(), (&'static str, String)> {
    let simple = [
        ("env_terminate_step", horizon, MAX_HORIZON),
        ("trace_len", c.trace_len, MAX_TRACE_LEN),
        ("sub_trace_len", c.sub_trace_len, MAX_TRACE_LEN),
        ("batch_size", c.batch_size, MAX_BATCH_SIZE),
        ("dec_mlp_layer_size", c.dec_mlp_layer_size, MAX_NET_WIDTH),
        ("dec_rnn_h_size", c.dec_rnn_h_size, MAX_NET_WIDTH),
        ("cen_mlp_layer_size", c.cen_mlp_layer_size, MAX_NET_WIDTH),
        ("cen_rnn_h_size", c.cen_rnn_h_size, MAX_NET_WIDTH),
        ("total_epi", c.total_epi, MAX_TOTAL_EPI),
        ("eval_num_epi", c.eval_num_epi, MAX_EVAL_NUM_EPI),
    ];
    for (key, value, max) in simple {
        if value > max {
            return Err((key, format!("must be at most {max}, got {value}")));
        }
    }
    // Sequences are windows of trace_len records, or whole episodes with the episode buffer.
    let (seq_key, seq_len) = if c.sample_epi {
        ("env_terminate_step", horizon)
    } else {
        ("trace_len", c.trace_len)
    };
    let widest = [
        c.dec_mlp_layer_size,
        c.dec_rnn_h_size,
        c.cen_mlp_layer_size,
        c.cen_rnn_h_size,
    ]
    .into_iter()
    .max()
    .unwrap_or(1);
    let elements = c.batch_size as u128 * seq_len as u128 * widest as u128;
    if elements > MAX_BATCH_ELEMENTS {
        return Err((
            "batch_size",
            format!(
                "batch_size x {seq_key} x widest layer = {} x {seq_len} x {widest} = {elements} \
                 elements per batch tensor, at most {MAX_BATCH_ELEMENTS}",
                c.batch_size
            ),
        ));
    }
    let records = c.replay_buffer_size as u128 * seq_len as u128;
    if records > MAX_REPLAY_RECORDS {
        return Err((
            "replay_buffer_size",
            format!(
                "replay_buffer_size x {seq_key} = {} x {seq_len} = {records} records when full, \
                 at most {MAX_REPLAY_RECORDS}",
                c.replay_buffer_size
            ),
        ));
    }
    let rows = c.total_epi / c.eval_freq.max(1);
    if rows > MAX_EVAL_ROWS {
        return Err((
            "eval_freq",
            format!(
                "total_epi / eval_freq = {rows} evaluation rows, at most {MAX_EVAL_ROWS}: evaluate less often"
            ),
        ));
    }
    Ok(())
}

/// Worker threads for `runs` runs when `requested` were asked for: at most one per run.
pub fn worker_threads(requested: usize, runs: usize) -> usize {
    requested.min(runs).max(1)
}

/// Check an actor-critic config's sizes against the bounds above and [`MAX_N_ENV`], for a
/// domain whose episodes last at most `horizon` primitive steps. Returns the key and why.
pub fn check_actor_critic_sizes(
    c: &AcConfig,
    horizon: usize,
) -> Result<(), (&'static str, String)> {
    let simple = [
        ("env_terminate_step", horizon, MAX_HORIZON),
        ("total_epi", c.total_epi, MAX_TOTAL_EPI),
        ("eval_num_epi", c.eval_num_epi, MAX_EVAL_NUM_EPI),
        ("n_env", c.n_env, MAX_N_ENV),
        ("train_freq", c.train_freq, MAX_N_ENV * 16),
        ("n_step_TD", c.n_step_td, MAX_HORIZON),
        ("a_rnn_layer_size", c.a_rnn_layer_size, MAX_NET_WIDTH),
        ("c_rnn_layer_size", c.c_rnn_layer_size, MAX_NET_WIDTH),
        ("c_mid_layer_size", c.c_mid_layer_size, MAX_NET_WIDTH),
    ];
    for (key, value, max) in simple {
        if value > max {
            return Err((key, format!("must be at most {max}, got {value}")));
        }
    }
    for (key, sizes) in [
        ("a_mlp_layer_size", &c.a_mlp_layer_size),
        ("c_mlp_layer_size", &c.c_mlp_layer_size),
    ] {
        if sizes.len() != 2 || sizes.iter().any(|&s| s == 0 || s > MAX_NET_WIDTH) {
            return Err((
                key,
                format!(
                    "must be two widths [before, after] the recurrent layer, each 1..={MAX_NET_WIDTH}, got {sizes:?}"
                ),
            ));
        }
    }
    // One update's batch activations: train_freq episodes x horizon x the widest layer (x3,
    // the GRU's gates).
    let widest = [c.a_rnn_layer_size, c.c_rnn_layer_size, c.c_mid_layer_size]
        .into_iter()
        .chain(c.a_mlp_layer_size.iter().copied())
        .chain(c.c_mlp_layer_size.iter().copied())
        .max()
        .unwrap_or(1) as u128;
    let elements = c.train_freq as u128 * horizon as u128 * widest * 3;
    if elements > MAX_BATCH_ELEMENTS {
        return Err((
            "train_freq",
            format!(
                "train_freq x env_terminate_step x the widest layer is {elements} activations, beyond {MAX_BATCH_ELEMENTS}"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::method::Method;

    use crate::experiment::definition::paper::value_paper_defaults as paper_defaults;

    #[test]
    fn the_papers_settings_are_within_every_bound() {
        for grid in [10, 30] {
            for m in [Method::DecHddrqn, Method::CenDdrqn, Method::Our1] {
                let env = crate::envs::box_pushing::paper_spec(grid);
                check_sizes(&paper_defaults(&env, m), env.horizon()).unwrap();
            }
        }
        for m in [Method::DecHddrqn, Method::CenDdrqn, Method::Our2] {
            check_sizes(
                &paper_defaults(&crate::envs::warehouse::paper_spec(), m),
                150,
            )
            .unwrap();
        }
    }

    #[test]
    fn each_size_beyond_its_bound_names_its_key() {
        let base = paper_defaults(&crate::envs::box_pushing::paper_spec(10), Method::Our1);
        type Edit = fn(&mut ValueConfig, &mut usize);
        let cases: [(&str, Edit); 6] = [
            ("batch_size", |c, _| c.batch_size = MAX_BATCH_SIZE + 1),
            ("dec_rnn_h_size", |c, _| c.dec_rnn_h_size = usize::MAX),
            ("env_terminate_step", |_, horizon| *horizon = 1 << 40),
            ("batch_size", |c, _| {
                c.batch_size = 60_000;
                c.trace_len = 60_000;
            }),
            ("replay_buffer_size", |c, _| {
                c.replay_buffer_size = usize::MAX
            }),
            ("eval_freq", |c, _| {
                c.total_epi = 50_000_000;
                c.eval_freq = 1;
            }),
        ];
        for (key, edit) in cases {
            let (mut c, mut horizon) = (base.clone(), 100);
            edit(&mut c, &mut horizon);
            assert_eq!(check_sizes(&c, horizon).unwrap_err().0, key);
        }
    }

    #[test]
    fn workers_never_exceed_the_runs() {
        assert_eq!(worker_threads(100_000, 3), 3);
        assert_eq!(worker_threads(2, 3), 2);
        assert_eq!(worker_threads(8, 0), 1);
    }
}
