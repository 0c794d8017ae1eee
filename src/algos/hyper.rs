//! Every hyperparameter of a run, concrete, with the paper's values as defaults.
//!
//! The trainer reads only this struct; `experiment::config` builds it from files, sweeps and
//! `--set` overrides. Field names are the reference's command-line flags (spec `algorithms.md` 10).

use crate::algos::method::Method;
use crate::envs::EnvSpec;
use serde::{Deserialize, Serialize};

/// Which domain a run trains on, by the reference's `--env_name`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum EnvName {
    /// Box Pushing (`box_pushing.md`).
    #[serde(rename = "BP_MA", alias = "box-pushing")]
    BoxPushing,
    /// Warehouse Tool Delivery (`warehouse.md`).
    #[serde(rename = "OSD_S_4", alias = "warehouse")]
    Warehouse,
}

impl EnvName {
    /// A short label for tables and benchmarks: `bp<grid>` (e.g. `bp10`) or `wtd`.
    pub fn short_name(self, grid_dim: usize) -> String {
        match self {
            EnvName::BoxPushing => format!("bp{grid_dim}"),
            EnvName::Warehouse => "wtd".into(),
        }
    }

    /// The domain spec these `config.toml` keys describe (`grid_dim` only for Box Pushing,
    /// `tb_m_noisy` only for Warehouse).
    pub fn spec(self, grid_dim: usize, horizon: usize, tb_m_noisy: f64) -> EnvSpec {
        match self {
            EnvName::BoxPushing => EnvSpec::BoxPushing {
                grid: grid_dim,
                horizon,
            },
            EnvName::Warehouse => EnvSpec::Warehouse {
                horizon,
                tb_m_noisy,
            },
        }
    }
}

/// The resolved configuration of one run: every hyperparameter concrete and validated.
/// Saved as `config.toml` beside the run's results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// Domain (`BP_MA` or `OSD_S_4`).
    pub env_name: EnvName,
    /// Box Pushing grid side N (N x N, N >= 8). Ignored by Warehouse.
    pub grid_dim: usize,
    /// Horizon in primitive steps (BP 10x10: 100, 30x30: 200; WTD: 150).
    pub env_terminate_step: usize,
    /// Warehouse Turtlebot movement noise std (paper: 0).
    pub tb_m_noisy: f64,
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

impl RunConfig {
    /// The environment this config describes, from its `env_name`, `grid_dim`,
    /// `env_terminate_step` and `tb_m_noisy` keys.
    pub fn env_spec(&self) -> EnvSpec {
        self.env_name
            .spec(self.grid_dim, self.env_terminate_step, self.tb_m_noisy)
    }
}

/// The paper's settings for a domain and method (spec `algorithms.md` 10), before user keys.
pub fn paper_defaults(env: EnvName, grid_dim: usize, method: Method) -> RunConfig {
    let (init_h, end_h) = method.paper_hysteresis();
    // 10x10: horizon 100, windows of 15; 30x30: horizon 200, windows of 45 (spec 10.1, 10.2).
    let big = grid_dim >= 30;
    let trace_len = if big { 45 } else { 15 };
    let box_pushing = RunConfig {
        env_name: EnvName::BoxPushing,
        grid_dim,
        env_terminate_step: if big { 200 } else { 100 },
        tb_m_noisy: 0.0,
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
        train_freq: trace_len,
        target_update_freq: 5000,
        trace_len,
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
    };
    match env {
        EnvName::BoxPushing => box_pushing,
        // Figure 5's commands differ from Box Pushing's only in these keys (spec 10.3).
        EnvName::Warehouse => RunConfig {
            env_name: EnvName::Warehouse,
            env_terminate_step: 150,
            total_epi: 40000,
            replay_buffer_size: 1000,
            sample_epi: true,
            h_explore: true,
            l_rate: 0.0006,
            discount: 1.0,
            train_freq: 30,
            trace_len: 10,
            batch_size: 16,
            dec_rnn_h_size: 64,
            ..box_pushing
        },
    }
}
