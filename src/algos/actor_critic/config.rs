//! The actor-critic methods' hyperparameters, under MacroMARL's flag names
//! (`scripts/pg_based_main.py`; `docs/MACROMARL.md` §1.4), with the reference's argparse defaults
//! where no published experiment sets a key. The published values per domain and method are
//! [`super::published`].

use serde::{Deserialize, Serialize};

/// The resolved hyperparameters of one actor-critic run. Unknown keys are refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AcConfig {
    /// Training episodes; `epi_count` advances by `train_freq` per update (`docs/MACROMARL.md` §2.3).
    pub total_epi: usize,
    /// Discount per primitive step, inside macro-actions too (P6).
    pub gamma: f64,
    /// Adam learning rates of the actors and the critics.
    pub a_lr: f64,
    /// The critics' Adam learning rate (MacroMARL's default 1e-3).
    pub c_lr: f64,
    /// Environments stepped in lockstep while collecting (P1).
    pub n_env: usize,
    /// Completed episodes per update (the on-policy batch).
    pub train_freq: usize,
    /// Episodes between hard copies of the critics into their targets (P10).
    pub c_target_update_freq: usize,
    /// Macro-steps of the SMDP n-step return; 0 and 1 are the one-step return (`docs/MACROMARL.md` §2.6).
    #[serde(rename = "n_step_TD")]
    pub n_step_td: usize,
    /// The exploration mixture's weight moves linearly from eps_start to eps_end over
    /// eps_stable_at episodes (`Linear_Decay`).
    pub eps_start: f64,
    /// The exploration weight from `eps_stable_at` episodes on.
    pub eps_end: f64,
    /// Episodes over which the weight decays from `eps_start` to `eps_end`.
    pub eps_stable_at: usize,
    /// Actor: MLP widths [before, after] the GRU, and the GRU's width.
    pub a_mlp_layer_size: Vec<usize>,
    /// The actor's GRU width.
    pub a_rnn_layer_size: usize,
    /// History critic: MLP widths [before, after] the GRU, and the GRU's width; the state
    /// critic's MLP uses c_mlp_layer_size and c_mid_layer_size.
    pub c_mlp_layer_size: Vec<usize>,
    /// The history critic's GRU width.
    pub c_rnn_layer_size: usize,
    /// The state critic's middle MLP width.
    pub c_mid_layer_size: usize,
    /// Evaluate every `eval_freq - eval_freq % train_freq` episodes, from episode 0 (P8).
    pub eval_freq: usize,
    /// Sampled episodes averaged per evaluation (the last ones to complete).
    pub eval_num_epi: usize,
    /// Training episodes between checkpoints (ours; rounded up to whole updates).
    pub checkpoint_freq: usize,
    /// Quirk P2 switch: weight the policy gradient by gamma^t at the macro-action's start
    /// instead of its end (faithful: false).
    pub pg_discount_at_start: bool,
    /// Quirk P3 switch: train on the actor's own log-probability instead of the
    /// epsilon-mixture's (faithful: false).
    pub pg_plain_log_prob: bool,
}

/// The keys whose value is a list by nature (one setting, not a sweep).
pub const LIST_KEYS: [&str; 2] = ["a_mlp_layer_size", "c_mlp_layer_size"];

impl AcConfig {
    /// The reference's argparse defaults (`pg_based_main.py`) with every published run's common
    /// flags (`--eps_start=1.0 --eval_policy --sample_epi`), before a domain's published values.
    pub fn reference_defaults() -> Self {
        AcConfig {
            total_epi: 40_000,
            gamma: 0.95,
            a_lr: 1e-4,
            c_lr: 1e-3,
            n_env: 1,
            train_freq: 2,
            c_target_update_freq: 16,
            n_step_td: 0,
            eps_start: 1.0,
            eps_end: 0.01,
            eps_stable_at: 4000,
            a_mlp_layer_size: vec![32, 32],
            a_rnn_layer_size: 32,
            c_mlp_layer_size: vec![32, 32],
            c_rnn_layer_size: 32,
            c_mid_layer_size: 32,
            eval_freq: 100,
            eval_num_epi: 10,
            checkpoint_freq: 2000,
            pg_discount_at_start: false,
            pg_plain_log_prob: false,
        }
    }

    /// Episodes between evaluations: `eval_freq - eval_freq % train_freq` (96 for train_freq
    /// 8, 16, 32 or 48 and eval_freq 100), at least one update.
    pub fn eval_period(&self) -> usize {
        (self.eval_freq - self.eval_freq % self.train_freq).max(self.train_freq)
    }

    /// The exploration weight at `episodes` training episodes (`Linear_Decay.get_value`).
    pub fn eps_at(&self, episodes: u64) -> f64 {
        let e = episodes as f64;
        let span = self.eps_stable_at as f64;
        if span <= 0.0 || e >= span {
            self.eps_end
        } else {
            self.eps_start - (self.eps_start - self.eps_end) * e / span
        }
    }
}

/// Environments one run may step in lockstep (published: at most 48).
pub const MAX_N_ENV: usize = 4096;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eval_period_and_eps_follow_the_reference() {
        let mut c = AcConfig::reference_defaults();
        for (tf, period) in [(2, 100), (4, 100), (8, 96), (16, 96), (32, 96), (48, 96)] {
            c.train_freq = tf;
            assert_eq!(c.eval_period(), period, "train_freq {tf}");
        }
        c.eps_end = 0.01;
        c.eps_stable_at = 4000;
        assert_eq!(c.eps_at(0), 1.0);
        assert!((c.eps_at(2000) - 0.505).abs() < 1e-12);
        assert_eq!(c.eps_at(4000), 0.01);
        assert_eq!(c.eps_at(9000), 0.01);
    }
}
