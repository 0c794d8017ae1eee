//! The actor-critic methods' hyperparameters, under MacroMARL's flag names
//! (`scripts/pg_based_main.py`; `docs/MACROMARL.md` §1.4), with the reference's argparse defaults
//! where no published experiment sets a key. The published values per domain and method are
//! [`super::published`].

use crate::algos::actor_critic::method::{AcActor, AcCritic, AcMethod};
use crate::algos::config_checks::{
    check_at_most, check_batch_activations, check_discount, check_mlp_widths, check_positive,
    check_rates, check_unit, NetWidths, MAX_EVAL_NUM_EPI, MAX_HORIZON, MAX_NET_WIDTH,
    MAX_TOTAL_EPI,
};
use crate::algos::learner::FamilyConfig;
use crate::envs::{EnvShape, EnvSpec};
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

impl FamilyConfig for AcConfig {
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
        self.gamma
    }
}

/// MacroMARL's published settings for actor-critic `method` on `env` (`docs/MACROMARL.md` §1.4): the
/// reference's argparse defaults, then the domain's published row for the method
/// ([`super::published`]). A domain MacroMARL did not publish on keeps the defaults, with the
/// discount of its paper setting when it has one.
pub fn published_defaults(env: &EnvSpec, method: AcMethod) -> AcConfig {
    let alg = method.design().reference_alg;
    let mut table = toml::Table::try_from(AcConfig::reference_defaults()).expect("a table");
    let published = crate::algos::actor_critic::published::settings(env, alg);
    if published.is_empty() {
        if let Some(d) = env.paper_discount() {
            table.insert("gamma".into(), d.into());
        }
    }
    for (key, value) in published {
        assert!(
            table.contains_key(&key),
            "{}'s actor-critic settings name `{key}`, which is not a hyperparameter",
            env.env_name()
        );
        table.insert(key, value);
    }
    AcConfig::deserialize(toml::Value::Table(table)).unwrap_or_else(|e| {
        panic!(
            "{}'s actor-critic settings do not type-check: {e}",
            env.env_name()
        )
    })
}

/// The actor-critic family's range checks (see
/// [`crate::algos::family::FamilyMethod::check`]).
pub fn check(
    c: &AcConfig,
    method: AcMethod,
    shape: &EnvShape,
) -> Result<(), (&'static str, String)> {
    check_positive(&[
        ("env_terminate_step", shape.horizon),
        ("total_epi", c.total_epi),
        ("n_env", c.n_env),
        ("train_freq", c.train_freq),
        ("c_target_update_freq", c.c_target_update_freq),
        ("a_rnn_layer_size", c.a_rnn_layer_size),
        ("c_rnn_layer_size", c.c_rnn_layer_size),
        ("c_mid_layer_size", c.c_mid_layer_size),
        ("eval_freq", c.eval_freq),
        ("eval_num_epi", c.eval_num_epi),
        ("checkpoint_freq", c.checkpoint_freq),
    ])?;
    check_sizes(c, method, shape)?;
    if c.train_freq > c.total_epi {
        return Err((
            "train_freq",
            format!(
                "must be at most total_epi ({}), got {}: an update runs every train_freq episodes, so none would",
                c.total_epi, c.train_freq
            ),
        ));
    }
    check_unit(&[
        ("gamma", c.gamma),
        ("eps_start", c.eps_start),
        ("eps_end", c.eps_end),
    ])?;
    check_discount("gamma", c.gamma)?;
    check_rates(&[("a_lr", c.a_lr), ("c_lr", c.c_lr)])
}

/// Check an actor-critic config's sizes against the bounds above and [`MAX_N_ENV`], for a
/// domain of this shape (its horizon, observation and macro-action counts). Returns the key
/// and why.
fn check_sizes(
    c: &AcConfig,
    method: AcMethod,
    shape: &EnvShape,
) -> Result<(), (&'static str, String)> {
    let horizon = shape.horizon;
    check_at_most(&[
        ("env_terminate_step", horizon, MAX_HORIZON),
        ("total_epi", c.total_epi, MAX_TOTAL_EPI),
        ("eval_num_epi", c.eval_num_epi, MAX_EVAL_NUM_EPI),
        ("n_env", c.n_env, MAX_N_ENV),
        ("train_freq", c.train_freq, MAX_N_ENV * 16),
        ("n_step_TD", c.n_step_td, MAX_HORIZON),
        ("a_rnn_layer_size", c.a_rnn_layer_size, MAX_NET_WIDTH),
        ("c_rnn_layer_size", c.c_rnn_layer_size, MAX_NET_WIDTH),
        ("c_mid_layer_size", c.c_mid_layer_size, MAX_NET_WIDTH),
    ])?;
    check_mlp_widths(&[
        ("a_mlp_layer_size", &c.a_mlp_layer_size),
        ("c_mlp_layer_size", &c.c_mlp_layer_size),
    ])?;
    let widest = [c.a_rnn_layer_size, c.c_rnn_layer_size, c.c_mid_layer_size]
        .into_iter()
        .chain(c.a_mlp_layer_size.iter().copied())
        .chain(c.c_mlp_layer_size.iter().copied())
        .max()
        .unwrap_or(1) as u128;
    // Every method but Mac-IAC has a critic on the joint observation or the state; Mac-CAC's
    // actor reads the joint observation and scores every joint macro-action.
    let design = method.design();
    let input = match design.critic {
        AcCritic::OwnHistory => shape.widest_obs(),
        _ => shape.joint_obs_size().max(shape.state_size as u128),
    };
    let output = match design.actor {
        AcActor::Decentralized => shape.widest_actions(),
        AcActor::Centralized => shape.n_joint_actions(),
    };
    // One update runs over the last train_freq episodes, each up to the horizon.
    check_batch_activations(
        ("train_freq", c.train_freq),
        ("env_terminate_step", shape.horizon),
        NetWidths {
            hidden: widest,
            input,
            output,
        },
    )?;
    Ok(())
}

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

    #[test]
    fn every_actor_critic_method_has_published_settings_on_macromarls_domains() {
        use crate::algos::family::FamilyMethod;
        for &method in AcMethod::ALL {
            for grid in [6, 8, 10, 12, 14] {
                let c = published_defaults(&crate::envs::bp_ma_v0::spec(grid, 100), method);
                assert_eq!(
                    (c.gamma, c.total_epi),
                    (0.98, 40_000),
                    "{method:?} bp{grid}"
                );
            }
            let bp6 = published_defaults(&crate::envs::bp_ma_v0::spec(6, 100), method);
            // Published rows differ from the argparse defaults (a_lr 1e-4) everywhere.
            assert_ne!(bp6.a_lr, 1e-4, "{method:?}");
            for id in [
                "OSD-D-v7",
                "OSD-T-v0",
                "OSD-T-v1",
                "OSD-F-v0",
                "Overcooked-MA-v1",
            ] {
                let spec = crate::envs::EnvSpec::new(id, &toml::Table::new()).unwrap();
                let c = published_defaults(&spec, method);
                assert!(c.gamma == 1.0 || c.gamma == 0.99, "{method:?} {id}");
                assert_eq!(c.n_env, c.train_freq, "{method:?} {id}");
            }
        }
        // BP 12x12 Mac-IAC: 8 environments, 16 episodes per update.
        let c = published_defaults(&crate::envs::bp_ma_v0::spec(12, 100), AcMethod::MacIac);
        assert_eq!((c.n_env, c.train_freq, c.n_step_td), (8, 16, 3));
        // An ICRA domain keeps the defaults with its discount.
        let c = published_defaults(&crate::envs::box_pushing::paper_spec(10), AcMethod::MacIac);
        assert_eq!((c.gamma, c.a_lr), (0.98, 1e-4));
    }

    #[test]
    fn actor_critic_bad_values_name_their_key() {
        let bp = EnvShape::of(&crate::envs::bp_ma_v0::spec(6, 100)).unwrap();
        let check = |c: &AcConfig| check(c, AcMethod::MacIaicc, &bp);
        let mut c = AcConfig::reference_defaults();
        assert!(check(&c).is_ok());
        c.a_mlp_layer_size = vec![32];
        assert_eq!(check(&c).unwrap_err().0, "a_mlp_layer_size");
        c = AcConfig::reference_defaults();
        c.gamma = 1.5;
        assert_eq!(check(&c).unwrap_err().0, "gamma");
        c = AcConfig::reference_defaults();
        c.n_env = 0;
        assert_eq!(check(&c).unwrap_err().0, "n_env");
        c = AcConfig::reference_defaults();
        c.c_lr = f64::NAN;
        assert_eq!(check(&c).unwrap_err().0, "c_lr");
        c = AcConfig::reference_defaults();
        (c.total_epi, c.train_freq) = (10, 11);
        assert_eq!(check(&c).unwrap_err().0, "train_freq");
        c.train_freq = 10;
        assert!(check(&c).is_ok());
    }

    #[test]
    fn mac_cac_counts_its_joint_action_output() {
        // Overcooked B with three agents: 15^3 = 3375 joint macro-actions. The published
        // Mac-CAC row (8 environments) fits; 200 environments and episodes per update would need
        // more than 5 GB and are refused before anything is allocated, naming the joint width.
        let spec =
            crate::envs::EnvSpec::new("Overcooked-MA-v1", &toml::toml! { map_type = "B" }).unwrap();
        let shape = EnvShape::of(&spec).unwrap();
        assert_eq!(shape.n_joint_actions(), 3375);
        let mut c = published_defaults(&spec, AcMethod::MacCac);
        assert!(check(&c, AcMethod::MacCac, &shape).is_ok());
        (c.n_env, c.train_freq) = (200, 200);
        let (key, why) = check(&c, AcMethod::MacCac, &shape).unwrap_err();
        assert_eq!(key, "train_freq");
        assert!(why.contains("widest output 3375"), "{why}");
        // The decentralized actors of Mac-IAICC output 15 each: the same sizes fit.
        let mut c = published_defaults(&spec, AcMethod::MacIaicc);
        (c.n_env, c.train_freq) = (200, 200);
        assert!(check(&c, AcMethod::MacIaicc, &shape).is_ok());
    }
}
