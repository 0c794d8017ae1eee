//! Every hyperparameter of a run, concrete, with the paper's values as defaults.
//!
//! The trainer reads only this struct; `experiment::config` builds it from files, sweeps and
//! `--set` overrides. Field names are the reference's command-line flags (spec `algorithms.md` 10).

use crate::envs::flags::{EnvFlags, EnvName};
use crate::envs::EnvSpec;
use serde::{Deserialize, Serialize};

/// The resolved configuration of one run: every hyperparameter concrete and validated.
/// Saved as `config.toml` beside the run's results (and inside `checkpoint.bin`), where the
/// domain is written as the reference's four keys `env_name`, `grid_dim`, `env_terminate_step`
/// and `tb_m_noisy` ([`EnvFlags`]), so every existing run directory keeps reading and writing
/// byte for byte the same.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "RunConfigFile", into = "RunConfigFile")]
pub struct RunConfig {
    /// The domain and its parameters, horizon included (BP 10x10: 100, 30x30: 200; WTD: 150).
    /// [`crate::train`] trains on a domain of the caller's instead and does not read it.
    pub env: EnvSpec,
    /// Training episodes (Our-2: decentralized-env episodes).
    pub total_epi: usize,
    /// Replay capacity: windows for the windowed buffer, episodes with `sample_epi` (spec 3).
    pub replay_buffer_size: usize,
    /// Whole-episode replay (WTD) instead of fixed-length windows (BP).
    pub sample_epi: bool,
    /// Hysteresis moves from init_h to end_h over h_stable_at episodes (spec 5.6).
    pub dynamic_h: bool,
    pub init_h: f64,
    pub end_h: f64,
    pub h_stable_at: usize,
    /// Linear epsilon decay over eps_l_d_steps episodes (spec 4.1); else the exponential schedule.
    pub eps_l_d: bool,
    pub eps_l_d_steps: usize,
    pub eps_end: f64,
    /// Carry the exploring nets' hidden state during training episodes (spec 4.4, quirk Q1).
    pub h_explore: bool,
    /// Our-1 / Our-1-R explore with the centralized net (spec 4.6).
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
    pub dec_rnn_h_size: usize,
    /// Centralized net: M and H (Cen-DDRQN's `mlp_layer_size`/`rnn_h_size`).
    pub cen_mlp_layer_size: usize,
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

/// `config.toml`'s `[config]` table (and `checkpoint.bin`'s config) as written since the first
/// runs: the domain as its four reference keys, then every hyperparameter, in this order. Only
/// [`RunConfig`]'s serde goes through it. Unknown keys are refused, so a typo in a hand-edited
/// config fails instead of being ignored.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RunConfigFile {
    env_name: EnvName,
    grid_dim: usize,
    env_terminate_step: usize,
    tb_m_noisy: f64,
    total_epi: usize,
    replay_buffer_size: usize,
    sample_epi: bool,
    dynamic_h: bool,
    init_h: f64,
    end_h: f64,
    h_stable_at: usize,
    eps_l_d: bool,
    eps_l_d_steps: usize,
    eps_end: f64,
    h_explore: bool,
    cen_explore: bool,
    l_rate: f64,
    discount: f64,
    start_train: usize,
    train_freq: usize,
    target_update_freq: usize,
    trace_len: usize,
    sub_trace_len: usize,
    batch_size: usize,
    dec_mlp_layer_size: usize,
    dec_rnn_h_size: usize,
    cen_mlp_layer_size: usize,
    cen_rnn_h_size: usize,
    eval_freq: usize,
    eval_num_epi: usize,
    checkpoint_freq: usize,
    early_return_skips_all: bool,
}

impl From<RunConfig> for RunConfigFile {
    fn from(c: RunConfig) -> Self {
        let EnvFlags {
            env_name,
            grid_dim,
            env_terminate_step,
            tb_m_noisy,
        } = EnvFlags::of(&c.env);
        RunConfigFile {
            env_name,
            grid_dim,
            env_terminate_step,
            tb_m_noisy,
            total_epi: c.total_epi,
            replay_buffer_size: c.replay_buffer_size,
            sample_epi: c.sample_epi,
            dynamic_h: c.dynamic_h,
            init_h: c.init_h,
            end_h: c.end_h,
            h_stable_at: c.h_stable_at,
            eps_l_d: c.eps_l_d,
            eps_l_d_steps: c.eps_l_d_steps,
            eps_end: c.eps_end,
            h_explore: c.h_explore,
            cen_explore: c.cen_explore,
            l_rate: c.l_rate,
            discount: c.discount,
            start_train: c.start_train,
            train_freq: c.train_freq,
            target_update_freq: c.target_update_freq,
            trace_len: c.trace_len,
            sub_trace_len: c.sub_trace_len,
            batch_size: c.batch_size,
            dec_mlp_layer_size: c.dec_mlp_layer_size,
            dec_rnn_h_size: c.dec_rnn_h_size,
            cen_mlp_layer_size: c.cen_mlp_layer_size,
            cen_rnn_h_size: c.cen_rnn_h_size,
            eval_freq: c.eval_freq,
            eval_num_epi: c.eval_num_epi,
            checkpoint_freq: c.checkpoint_freq,
            early_return_skips_all: c.early_return_skips_all,
        }
    }
}

impl From<RunConfigFile> for RunConfig {
    fn from(f: RunConfigFile) -> Self {
        let flags = EnvFlags {
            env_name: f.env_name,
            grid_dim: f.grid_dim,
            env_terminate_step: f.env_terminate_step,
            tb_m_noisy: f.tb_m_noisy,
        };
        RunConfig {
            env: flags.spec(),
            total_epi: f.total_epi,
            replay_buffer_size: f.replay_buffer_size,
            sample_epi: f.sample_epi,
            dynamic_h: f.dynamic_h,
            init_h: f.init_h,
            end_h: f.end_h,
            h_stable_at: f.h_stable_at,
            eps_l_d: f.eps_l_d,
            eps_l_d_steps: f.eps_l_d_steps,
            eps_end: f.eps_end,
            h_explore: f.h_explore,
            cen_explore: f.cen_explore,
            l_rate: f.l_rate,
            discount: f.discount,
            start_train: f.start_train,
            train_freq: f.train_freq,
            target_update_freq: f.target_update_freq,
            trace_len: f.trace_len,
            sub_trace_len: f.sub_trace_len,
            batch_size: f.batch_size,
            dec_mlp_layer_size: f.dec_mlp_layer_size,
            dec_rnn_h_size: f.dec_rnn_h_size,
            cen_mlp_layer_size: f.cen_mlp_layer_size,
            cen_rnn_h_size: f.cen_rnn_h_size,
            eval_freq: f.eval_freq,
            eval_num_epi: f.eval_num_epi,
            checkpoint_freq: f.checkpoint_freq,
            early_return_skips_all: f.early_return_skips_all,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::method::Method;
    use crate::experiment::paper::paper_defaults;

    #[test]
    fn the_domain_is_written_as_the_four_reference_keys_first() {
        let c = paper_defaults(EnvSpec::paper_warehouse(), Method::Our2);
        let text = toml::to_string(&c).unwrap();
        assert!(
            text.starts_with(
                "env_name = \"OSD_S_4\"\ngrid_dim = 10\nenv_terminate_step = 150\ntb_m_noisy = 0.0\ntotal_epi = 40000\n"
            ),
            "{text}"
        );
        let back: RunConfig = toml::from_str(&text).unwrap();
        assert_eq!(back, c);
    }

    #[test]
    fn checkpoints_keep_the_domain_as_name_index_and_three_numbers() {
        // bincode (checkpoint.bin): the env_name variant index as u32, then grid_dim,
        // env_terminate_step (u64) and tb_m_noisy (f64), as before the config held an EnvSpec.
        let mut c = paper_defaults(EnvSpec::paper_warehouse(), Method::Our1);
        c.env = EnvSpec::Warehouse {
            horizon: 150,
            tb_m_noisy: 0.5,
        };
        let bytes = bincode::serialize(&c).unwrap();
        let mut head = 1u32.to_le_bytes().to_vec();
        head.extend(10u64.to_le_bytes());
        head.extend(150u64.to_le_bytes());
        head.extend(0.5f64.to_le_bytes());
        assert_eq!(&bytes[..head.len()], &head[..]);
        assert_eq!(bincode::deserialize::<RunConfig>(&bytes).unwrap(), c);
    }

    #[test]
    fn unknown_keys_are_refused_and_unused_domain_keys_are_not_read() {
        let c = paper_defaults(EnvSpec::paper_box_pushing(10), Method::Our1);
        let text = toml::to_string(&c).unwrap();
        let err = toml::from_str::<RunConfig>(&format!("{text}trace_lenn = 3\n")).unwrap_err();
        assert!(err.message().contains("trace_lenn"), "{err}");
        // A Box Pushing config's tb_m_noisy is not part of its domain.
        let noisy = text.replace("tb_m_noisy = 0.0", "tb_m_noisy = 0.3");
        assert_ne!(noisy, text);
        assert_eq!(toml::from_str::<RunConfig>(&noisy).unwrap().env, c.env);
    }
}
