//! Every hyperparameter of a run, concrete, with the papers' values as defaults.
//!
//! A run's [`RunConfig`] is its family's own set of keys: the ICRA code's flags for the value
//! methods ([`ValueConfig`], `docs/ALGORITHMS.md` §10) and MacroMARL's for the actor-critic methods
//! ([`AcConfig`], `docs/MACROMARL.md` §1.4). A learner reads only its own struct;
//! `experiment::definition::config` builds them from files, sweeps and `--set` overrides. They
//! name no domain: the loop is handed a way to build the environment, and a run on disk records its domain beside
//! these keys (`experiment::definition::run_settings`).

use serde::{Deserialize, Serialize};

pub use crate::algos::actor_critic::config::AcConfig;

/// The resolved hyperparameters of one run, by method family: every one concrete and validated.
/// On disk (`config.toml`) it is the family's flat table of keys; which family a table is follows
/// from its keys (only actor-critic tables have `a_lr`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum RunConfig {
    /// The ICRA 2020 Q-learning methods.
    Value(ValueConfig),
    /// MacroMARL's macro-action actor-critic methods.
    ActorCritic(AcConfig),
}

impl RunConfig {
    /// Training episodes.
    pub fn total_epi(&self) -> usize {
        match self {
            RunConfig::Value(c) => c.total_epi,
            RunConfig::ActorCritic(c) => c.total_epi,
        }
    }

    /// Set the number of training episodes (e.g. a shortened run in a benchmark).
    pub fn set_total_epi(&mut self, episodes: usize) {
        match self {
            RunConfig::Value(c) => c.total_epi = episodes,
            RunConfig::ActorCritic(c) => c.total_epi = episodes,
        }
    }

    /// Training episodes between checkpoints.
    pub fn checkpoint_freq(&self) -> usize {
        match self {
            RunConfig::Value(c) => c.checkpoint_freq,
            RunConfig::ActorCritic(c) => c.checkpoint_freq,
        }
    }

    /// The discount of evaluation returns and exported policies (per primitive step).
    pub fn discount(&self) -> f64 {
        match self {
            RunConfig::Value(c) => c.discount,
            RunConfig::ActorCritic(c) => c.gamma,
        }
    }

    /// The value family's keys, if this is a value-method config.
    pub fn value(&self) -> Option<&ValueConfig> {
        match self {
            RunConfig::Value(c) => Some(c),
            RunConfig::ActorCritic(_) => None,
        }
    }

    /// The same, mutable (e.g. to shorten a run built from the paper's defaults in code).
    pub fn value_mut(&mut self) -> Option<&mut ValueConfig> {
        match self {
            RunConfig::Value(c) => Some(c),
            RunConfig::ActorCritic(_) => None,
        }
    }

    /// The actor-critic family's keys, if this is an actor-critic config.
    pub fn actor_critic(&self) -> Option<&AcConfig> {
        match self {
            RunConfig::ActorCritic(c) => Some(c),
            RunConfig::Value(_) => None,
        }
    }

    /// The same, mutable.
    pub fn actor_critic_mut(&mut self) -> Option<&mut AcConfig> {
        match self {
            RunConfig::ActorCritic(c) => Some(c),
            RunConfig::Value(_) => None,
        }
    }

    /// The flat table of keys `config.toml` records.
    pub fn to_table(&self) -> toml::Table {
        match self {
            RunConfig::Value(c) => toml::Table::try_from(c),
            RunConfig::ActorCritic(c) => toml::Table::try_from(c),
        }
        .expect("a config serializes to a table")
    }

    /// Read the table [`Self::to_table`] writes: the family follows from the keys (`a_lr` only
    /// exists for the actor-critic methods); unknown keys are refused, naming them.
    pub fn from_table(table: toml::Table) -> Result<Self, String> {
        let value = toml::Value::Table(table);
        let is_ac = value.get("a_lr").is_some();
        if is_ac {
            AcConfig::deserialize(value).map(RunConfig::ActorCritic)
        } else {
            ValueConfig::deserialize(value).map(RunConfig::Value)
        }
        .map_err(|e| e.message().to_string())
    }
}

impl From<ValueConfig> for RunConfig {
    fn from(c: ValueConfig) -> Self {
        RunConfig::Value(c)
    }
}

impl From<AcConfig> for RunConfig {
    fn from(c: AcConfig) -> Self {
        RunConfig::ActorCritic(c)
    }
}

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
