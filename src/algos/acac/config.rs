//! ACAC's hyperparameters under its own JSON keys (`scripts/params/default.json`), layered as its
//! `scripts/params/utils.py merge_params` layers them: `default.json`, then `alg/<alg>.json`, then
//! `env/<env>.json` (the env file wins where both set a key), the user's keys on top.
//!
//! ACAC's parameter files mix three kinds of keys; each goes where macdec keeps it:
//! - the environment's (`env_id`, `n_agent`, `env_terminate_step`, `grid_dim`, `map_type`,
//!   `rand_start`, `task`, `step_penalty`, ...) are the domain's keys ([`ENV_KEYS`]), given in an
//!   experiment file by the domain's names (`env_name`, `task` as the salad's name, `rewardList`);
//! - the Python runner's (`alg_name`, `env_name` as ACAC's setting name, `exp_name`, `seed`,
//!   `resume`, `device`, `parallel`, `wandb`; [`RUNNER_KEYS`]) are **refused** as unknown keys:
//!   macdec names methods, seeds and output directories its own way, runs on the CPU, and
//!   resumes from its own checkpoints;
//! - the learner's are [`AcacConfig`]'s fields, plus `duplicate` (ACAC's `--duplicate` flag) and
//!   macdec's `checkpoint_freq`.

use crate::algos::acac::method::AcacMethod;
use crate::algos::config_checks::{
    check_at_most, check_batch_activations, check_discount, check_eval_rows, check_mlp_widths,
    check_non_negative, check_positive, check_rates, check_unit, NetWidths, MAX_EVAL_NUM_EPI,
    MAX_HORIZON, MAX_NET_WIDTH, MAX_TOTAL_EPI,
};
use crate::algos::learner::FamilyConfig;
use crate::envs::{EnvShape, EnvSpec};
use crate::nn::ValueHead;
use serde::{Deserialize, Serialize};

/// The resolved hyperparameters of one ACAC run, by ACAC's JSON keys. Unknown keys are refused.
///
/// Keys marked *no effect* are read by nothing in ACAC's training code for its three algorithms
/// (they exist in `default.json` for its baselines); they are kept so ACAC's parameter files and
/// command lines carry over unchanged, and have no effect here either. Keys whose non-default
/// values select code ACAC has but macdec does not are refused by [`check`] naming the key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AcacConfig {
    /// Parallel environments collecting each batch (ACAC's worker processes).
    pub n_env: usize,
    /// *No effect* (a baseline's critic mode).
    pub c_mode: usize,
    /// *No effect* (a baseline's learner mode).
    pub l_mode: usize,
    /// Share each agent's GRU encoder between actor and critic (one optimizer, `vf_coef`
    /// weighting the critic loss). macdec: only `false`.
    pub share_encoder: bool,
    /// *No effect* (a baseline's state-based critic).
    pub state: bool,
    /// With `env_terminate_step`, the training budget: ACAC trains until
    /// `env_terminate_step x total_epi` **primitive steps** (`max_timesteps` in
    /// `algs/acac.py`), not `total_epi` episodes.
    pub total_epi: usize,
    /// Discount per primitive step (per macro-step: gamma^duration).
    pub gamma: f64,
    /// The actors' Adam learning rate.
    pub a_lr: f64,
    /// The critic's Adam learning rate.
    pub c_lr: f64,
    /// Critic steps per update in `acac-vanilla`; *no effect* in `acac` and `acac-micro-gae`
    /// (the critic trains once per PPO epoch).
    pub c_train_iteration: usize,
    /// Exploration rate at episode 0 (`Linear_Decay` over episodes).
    pub eps_start: f64,
    /// Exploration rate from `eps_stable_at` episodes on.
    pub eps_end: f64,
    /// Episodes over which the exploration rate falls linearly.
    pub eps_stable_at: usize,
    /// *No effect* unless `critic_hys` (refused).
    pub c_hys_start: f64,
    /// *No effect* unless `critic_hys` (refused).
    pub c_hys_end: f64,
    /// *No effect* (no learner reads the advantage hysteresis).
    pub adv_hys_start: f64,
    /// *No effect* (no learner reads the advantage hysteresis).
    pub adv_hys_end: f64,
    /// *No effect* unless `critic_hys` (refused).
    pub hys_stable_at: usize,
    /// Hysteretic critic TD errors. macdec: only `false` (ACAC's published runs).
    pub critic_hys: bool,
    /// *No effect* (passed to the learners, never read).
    pub adv_hys: bool,
    /// Entropy weight at episode 0 (read by `acac_vanilla` only; `acac` computes the entropy
    /// but leaves it out of the loss).
    pub etrpy_w_start: f64,
    /// Entropy weight from `etrpy_w_stable_at` episodes on.
    pub etrpy_w_end: f64,
    /// Episodes over which the entropy weight moves linearly.
    pub etrpy_w_stable_at: usize,
    /// Episodes per batch (one update per batch of `train_freq` finished episodes).
    pub train_freq: usize,
    /// Episodes between hard copies of the critic (and actors) into their targets; the target
    /// critic gives GAE's values.
    pub c_target_update_freq: usize,
    /// Soft (Polyak, `tau`) target updates after every batch. macdec: only `false`.
    pub c_target_soft_update: bool,
    /// The soft update's rate (*no effect* without `c_target_soft_update`).
    pub tau: f64,
    /// `acac-vanilla`'s n-step returns (0 or 1: one-step TD); *no effect* in the PPO methods.
    #[serde(rename = "n_step_TD")]
    pub n_step_td: usize,
    /// *No effect* in the PPO methods; must be 0 for `acac-vanilla` (ACAC's TD(lambda) path
    /// calls its n-step helper with a missing argument and fails).
    #[serde(rename = "TD_lambda")]
    pub td_lambda: f64,
    /// GAE's lambda.
    #[serde(rename = "GAE_lambda")]
    pub gae_lambda: f64,
    /// The actors' [fc1 width, fc3 width] around the GRU.
    pub a_mlp_layer_size: Vec<usize>,
    /// The actors' GRU width.
    pub a_rnn_layer_size: usize,
    /// The critic encoders' [fc1 width, fc width]; only the first is used with `use_attention`.
    pub c_mlp_layer_size: Vec<usize>,
    /// *No effect* (a baseline's critic layer).
    pub c_mid_layer_size: usize,
    /// The critic encoders' GRU width = the GPT-2 block's `n_embd`.
    pub c_rnn_layer_size: usize,
    /// Clip every gradient element to +-this (0: off).
    pub grad_clip_value: f64,
    /// Clip each net's gradient norm to this (0: off).
    pub grad_clip_norm: f64,
    /// Append the last macro-action to observations. macdec: only `false`.
    pub obs_last_action: bool,
    /// Evaluate during training (ACAC's runs: always).
    pub eval_policy: bool,
    /// Evaluate every `eval_freq - eval_freq % train_freq` training episodes (after the update).
    pub eval_freq: usize,
    /// Episodes per evaluation (`Eval/Return` is their mean).
    pub eval_num_epi: usize,
    /// *No effect* for ACAC (its episode memory keeps exactly one batch).
    pub sample_epi: bool,
    /// *No effect* (whole episodes are trained on).
    pub trace_len: usize,
    /// PPO epochs over each batch; *no effect* in `acac-vanilla` (ACAC passes 1 to its learner).
    pub n_train_repeat: usize,
    /// PPO's ratio clip.
    pub clip_ratio: f64,
    /// *No effect*: stored by ACAC's learners and never read; each PPO epoch uses the whole
    /// batch as one minibatch, here too.
    pub n_minibatch: usize,
    /// The critic's GPT-2 block over agents' encodings (otherwise a linear layer over their
    /// concatenation). macdec: only `true` (every ACAC algorithm file sets it).
    pub use_attention: bool,
    /// Attention heads of the critic's GPT-2 block (must divide `c_rnn_layer_size`).
    pub cc_n_head: usize,
    /// The critic's pooling over agents: `concat`, `mean_linear` or `max_linear`.
    pub value_head: ValueHead,
    /// *No effect* (a baseline's encoder heads).
    pub enc_n_head: usize,
    /// *No effect* (the critic's GPT-2 always has one layer in `models.py`).
    pub n_layer: usize,
    /// Concatenate a time embedding of each macro-observation's primitive step to the critic's
    /// inputs.
    pub time_emb: bool,
    /// The same for the actors' inputs.
    pub time_emb_actor: bool,
    /// The time embedding: `sinu` (fixed sinusoidal). macdec: only `sinu` (ACAC's runs).
    pub time_emb_alg: TimeEmbAlg,
    /// The time embedding's width (even for `sinu`).
    pub time_emb_dim: usize,
    /// LayerNorm in the actors (`use_actor_ln`).
    pub use_actor_ln: bool,
    /// The critic loss weight (read only with `share_encoder`; otherwise 1).
    pub vf_coef: f64,
    /// PopArt value normalisation in the critic.
    pub use_popart: bool,
    /// ACAC's `--duplicate`: the critic on duplicated observations.
    pub duplicate: bool,
    /// Training episodes between checkpoints (macdec's).
    pub checkpoint_freq: usize,
}

/// ACAC's time embeddings (`time_emb_alg`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeEmbAlg {
    /// `positionalencoding1d`: fixed sin/cos.
    Sinu,
    /// A learned `nn.Embedding`.
    Learn,
}

/// The keys whose value is a list by nature.
pub const LIST_KEYS: [&str; 2] = ["a_mlp_layer_size", "c_mlp_layer_size"];

/// Keys of ACAC's parameter files that are the environment's: the domain's keys in macdec.
pub const ENV_KEYS: [&str; 17] = [
    "env_id",
    "env_terminate_step",
    "n_agent",
    "grid_dim",
    "big_box_reward",
    "small_box_reward",
    "penalty",
    "task",
    "map_type",
    "step_penalty",
    "rand_start",
    "observation_type",
    "num_agvs",
    "num_pickers",
    "n_knife",
    "n_plate",
    "obj",
];

/// Keys of ACAC's parameter files that only its Python runner reads; refused here.
pub const RUNNER_KEYS: [&str; 7] = [
    "alg_name", "env_name", "exp_name", "seed", "resume", "device", "parallel",
];

/// ACAC's 15 published settings, by its `--env_name`.
pub const ENV_NAMES: [&str; 15] = [
    "bp6",
    "bp8",
    "bp10",
    "ovcA7",
    "ovcB7",
    "ovcC7",
    "ovcAR7",
    "ovcBR7",
    "ovcCR7",
    "ovcA11_N6",
    "ovcB11_N6",
    "ovcC11_N6",
    "ovcAR11_N6",
    "ovcBR11_N6",
    "ovcCR11_N6",
];

/// Training episodes between checkpoints when nobody says (ACAC saves ten per run).
const CHECKPOINT_FREQ: usize = 1000;

/// Widest batch: episodes per update (published: 8 and 16).
pub const MAX_TRAIN_FREQ: usize = 100_000;
/// PPO epochs per batch (published: 1 to 5).
pub const MAX_TRAIN_REPEAT: usize = 10_000;
/// Primitive steps one run may train, env_terminate_step x total_epi (published: at most 2e8).
pub const MAX_BUDGET_STEPS: u128 = 1 << 40;

const DEFAULT_JSON: &str = include_str!("published/default.json");

/// `alg/<alg>.json` of `method`.
fn alg_json(method: AcacMethod) -> &'static str {
    match method {
        AcacMethod::Acac => include_str!("published/alg/acac.json"),
        AcacMethod::AcacVanilla => include_str!("published/alg/acac_vanilla.json"),
        AcacMethod::AcacMicroGae => include_str!("published/alg/acac_micro_gae.json"),
    }
}

/// `env/<env>.json` of ACAC's setting `name`, if it is one of the 15.
pub fn env_json(name: &str) -> Option<&'static str> {
    Some(match name {
        "bp6" => include_str!("published/env/bp6.json"),
        "bp8" => include_str!("published/env/bp8.json"),
        "bp10" => include_str!("published/env/bp10.json"),
        "ovcA7" => include_str!("published/env/ovcA7.json"),
        "ovcB7" => include_str!("published/env/ovcB7.json"),
        "ovcC7" => include_str!("published/env/ovcC7.json"),
        "ovcAR7" => include_str!("published/env/ovcAR7.json"),
        "ovcBR7" => include_str!("published/env/ovcBR7.json"),
        "ovcCR7" => include_str!("published/env/ovcCR7.json"),
        "ovcA11_N6" => include_str!("published/env/ovcA11_N6.json"),
        "ovcB11_N6" => include_str!("published/env/ovcB11_N6.json"),
        "ovcC11_N6" => include_str!("published/env/ovcC11_N6.json"),
        "ovcAR11_N6" => include_str!("published/env/ovcAR11_N6.json"),
        "ovcBR11_N6" => include_str!("published/env/ovcBR11_N6.json"),
        "ovcCR11_N6" => include_str!("published/env/ovcCR11_N6.json"),
        _ => return None,
    })
}

/// ACAC's setting name for a domain spec (`utils.py make_env_name`): `bp<N>` for Box Pushing,
/// `ovc<map>[R]<grid>[_N<n>]` for its Overcooked (`_N` for the `-v0` kitchens). `None` for a
/// domain that is not one of ACAC's environments.
pub fn acac_env_name(env: &EnvSpec) -> Option<String> {
    let gym_id = crate::envs::acac::GYM_IDS
        .iter()
        .find(|(_, domain)| *domain == env.env_name())
        .map(|(gym, _)| *gym)?;
    let keys = env.keys();
    let grid = keys
        .get("grid_dim")
        .and_then(|g| g.as_array())
        .and_then(|g| g.first())
        .and_then(|n| n.as_integer())?;
    if gym_id.starts_with("BP") {
        return Some(format!("bp{grid}"));
    }
    let map = keys.get("map_type").and_then(|m| m.as_str())?;
    let random = keys.get("rand_start").and_then(|r| r.as_bool()) == Some(true);
    let mut name = format!("ovc{map}{}{grid}", if random { "R" } else { "" });
    if gym_id.ends_with('0') {
        let n = keys.get("n_agent").and_then(|n| n.as_integer())?;
        name += &format!("_N{n}");
    }
    Some(name)
}

/// `override_params`: every key of `layer` must already be in `params` (ACAC raises
/// `ValueError("Key ... is not in params")`).
fn override_params(
    params: &mut serde_json::Map<String, serde_json::Value>,
    layer: &str,
    origin: &str,
) {
    let layer: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(layer).unwrap_or_else(|e| panic!("{origin} is not JSON: {e}"));
    for (key, value) in layer {
        assert!(
            params.contains_key(&key),
            "{origin} sets `{key}`, which default.json does not have"
        );
        params.insert(key, value);
    }
}

/// ACAC's merged parameters for `method` on its setting `env_name` (any name: a setting without
/// an env file keeps default.json and the algorithm file, as `merge_params` does), every key of
/// ACAC's `default.json` included.
pub fn merged_params(
    method: AcacMethod,
    env_name: Option<&str>,
) -> serde_json::Map<String, serde_json::Value> {
    let mut params: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(DEFAULT_JSON).expect("default.json is a JSON object");
    override_params(&mut params, alg_json(method), "alg json");
    if let Some(env) = env_name.and_then(env_json) {
        override_params(&mut params, env, "env json");
    }
    params
}

/// The settings ACAC's runner uses for `method` on `env`, as an [`AcacConfig`]: the merged
/// parameters without the environment's and the runner's keys, `duplicate` false (the flag's
/// default) and macdec's `checkpoint_freq`.
pub fn published_defaults(env: &EnvSpec, method: AcacMethod) -> AcacConfig {
    let name = acac_env_name(env);
    let mut params = merged_params(method, name.as_deref());
    for key in ENV_KEYS.iter().chain(&RUNNER_KEYS) {
        params.remove(*key);
    }
    params.insert("duplicate".into(), false.into());
    params.insert("checkpoint_freq".into(), CHECKPOINT_FREQ.into());
    serde_json::from_value(serde_json::Value::Object(params))
        .unwrap_or_else(|e| panic!("ACAC's parameters do not type-check: {e}"))
}

impl AcacConfig {
    /// `Linear_Decay(stable_at, start, end).get_value(episodes)`: start + min(episodes /
    /// stable_at, 1) x (end - start), in the reference's order of operations (`stable_at` 0
    /// divides by zero in Python; here it means "already at `end`").
    pub fn linear_decay(stable_at: usize, start: f64, end: f64, episodes: u64) -> f64 {
        let frac = if stable_at == 0 {
            1.0
        } else {
            (episodes as f64 / stable_at as f64).min(1.0)
        };
        start + frac * (end - start)
    }

    /// The exploration rate of the batch collected after `episodes` training episodes.
    pub fn epsilon_at(&self, episodes: u64) -> f64 {
        Self::linear_decay(self.eps_stable_at, self.eps_start, self.eps_end, episodes)
    }

    /// The entropy weight of the update after `episodes` training episodes.
    pub fn entropy_weight_at(&self, episodes: u64) -> f64 {
        Self::linear_decay(
            self.etrpy_w_stable_at,
            self.etrpy_w_start,
            self.etrpy_w_end,
            episodes,
        )
    }

    /// Training episodes between evaluations: `eval_freq - eval_freq % train_freq`.
    pub fn eval_period(&self) -> usize {
        self.eval_freq - self.eval_freq % self.train_freq
    }
}

impl FamilyConfig for AcacConfig {
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

/// The family's range checks (see [`crate::algos::family::FamilyMethod::check`]).
pub fn check(
    c: &AcacConfig,
    method: AcacMethod,
    shape: &EnvShape,
) -> Result<(), (&'static str, String)> {
    // What ACAC can do and macdec does not (yet): refused by name rather than silently ignored.
    for (key, unsupported) in [
        ("share_encoder", c.share_encoder),
        ("critic_hys", c.critic_hys),
        ("c_target_soft_update", c.c_target_soft_update),
        ("obs_last_action", c.obs_last_action),
        ("use_attention", !c.use_attention),
        ("time_emb_alg", c.time_emb_alg != TimeEmbAlg::Sinu),
    ] {
        if unsupported {
            return Err((
                key,
                format!(
                    "macdec's {} does not implement this setting of ACAC's (every published run \
                     keeps the default)",
                    crate::algos::learner::MethodName::name(method)
                ),
            ));
        }
    }
    if method == AcacMethod::AcacVanilla {
        // learner_acac_vanilla.py builds its critics without `use_popart` (a plain Linear
        // value layer) and never reads TD_lambda's broken path: refuse what it would ignore
        // or crash on.
        if c.use_popart {
            return Err((
                "use_popart",
                "must be false for acac-vanilla: ACAC's vanilla learner has no PopArt".into(),
            ));
        }
        if c.td_lambda != 0.0 {
            return Err((
                "TD_lambda",
                format!(
                    "must be 0 for acac-vanilla (ACAC's TD(lambda) returns fail with a \
                     TypeError), got {}",
                    c.td_lambda
                ),
            ));
        }
        check_positive(&[("c_train_iteration", c.c_train_iteration)])?;
        check_at_most(&[("c_train_iteration", c.c_train_iteration, MAX_TRAIN_REPEAT)])?;
    }
    // ACAC's learner feeds the actors' time embedding only when the critic's is on
    // (`if not self.controller.time_emb: obs_seq_agent = None`): unequal flags crash its
    // actor forward, so they must agree.
    if c.time_emb != c.time_emb_actor {
        return Err((
            "time_emb_actor",
            format!(
                "must equal time_emb ({}): ACAC's learner gives the actors a time embedding \
                 exactly when the critic has one, got {}",
                c.time_emb, c.time_emb_actor
            ),
        ));
    }
    // ACAC counts its primitive-step budget at evaluations only (`log_diagnostics`): without
    // them its run never ends.
    if !c.eval_policy {
        return Err((
            "eval_policy",
            "must be true: ACAC counts its budget of primitive steps at evaluations".into(),
        ));
    }
    check_positive(&[
        ("env_terminate_step", shape.horizon),
        ("total_epi", c.total_epi),
        ("n_env", c.n_env),
        ("train_freq", c.train_freq),
        ("c_target_update_freq", c.c_target_update_freq),
        ("a_rnn_layer_size", c.a_rnn_layer_size),
        ("c_rnn_layer_size", c.c_rnn_layer_size),
        ("n_train_repeat", c.n_train_repeat),
        ("cc_n_head", c.cc_n_head),
        ("eval_freq", c.eval_freq),
        ("eval_num_epi", c.eval_num_epi),
        ("checkpoint_freq", c.checkpoint_freq),
    ])?;
    check_at_most(&[
        ("env_terminate_step", shape.horizon, MAX_HORIZON),
        ("total_epi", c.total_epi, MAX_TOTAL_EPI),
        ("n_env", c.n_env, crate::algos::training_loop::MAX_LANES),
        ("train_freq", c.train_freq, MAX_TRAIN_FREQ),
        ("n_train_repeat", c.n_train_repeat, MAX_TRAIN_REPEAT),
        ("a_rnn_layer_size", c.a_rnn_layer_size, MAX_NET_WIDTH),
        ("c_rnn_layer_size", c.c_rnn_layer_size, MAX_NET_WIDTH),
        ("time_emb_dim", c.time_emb_dim, MAX_NET_WIDTH),
        ("eval_num_epi", c.eval_num_epi, MAX_EVAL_NUM_EPI),
    ])?;
    check_mlp_widths(&[
        ("a_mlp_layer_size", &c.a_mlp_layer_size),
        ("c_mlp_layer_size", &c.c_mlp_layer_size),
    ])?;
    if !c.c_rnn_layer_size.is_multiple_of(c.cc_n_head) {
        return Err((
            "cc_n_head",
            format!(
                "must divide c_rnn_layer_size ({}), got {}: GPT-2 splits n_embd into heads",
                c.c_rnn_layer_size, c.cc_n_head
            ),
        ));
    }
    if (c.time_emb || c.time_emb_actor) && (c.time_emb_dim == 0 || c.time_emb_dim % 2 == 1) {
        return Err((
            "time_emb_dim",
            format!(
                "the sinusoidal time embedding needs an even width >= 2, got {}",
                c.time_emb_dim
            ),
        ));
    }
    // ACAC evaluates when episodes % (eval_freq - eval_freq % train_freq) == 0: a period of 0
    // is a modulo by zero in the reference.
    if c.eval_freq < c.train_freq {
        return Err((
            "eval_freq",
            format!(
                "must be at least train_freq ({}): ACAC evaluates every eval_freq - eval_freq % \
                 train_freq episodes, got {}",
                c.train_freq, c.eval_freq
            ),
        ));
    }
    let budget = (shape.horizon as u128).saturating_mul(c.total_epi as u128);
    if budget > MAX_BUDGET_STEPS {
        return Err((
            "total_epi",
            format!(
                "env_terminate_step x total_epi = {budget} primitive steps of training, at most \
                 {MAX_BUDGET_STEPS}"
            ),
        ));
    }
    // Runs at least one episode per batch; the budget in steps may take many more episodes
    // than total_epi (short episodes), so bound evaluation rows by the steps, one per episode.
    check_eval_rows(
        usize::try_from(budget).unwrap_or(usize::MAX),
        c.eval_period(),
    )?;
    check_unit(&[
        ("eps_start", c.eps_start),
        ("eps_end", c.eps_end),
        ("GAE_lambda", c.gae_lambda),
        ("clip_ratio", c.clip_ratio),
    ])?;
    check_non_negative(&[
        ("etrpy_w_start", c.etrpy_w_start),
        ("etrpy_w_end", c.etrpy_w_end),
        ("grad_clip_value", c.grad_clip_value),
        ("grad_clip_norm", c.grad_clip_norm),
        ("vf_coef", c.vf_coef),
        ("tau", c.tau),
    ])?;
    check_discount("gamma", c.gamma)?;
    check_rates(&[("a_lr", c.a_lr), ("c_lr", c.c_lr)])?;
    // One update runs every net over the whole batch: train_freq episodes of at most the
    // horizon, each agent's actor and the critic's n_agent encoders plus the attention block.
    let emb = if c.time_emb || c.time_emb_actor {
        c.time_emb_dim
    } else {
        0
    } as u128;
    let n_agents = shape.obs_sizes.len() as u128;
    let widest = c
        .a_mlp_layer_size
        .iter()
        .chain(&c.c_mlp_layer_size)
        .copied()
        .chain([c.a_rnn_layer_size, c.c_rnn_layer_size])
        .max()
        .unwrap_or(1) as u128;
    check_batch_activations(
        ("train_freq", c.train_freq),
        ("env_terminate_step", shape.horizon + 1),
        NetWidths {
            // Per agent: its actor, its critic encoder, and the attention's 4 x n_embd MLP.
            hidden: widest.saturating_mul(6).saturating_mul(n_agents.max(1)),
            input: shape
                .joint_obs_size()
                .saturating_add(emb.saturating_mul(n_agents)),
            output: shape.widest_actions().saturating_mul(n_agents),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bp(grid: i64) -> EnvSpec {
        let keys = toml::toml! { grid_dim = [grid, grid] };
        EnvSpec::new("BP-MA-v0", &keys).unwrap()
    }

    fn ovc(map: &str, random: bool) -> EnvSpec {
        let keys = toml::toml! { map_type = map  rand_start = random };
        EnvSpec::new("ACAC-Overcooked-MA-v1", &keys).unwrap()
    }

    #[test]
    fn settings_are_named_as_acacs_make_env_name() {
        assert_eq!(acac_env_name(&bp(6)).as_deref(), Some("bp6"));
        assert_eq!(acac_env_name(&bp(12)).as_deref(), Some("bp12"));
        assert_eq!(acac_env_name(&ovc("B", false)).as_deref(), Some("ovcB7"));
        assert_eq!(acac_env_name(&ovc("C", true)).as_deref(), Some("ovcCR7"));
        // MacroMARL's Overcooked is not ACAC's environment: no ACAC setting.
        let macromarl = EnvSpec::new("Overcooked-MA-v1", &toml::Table::new()).unwrap();
        assert_eq!(acac_env_name(&macromarl), None);
    }

    #[test]
    fn the_env_file_wins_over_the_algorithm_file() {
        // alg/acac.json: a_mlp_layer_size [128, 64], a_rnn 64, gamma 0.99 (default); env/bp6.json:
        // [32, 32], 32, gamma 0.98, clip_ratio 0.05 over acac.json's 0.01.
        let c = published_defaults(&bp(6), AcacMethod::Acac);
        assert_eq!(c.a_mlp_layer_size, vec![32, 32]);
        assert_eq!(c.a_rnn_layer_size, 32);
        assert_eq!(c.gamma, 0.98);
        assert_eq!(c.clip_ratio, 0.05);
        assert_eq!(c.n_train_repeat, 2);
        // acac.json over default.json where the env file is silent.
        assert_eq!(c.c_lr, 0.0003);
        assert!(c.use_popart && c.use_actor_ln && c.time_emb && c.time_emb_actor);
        assert_eq!(c.value_head, ValueHead::MeanLinear);
        assert_eq!(c.gae_lambda, 0.95);
        // default.json where neither sets the key.
        assert_eq!(c.time_emb_dim, 2);
        assert_eq!(c.cc_n_head, 2);
        assert_eq!(c.n_minibatch, 8);
        assert!(!c.duplicate);
        // acac_vanilla.json sets n_train_repeat 1 and no popart; bp6.json sets 2.
        let v = published_defaults(&bp(6), AcacMethod::AcacVanilla);
        assert_eq!(v.n_train_repeat, 2);
        assert!(!v.use_popart);
        assert_eq!(v.clip_ratio, 0.05);
        // A setting without an env file keeps default.json + the algorithm file.
        let b12 = published_defaults(&bp(12), AcacMethod::Acac);
        assert_eq!(b12.a_mlp_layer_size, vec![128, 64]);
        assert_eq!((b12.gamma, b12.clip_ratio, b12.n_env), (0.99, 0.01, 8));
    }

    #[test]
    fn every_published_setting_type_checks_and_passes_its_checks() {
        for method in [
            AcacMethod::Acac,
            AcacMethod::AcacVanilla,
            AcacMethod::AcacMicroGae,
        ] {
            for env in [bp(6), bp(8), bp(10), ovc("A", false), ovc("C", true)] {
                let c = published_defaults(&env, method);
                let shape = EnvShape::of(&env).unwrap();
                assert_eq!(check(&c, method, &shape), Ok(()), "{method:?} {env:?}");
            }
        }
    }

    #[test]
    fn epsilon_follows_linear_decay_over_episodes() {
        let c = published_defaults(&bp(6), AcacMethod::Acac);
        // bp6: 1.0 -> 0.01 over 30000 episodes.
        assert_eq!(c.epsilon_at(0), 1.0);
        assert!((c.epsilon_at(15_000) - 0.505).abs() < 1e-12);
        assert_eq!(c.epsilon_at(30_000), 1.0 + (0.01 - 1.0));
        assert_eq!(c.epsilon_at(90_000), c.epsilon_at(30_000));
        // eval_freq 100, train_freq 16: every 96 episodes.
        assert_eq!(c.eval_period(), 96);
    }

    #[test]
    fn bad_values_name_their_key() {
        let env = bp(6);
        let shape = EnvShape::of(&env).unwrap();
        let ok = published_defaults(&env, AcacMethod::Acac);
        let bad = |f: &dyn Fn(&mut AcacConfig)| {
            let mut c = ok.clone();
            f(&mut c);
            check(&c, AcacMethod::Acac, &shape).unwrap_err().0
        };
        assert_eq!(bad(&|c| c.a_mlp_layer_size = vec![32]), "a_mlp_layer_size");
        assert_eq!(bad(&|c| c.c_rnn_layer_size = 1 << 30), "c_rnn_layer_size");
        assert_eq!(bad(&|c| c.cc_n_head = 3), "cc_n_head");
        assert_eq!(bad(&|c| c.time_emb_dim = 3), "time_emb_dim");
        assert_eq!(bad(&|c| c.eval_freq = 8), "eval_freq");
        assert_eq!(bad(&|c| c.n_env = 5000), "n_env");
        assert_eq!(bad(&|c| c.train_freq = 0), "train_freq");
        assert_eq!(bad(&|c| c.train_freq = 200_000), "train_freq");
        assert_eq!(bad(&|c| c.total_epi = usize::MAX), "total_epi");
        assert_eq!(bad(&|c| c.a_lr = f64::NAN), "a_lr");
        assert_eq!(bad(&|c| c.gamma = 0.0), "gamma");
        assert_eq!(bad(&|c| c.clip_ratio = -0.1), "clip_ratio");
        assert_eq!(bad(&|c| c.grad_clip_norm = f64::INFINITY), "grad_clip_norm");
        assert_eq!(bad(&|c| c.share_encoder = true), "share_encoder");
        assert_eq!(bad(&|c| c.use_attention = false), "use_attention");
        assert_eq!(bad(&|c| c.time_emb_alg = TimeEmbAlg::Learn), "time_emb_alg");
        assert_eq!(bad(&|c| c.eval_num_epi = 0), "eval_num_epi");
        assert_eq!(bad(&|c| c.time_emb_actor = false), "time_emb_actor");
        assert_eq!(bad(&|c| c.eval_policy = false), "eval_policy");
    }
}
