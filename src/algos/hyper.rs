//! Every hyperparameter of a run, concrete, with the paper's values as defaults.
//!
//! The learner reads only this struct; `experiment::config` builds it from files, sweeps and
//! `--set` overrides. Field names are the reference's command-line flags (spec `algorithms.md` 10).
//! It names no domain: the loop is handed a way to build the environment, and a run on disk
//! records its domain beside these keys (`experiment::run_settings`).

use serde::{Deserialize, Serialize};

/// The resolved hyperparameters of one run: every one concrete and validated. Unknown keys are
/// refused, so a typo in a hand-edited config fails instead of being ignored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
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
