//! The value family's hyperparameters under the ICRA code's flag names (`docs/ALGORITHMS.md`
//! §10), the paper's settings per domain and method, and the family's range checks.

use crate::algos::config_checks::{
    check_at_most, check_batch_activations, check_discount, check_eval_rows, check_positive,
    check_rates, check_train_freq_steps, check_unit, NetWidths, MAX_EVAL_NUM_EPI, MAX_HORIZON,
    MAX_NET_WIDTH, MAX_TOTAL_EPI,
};
use crate::algos::learner::FamilyConfig;
use crate::algos::value::method::ValueMethod;
use crate::envs::{EnvShape, EnvSpec};
use serde::{Deserialize, Serialize};

/// Window length `trace_len` and minimum kept records `sub_trace_len` (paper: 15 and 45).
pub const MAX_TRACE_LEN: usize = 100_000;
/// Sequences per batch, `batch_size` (paper: 128 and 16).
pub const MAX_BATCH_SIZE: usize = 65_536;
/// Records the replay buffer may hold when full: replay_buffer_size x sequence length
/// (paper: 1.2e6).
pub const MAX_REPLAY_RECORDS: u128 = 1 << 26;
/// Values (observation entries, actions, rewards, flags) the full replay buffer holds: records x
/// (2 x the joint observation + 5 per agent + 1), 2^30 = 4 GiB of f32 (paper: about 1e8).
pub const MAX_REPLAY_VALUES: u128 = 1 << 30;

/// The value methods' resolved hyperparameters (the ICRA code's flags). Unknown keys are refused,
/// so a typo in a hand-edited config fails instead of being ignored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValueConfig {
    /// Training episodes (Our-2: decentralized-env episodes).
    pub total_epi: usize,
    /// Replay capacity: windows for the windowed buffer, episodes with `sample_epi` (`docs/ALGORITHMS.md` §3).
    pub replay_buffer_size: usize,
    /// Whole-episode replay (WTD) instead of fixed-length windows (BP).
    pub sample_epi: bool,
    /// Hysteresis moves from init_h to end_h over h_stable_at episodes (`docs/ALGORITHMS.md` §5.6).
    pub dynamic_h: bool,
    /// Hysteresis h at the start (with `dynamic_h`).
    pub init_h: f64,
    /// Hysteresis h from `h_stable_at` episodes on.
    pub end_h: f64,
    /// Episodes over which h moves from `init_h` to `end_h`.
    pub h_stable_at: usize,
    /// Linear epsilon decay over eps_l_d_steps episodes (`docs/ALGORITHMS.md` §4.1); else the exponential schedule.
    pub eps_l_d: bool,
    /// Episodes of the linear epsilon decay.
    pub eps_l_d_steps: usize,
    /// Epsilon once the linear decay is over.
    pub eps_end: f64,
    /// Carry the exploring nets' hidden state during training episodes (`docs/ALGORITHMS.md` §4.4, quirk Q1).
    pub h_explore: bool,
    /// Our-1 / Our-1-R explore with the centralized net (`docs/ALGORITHMS.md` §4.6).
    pub cen_explore: bool,
    /// Adam learning rate of every net.
    pub l_rate: f64,
    /// Discount per macro-transition in targets, per primitive step in evaluation (Q5, Q13).
    pub discount: f64,
    /// Episodes to collect before the first training iteration.
    pub start_train: usize,
    /// Main-loop steps between training iterations.
    pub train_freq: usize,
    /// Main-loop steps between hard target-net copies.
    pub target_update_freq: usize,
    /// Window length in primitive steps (windowed buffer only).
    pub trace_len: usize,
    /// Minimum kept records for a sequence to be trained on.
    pub sub_trace_len: usize,
    /// Sequences (windows or episodes) per training batch.
    pub batch_size: usize,
    /// Decentralized nets: MLP width M and LSTM width H (Dec-HDDRQN's `mlp_layer_size`/`rnn_h_size`).
    pub dec_mlp_layer_size: usize,
    /// H of the decentralized nets.
    pub dec_rnn_h_size: usize,
    /// Centralized net: M and H (Cen-DDRQN's `mlp_layer_size`/`rnn_h_size`).
    pub cen_mlp_layer_size: usize,
    /// H of the centralized net.
    pub cen_rnn_h_size: usize,
    /// Evaluate before training and then every eval_freq training episodes (ICRA code: 10).
    pub eval_freq: usize,
    /// Greedy episodes per evaluation (ICRA code: 1; Dec-HDDRQN 20).
    pub eval_num_epi: usize,
    /// Training episodes between checkpoints (ours; the reference has none).
    pub checkpoint_freq: usize,
    /// Quirk Q9: when one agent's view of a batch is empty, skip every decentralized update of
    /// that iteration (faithful) instead of just that agent's.
    pub early_return_skips_all: bool,
}

impl FamilyConfig for ValueConfig {
    fn total_epi(&self) -> usize {
        self.total_epi
    }
    fn set_total_epi(&mut self, episodes: usize) {
        self.total_epi = episodes;
    }
    fn checkpoint_freq(&self) -> usize {
        self.checkpoint_freq
    }
    fn discount(&self) -> f64 {
        self.discount
    }
}

/// The ICRA paper's common settings for `method` (its Box Pushing 10 x 10 runs, `docs/ALGORITHMS.md` §10.1).
pub fn base_settings(method: ValueMethod) -> ValueConfig {
    let (init_h, end_h) = method.paper_hysteresis();
    ValueConfig {
        total_epi: 15000,
        replay_buffer_size: 80000,
        sample_epi: false,
        dynamic_h: true,
        init_h,
        end_h,
        h_stable_at: 6000,
        eps_l_d: true,
        eps_l_d_steps: 6000,
        eps_end: 0.1,
        h_explore: false,
        cen_explore: method.paper_cen_explore(),
        l_rate: 0.001,
        discount: 0.98,
        start_train: 2,
        train_freq: 15,
        target_update_freq: 5000,
        trace_len: 15,
        sub_trace_len: 1,
        batch_size: 128,
        dec_mlp_layer_size: 32,
        dec_rnn_h_size: 32,
        cen_mlp_layer_size: 32,
        cen_rnn_h_size: 64,
        eval_freq: 10,
        eval_num_epi: method.paper_eval_num_epi(),
        checkpoint_freq: 500,
        early_return_skips_all: true,
    }
}

/// The ICRA paper's settings for value `method` on `env` (`docs/ALGORITHMS.md` §10), before user
/// keys: [`base_settings`] with the domain's paper keys over them.
pub fn paper_defaults(env: &EnvSpec, method: ValueMethod) -> ValueConfig {
    let mut table = toml::Table::try_from(base_settings(method)).expect("a table");
    for (key, value) in crate::algos::value::published::settings(env) {
        assert!(
            table.contains_key(&key),
            "{}'s paper settings name `{key}`, which is not a hyperparameter",
            env.env_name()
        );
        table.insert(key, value);
    }
    ValueConfig::deserialize(toml::Value::Table(table))
        .unwrap_or_else(|e| panic!("{}'s paper settings do not type-check: {e}", env.env_name()))
}

/// The value family's range checks (see [`FamilyMethod::check`](crate::algos::family::FamilyMethod::check)).
pub fn check(
    c: &ValueConfig,
    method: ValueMethod,
    shape: &EnvShape,
) -> Result<(), (&'static str, String)> {
    check_positive(&[
        ("env_terminate_step", shape.horizon),
        ("total_epi", c.total_epi),
        ("replay_buffer_size", c.replay_buffer_size),
        ("h_stable_at", c.h_stable_at),
        ("eps_l_d_steps", c.eps_l_d_steps),
        ("train_freq", c.train_freq),
        ("target_update_freq", c.target_update_freq),
        ("trace_len", c.trace_len),
        ("sub_trace_len", c.sub_trace_len),
        ("batch_size", c.batch_size),
        ("dec_mlp_layer_size", c.dec_mlp_layer_size),
        ("dec_rnn_h_size", c.dec_rnn_h_size),
        ("cen_mlp_layer_size", c.cen_mlp_layer_size),
        ("cen_rnn_h_size", c.cen_rnn_h_size),
        ("eval_freq", c.eval_freq),
        ("eval_num_epi", c.eval_num_epi),
        ("checkpoint_freq", c.checkpoint_freq),
    ])?;
    if c.start_train == 0 {
        return Err((
            "start_train",
            "must be >= 1: training starts once an episode has been collected".into(),
        ));
    }
    if c.start_train > c.total_epi {
        return Err((
            "start_train",
            format!(
                "must be at most total_epi ({}), got {}: training starts after start_train episodes, so no update would run",
                c.total_epi, c.start_train
            ),
        ));
    }
    check_train_freq_steps(c.train_freq, c.total_epi, shape.horizon)?;
    if !c.total_epi.is_multiple_of(c.eval_freq) {
        return Err((
            "total_epi",
            format!(
                "must be a multiple of eval_freq ({}), got {}: the last {} episodes would never be evaluated",
                c.eval_freq,
                c.total_epi,
                c.total_epi % c.eval_freq
            ),
        ));
    }
    check_sizes(c, method, shape)?;
    check_unit(&[
        ("eps_end", c.eps_end),
        ("discount", c.discount),
        ("init_h", c.init_h),
        ("end_h", c.end_h),
    ])?;
    check_discount("discount", c.discount)?;
    check_rates(&[("l_rate", c.l_rate)])?;
    if method.requires_episode_buffer() && !c.sample_epi {
        // `docs/ALGORITHMS.md` Q10: the reference's windowed path for Our-2 crashes; we keep Our-2 episode-based.
        return Err((
            "sample_epi",
            "our2 needs the episode buffer (sample_epi = true), as in the reference (`docs/ALGORITHMS.md` Q10)"
                .into(),
        ));
    }
    Ok(())
}

/// Check a value config's sizes against the bounds, for a domain of this shape (its horizon,
/// observation and macro-action counts). Returns the key and why.
fn check_sizes(
    c: &ValueConfig,
    method: ValueMethod,
    shape: &EnvShape,
) -> Result<(), (&'static str, String)> {
    let horizon = shape.horizon;
    check_at_most(&[
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
    ])?;
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
    .unwrap_or(1) as u128;
    // The centralized Q-net reads the joint observation and scores every joint macro-action.
    let (input, output) = if method.has_cen_net() {
        (shape.joint_obs_size(), shape.n_joint_actions())
    } else {
        (shape.widest_obs(), shape.widest_actions())
    };
    check_batch_activations(
        ("batch_size", c.batch_size),
        (seq_key, seq_len),
        NetWidths {
            hidden: widest,
            input,
            output,
        },
    )?;
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
    // A record holds the joint observation and the next one, and per agent its action, its
    // macro-reward and three flags.
    let record_values = 2 * shape.joint_obs_size() + 5 * shape.n_actions.len() as u128 + 1;
    let values = records.saturating_mul(record_values);
    if values > MAX_REPLAY_VALUES {
        return Err((
            "replay_buffer_size",
            format!(
                "replay_buffer_size x {seq_key} x a record's values = {} x {seq_len} x \
                 {record_values} = {values} values when full, at most {MAX_REPLAY_VALUES}",
                c.replay_buffer_size
            ),
        ));
    }
    check_eval_rows(c.total_epi, c.eval_freq)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_pushing_windows_follow_the_grid_and_warehouse_replays_episodes() {
        let bp10 = paper_defaults(&crate::envs::box_pushing::paper_spec(10), ValueMethod::Our1);
        assert_eq!((bp10.trace_len, bp10.train_freq), (15, 15));
        let bp30 = paper_defaults(&crate::envs::box_pushing::paper_spec(30), ValueMethod::Our1);
        assert_eq!((bp30.trace_len, bp30.train_freq), (45, 45));
        let wtd = paper_defaults(&crate::envs::warehouse::paper_spec(), ValueMethod::Our2);
        assert!(wtd.sample_epi && wtd.h_explore);
        assert_eq!(
            (wtd.discount, wtd.batch_size, wtd.total_epi),
            (1.0, 16, 40000)
        );
        assert_eq!(bp10.discount, 0.98);
    }

    fn shape(spec: &EnvSpec) -> EnvShape {
        EnvShape::of(spec).unwrap()
    }

    #[test]
    fn the_papers_settings_are_within_every_bound() {
        use ValueMethod::{CenDdrqn, DecHddrqn, Our1, Our2};
        for grid in [10, 30] {
            for m in [DecHddrqn, CenDdrqn, Our1] {
                let env = crate::envs::box_pushing::paper_spec(grid);
                check(&paper_defaults(&env, m), m, &shape(&env)).unwrap();
            }
        }
        for m in [DecHddrqn, CenDdrqn, Our2] {
            let env = crate::envs::warehouse::paper_spec();
            check(&paper_defaults(&env, m), m, &shape(&env)).unwrap();
        }
    }

    #[test]
    fn each_size_beyond_its_bound_names_its_key() {
        let base = paper_defaults(&crate::envs::box_pushing::paper_spec(10), ValueMethod::Our1);
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
        let bp10 = shape(&crate::envs::box_pushing::paper_spec(10));
        for (key, edit) in cases {
            let (mut c, mut bp10) = (base.clone(), bp10.clone());
            edit(&mut c, &mut bp10.horizon);
            assert_eq!(
                check_sizes(&c, ValueMethod::Our1, &bp10).unwrap_err().0,
                key
            );
        }
    }

    #[test]
    fn a_joint_q_net_counts_its_joint_action_output_and_a_full_replay_its_observations() {
        // Cen-DDRQN on a domain of four agents with 40 macro-actions each: 2.56 M joint
        // macro-actions. The paper's batch of 32 windows of 15 would need 32 x 15 x 16 x 2.56 M
        // values in one update; the decentralized Dec-HDDRQN outputs only 40 per agent.
        let wide = EnvShape {
            horizon: 100,
            obs_sizes: vec![10; 4],
            n_actions: vec![40; 4],
            state_size: 0,
        };
        let c = paper_defaults(
            &crate::envs::box_pushing::paper_spec(10),
            ValueMethod::CenDdrqn,
        );
        let (key, why) = check(&c, ValueMethod::CenDdrqn, &wide).unwrap_err();
        assert_eq!(key, "batch_size");
        assert!(why.contains("2560000"), "{why}");
        let mut dec = c.clone();
        dec.replay_buffer_size = 1000;
        assert!(check(&dec, ValueMethod::DecHddrqn, &wide).is_ok());
        // A full replay of huge observations is refused although its record count is allowed.
        let huge_obs = EnvShape {
            obs_sizes: vec![1_000_000; 2],
            n_actions: vec![4; 2],
            ..wide
        };
        let mut big = c.clone();
        big.replay_buffer_size = 10_000;
        big.batch_size = 1;
        let (key, why) = check(&big, ValueMethod::DecHddrqn, &huge_obs).unwrap_err();
        assert_eq!(key, "replay_buffer_size", "{why}");
        assert!(why.contains("values when full"), "{why}");
    }
}
