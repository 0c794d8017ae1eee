//! MacroMARL's value-based hyperparameters under the reference's flag names
//! (`scripts/value_based_main.py`, `docs/MACROMARL.md` §8.3), with its argparse defaults where no
//! published script sets a key. The published rows per domain and method are [`super::published`].

use crate::algos::config_checks::{
    check_at_most, check_batch_activations, check_discount, check_eval_rows, check_mlp_widths,
    check_positive, check_rates, check_train_freq_steps, check_unit, NetWidths, MAX_HORIZON,
    MAX_NET_WIDTH, MAX_TOTAL_EPI,
};
use crate::algos::learner::FamilyConfig;
use crate::algos::mac_value::method::{MacValueMethod, QNets};
use crate::envs::{EnvShape, EnvSpec};
use serde::{Deserialize, Serialize};

/// The resolved hyperparameters of one MacroMARL value-based run. Unknown keys are refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MacValueConfig {
    /// Training episodes.
    pub total_epi: usize,
    /// Environments stepped per main-loop step; each update trains `n_env` times.
    pub n_env: usize,
    /// Replay capacity: windows of `trace_len` records, or whole episodes with `sample_epi`.
    pub replay_buffer_size: usize,
    /// Store and sample whole episodes (`ReplayMemory_epi`) instead of windows
    /// (`ReplayMemory_rand`).
    pub sample_epi: bool,
    /// Hysteresis rises linearly from `init_h` to `end_h` over `h_stable_at` episodes after
    /// `start_train`; without it the hysteresis is 1 - epsilon (the reference's `update_hysteretic`).
    pub dynamic_h: bool,
    /// Hysteresis (the weight of negative TD errors) at `start_train`; 1 is plain double Q.
    pub init_h: f64,
    /// Hysteresis from `h_stable_at` episodes after `start_train` on.
    pub end_h: f64,
    /// Episodes over which the hysteresis rises.
    pub h_stable_at: usize,
    /// Epsilon falls linearly from 1 to `eps_end` over `eps_l_d_steps` episodes after
    /// `start_train`; without it, eps_end + (1 - eps_end) exp(-(episodes / 8) / 2000).
    pub eps_l_d: bool,
    /// Episodes of the linear decay.
    pub eps_l_d_steps: usize,
    /// The final exploration rate.
    pub eps_end: f64,
    /// Carry each net's recurrent state while exploring (`--h_explore`); otherwise every
    /// training decision starts from the zero state (the reference's runner never updates it).
    pub h_explore: bool,
    /// Adam learning rate.
    pub l_rate: f64,
    /// Discount per primitive step: inside macro-actions, in the gamma^duration bootstrap and in
    /// evaluation returns.
    pub discount: f64,
    /// Training episodes before the first update.
    pub start_train: usize,
    /// Main-loop steps (counted from 1) between updates.
    pub train_freq: usize,
    /// Main-loop steps (counted from 1) between hard target copies.
    pub target_update_freq: usize,
    /// Records per replay window (without `sample_epi`).
    pub trace_len: usize,
    /// Sequences with fewer squeezed records are dropped from an update.
    pub sub_trace_len: usize,
    /// Sequences (windows or episodes) per update, sampled without replacement.
    pub batch_size: usize,
    /// [m0, m1]: widths of fc1 and fc2 (m0) and of fc3 (m1).
    pub mlp_layer_size: Vec<usize>,
    /// The GRU's width.
    pub rnn_h_size: usize,
    /// MacDec-DDRQN: [m0, m1] of the decentralized nets (`mlp_layer_size` is not read).
    pub dec_mlp_layer_size: Vec<usize>,
    /// MacDec-DDRQN: [m0, m1] of the centralized net.
    pub cen_mlp_layer_size: Vec<usize>,
    /// MacDec-DDRQN: the decentralized nets' GRU width.
    pub dec_rnn_h_size: usize,
    /// MacDec-DDRQN: the centralized net's GRU width.
    pub cen_rnn_h_size: usize,
    /// Evaluate one greedy episode before training and every `eval_freq` training episodes.
    pub eval_freq: usize,
    /// Training episodes between checkpoints (ours).
    pub checkpoint_freq: usize,
}

/// The keys whose value is a list by nature.
pub const LIST_KEYS: [&str; 3] = ["mlp_layer_size", "dec_mlp_layer_size", "cen_mlp_layer_size"];

/// Replay capacity, in windows or episodes (published: at most 100 000 windows).
pub const MAX_REPLAY: usize = 10_000_000;
/// Replay records (steps) one run may hold: capacity x records per entry (2^26 records of a
/// few hundred floats each is tens of GB; published: 2000 episodes x 250 steps).
pub const MAX_REPLAY_RECORDS: u128 = 1 << 26;
/// Joint macro-actions MacCen-Q's net may output.
pub const MAX_JOINT_ACTIONS: u128 = 1 << 16;

impl MacValueConfig {
    /// `value_based_main.py`'s argparse defaults with every published script's common flags
    /// (`--dynamic_h --eps_l_d`), before a domain's published row.
    pub fn reference_defaults() -> Self {
        MacValueConfig {
            total_epi: 40_000,
            n_env: 1,
            replay_buffer_size: 1000,
            sample_epi: false,
            dynamic_h: true,
            init_h: 0.2,
            end_h: 0.4,
            h_stable_at: 4000,
            eps_l_d: true,
            eps_l_d_steps: 4000,
            eps_end: 0.1,
            h_explore: false,
            l_rate: 0.0006,
            discount: 0.95,
            start_train: 2,
            train_freq: 30,
            target_update_freq: 5000,
            trace_len: 10,
            sub_trace_len: 1,
            batch_size: 16,
            mlp_layer_size: vec![32, 32],
            rnn_h_size: 32,
            dec_mlp_layer_size: vec![32, 32],
            cen_mlp_layer_size: vec![32, 32],
            dec_rnn_h_size: 32,
            cen_rnn_h_size: 64,
            eval_freq: 100,
            checkpoint_freq: 2000,
        }
    }

    /// Epsilon after an update at `since_start` = episodes - start_train (`Team.update_epsilon`).
    pub fn epsilon_at(&self, since_start: u64) -> f64 {
        if self.eps_l_d {
            let frac = if self.eps_l_d_steps == 0 {
                1.0
            } else {
                (since_start as f64 / self.eps_l_d_steps as f64).min(1.0)
            };
            1.0 + frac * (self.eps_end - 1.0)
        } else {
            self.eps_end + (1.0 - self.eps_end) * (-((since_start / 8) as f64) / 2000.0).exp()
        }
    }

    /// The hysteresis before an update at `since_start` (`Team.update_hysteretic`), given the
    /// epsilon then in force.
    pub fn hysteresis_at(&self, since_start: u64, epsilon: f64) -> f64 {
        if self.dynamic_h {
            let slope = (self.end_h - self.init_h) / self.h_stable_at as f64;
            self.end_h.min(slope * since_start as f64 + self.init_h)
        } else {
            1.0 - epsilon
        }
    }
}

impl FamilyConfig for MacValueConfig {
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

/// The published settings of `method` on `env`: the argparse defaults, then the domain's
/// published row ([`super::published`]). A domain without one keeps the defaults, with its
/// paper discount when it has one.
pub fn published_defaults(env: &EnvSpec, method: MacValueMethod) -> MacValueConfig {
    let mut table = toml::Table::try_from(MacValueConfig::reference_defaults()).expect("a table");
    let published = super::published::settings(env, method.reference_alg());
    if published.is_empty() {
        if let Some(d) = env.paper_discount() {
            table.insert("discount".into(), d.into());
        }
    }
    for (key, value) in published {
        assert!(
            table.contains_key(&key),
            "{}'s value-based settings name `{key}`, which is not a hyperparameter",
            env.env_name()
        );
        table.insert(key, value);
    }
    MacValueConfig::deserialize(toml::Value::Table(table)).unwrap_or_else(|e| {
        panic!(
            "{}'s value-based settings do not type-check: {e}",
            env.env_name()
        )
    })
}

/// The family's range checks (see [`crate::algos::family::FamilyMethod::check`]).
pub fn check(
    c: &MacValueConfig,
    method: MacValueMethod,
    shape: &EnvShape,
) -> Result<(), (&'static str, String)> {
    check_positive(&[
        ("env_terminate_step", shape.horizon),
        ("total_epi", c.total_epi),
        ("n_env", c.n_env),
        ("replay_buffer_size", c.replay_buffer_size),
        ("h_stable_at", c.h_stable_at),
        ("train_freq", c.train_freq),
        ("target_update_freq", c.target_update_freq),
        ("trace_len", c.trace_len),
        ("batch_size", c.batch_size),
        ("rnn_h_size", c.rnn_h_size),
        ("eval_freq", c.eval_freq),
        ("checkpoint_freq", c.checkpoint_freq),
    ])?;
    check_at_most(&[
        ("env_terminate_step", shape.horizon, MAX_HORIZON),
        ("total_epi", c.total_epi, MAX_TOTAL_EPI),
        // Parallel-MacDec-DDRQN steps n_env environments per runner, two runners.
        (
            "n_env",
            c.n_env,
            crate::algos::training_loop::MAX_LANES / if method.parallel() { 2 } else { 1 },
        ),
        ("replay_buffer_size", c.replay_buffer_size, MAX_REPLAY),
        ("trace_len", c.trace_len, MAX_HORIZON),
        ("rnn_h_size", c.rnn_h_size, MAX_NET_WIDTH),
        ("batch_size", c.batch_size, c.replay_buffer_size),
    ])?;
    check_mlp_widths(&[
        ("mlp_layer_size", &c.mlp_layer_size),
        ("dec_mlp_layer_size", &c.dec_mlp_layer_size),
        ("cen_mlp_layer_size", &c.cen_mlp_layer_size),
    ])?;
    check_positive(&[
        ("dec_rnn_h_size", c.dec_rnn_h_size),
        ("cen_rnn_h_size", c.cen_rnn_h_size),
    ])?;
    check_at_most(&[
        ("dec_rnn_h_size", c.dec_rnn_h_size, MAX_NET_WIDTH),
        ("cen_rnn_h_size", c.cen_rnn_h_size, MAX_NET_WIDTH),
    ])?;
    if c.start_train >= c.total_epi {
        return Err((
            "start_train",
            format!(
                "must be below total_epi ({}), got {}: no update would run",
                c.total_epi, c.start_train
            ),
        ));
    }
    check_train_freq_steps(c.train_freq, c.total_epi, shape.horizon)?;
    check_eval_rows(c.total_epi, c.eval_freq)?;
    check_unit(&[
        ("init_h", c.init_h),
        ("end_h", c.end_h),
        ("eps_end", c.eps_end),
    ])?;
    check_discount("discount", c.discount)?;
    check_rates(&[("l_rate", c.l_rate)])?;
    // Replay holds whole episodes: capacity x the horizon records at most (a window's episode
    // stays while any of its windows does, so windows count one episode each at worst).
    let memories = if method.parallel() { 2 } else { 1 };
    let records = (c.replay_buffer_size as u128)
        .saturating_mul(shape.horizon as u128)
        .saturating_mul(memories);
    if records > MAX_REPLAY_RECORDS {
        return Err((
            "replay_buffer_size",
            format!(
                "replay_buffer_size x env_terminate_step x memories ({memories}) = {records} records, at most {MAX_REPLAY_RECORDS}"
            ),
        ));
    }
    let (input, output) = match method.nets() {
        QNets::Decentralized => (shape.widest_obs(), shape.widest_actions()),
        QNets::Centralized | QNets::DecWithCen => (shape.joint_obs_size(), shape.n_joint_actions()),
    };
    if output > MAX_JOINT_ACTIONS {
        return Err((
            "method",
            format!("{output} joint macro-actions, at most {MAX_JOINT_ACTIONS} for one Q-net"),
        ));
    }
    let widest = c
        .mlp_layer_size
        .iter()
        .chain(&c.dec_mlp_layer_size)
        .chain(&c.cen_mlp_layer_size)
        .copied()
        .chain([c.rnn_h_size, c.dec_rnn_h_size, c.cen_rnn_h_size])
        .max()
        .unwrap_or(1) as u128;
    // One update's taped pass unrolls batch_size sequences of at most the horizon (a window is
    // shorter); the continuation (one longer) runs untaped through the net and its target.
    let seq = if c.sample_epi {
        shape.horizon
    } else {
        c.trace_len.min(shape.horizon)
    };
    check_batch_activations(
        ("batch_size", c.batch_size),
        ("env_terminate_step", seq + 1),
        NetWidths {
            hidden: widest,
            input,
            output,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn epsilon_and_hysteresis_follow_the_reference_schedules() {
        let mut c = MacValueConfig::reference_defaults();
        (c.eps_end, c.eps_l_d_steps) = (0.05, 4000);
        assert_eq!(c.epsilon_at(0), 1.0);
        assert!((c.epsilon_at(2000) - 0.525).abs() < 1e-12);
        // Linear_Decay: init + frac x (end - init), as the reference rounds it.
        assert_eq!(c.epsilon_at(9000), 1.0 + (0.05 - 1.0));
        (c.init_h, c.end_h, c.h_stable_at) = (0.2, 0.4, 4000);
        assert!((c.hysteresis_at(2000, 0.5) - 0.3).abs() < 1e-12);
        assert_eq!(c.hysteresis_at(8000, 0.5), 0.4);
        c.dynamic_h = false;
        assert_eq!(c.hysteresis_at(10, 0.25), 0.75);
        c.eps_l_d = false;
        // eps_end + (1 - eps_end) exp(-(16 // 8) / 2000)
        assert!((c.epsilon_at(17) - (0.05 + 0.95 * (-2.0f64 / 2000.0).exp())).abs() < 1e-12);
    }

    #[test]
    fn bad_values_name_their_key() {
        let bp = EnvShape::of(&crate::envs::bp_ma_v0::spec(8, 100)).unwrap();
        let check = |c: &MacValueConfig| check(c, MacValueMethod::MacDecQ, &bp);
        let ok = MacValueConfig::reference_defaults();
        assert!(check(&ok).is_ok());
        let bad = |f: &dyn Fn(&mut MacValueConfig)| {
            let mut c = ok.clone();
            f(&mut c);
            check(&c).unwrap_err().0
        };
        assert_eq!(bad(&|c| c.mlp_layer_size = vec![32]), "mlp_layer_size");
        assert_eq!(bad(&|c| c.init_h = 1.5), "init_h");
        assert_eq!(bad(&|c| c.batch_size = 2000), "batch_size");
        assert_eq!(
            bad(&|c| c.replay_buffer_size = usize::MAX),
            "replay_buffer_size"
        );
        assert_eq!(bad(&|c| c.l_rate = f64::NAN), "l_rate");
        assert_eq!(bad(&|c| c.start_train = 40_000), "start_train");
        assert_eq!(bad(&|c| c.discount = 0.0), "discount");
        assert_eq!(bad(&|c| c.train_freq = 0), "train_freq");
        assert_eq!(bad(&|c| c.trace_len = 1 << 40), "trace_len");
    }

    #[test]
    fn mac_cen_q_on_three_cooks_is_refused_and_the_published_two_cooks_fit() {
        // docs/MACROMARL.md 8.4 bug 4: the published runs trained 2 cooks; with 3, MacCen-Q's
        // joint output (15^3 on map B) over 64 whole episodes exceeds the activation bound.
        for (cooks, fits) in [(2, true), (3, false)] {
            let keys = toml::toml! { map_type = "B" n_agent = cooks };
            let spec = crate::envs::EnvSpec::new("Overcooked-MA-v1", &keys).unwrap();
            let shape = EnvShape::of(&spec).unwrap();
            let c = published_defaults(&spec, MacValueMethod::MacCenQ);
            let result = check(&c, MacValueMethod::MacCenQ, &shape);
            assert_eq!(result.is_ok(), fits, "{cooks} cooks: {result:?}");
            if let Err((key, why)) = result {
                assert_eq!(key, "batch_size");
                assert!(why.contains("widest output 3375"), "{why}");
            }
            let dec = published_defaults(&spec, MacValueMethod::MacDecQ);
            assert!(
                check(&dec, MacValueMethod::MacDecQ, &shape).is_ok(),
                "{cooks} cooks"
            );
        }
    }
}
