//! One PPO update (`learner_acac.py: train`, `learner_acac_micro_gae.py: train`) as a pure
//! function of the nets and their Adam states, a squeezed batch, the exploration weight and a
//! source of dropout masks:
//!
//! 1. the target critic's values of every joint history (dropout live), denormalized with the
//!    online critic's PopArt statistics; macro-level GAE per episode ([`super::gae`]); PopArt's
//!    statistics updated from the batch's returns, which are then normalized;
//! 2. each actor's log-probability of its macro-actions under the eps-mixture, kept as
//!    log pi_old;
//! 3. `n_train_repeat` times: the critic's squared error to the (normalized) returns, its
//!    gradient, clipping, an Adam step; then each actor's clipped-ratio loss
//!    -sum(min(r A, clip(r, 1 - c, 1 + c) A)) / M, its gradient, clipping, an Adam step.
//!
//! Each PPO epoch uses the whole batch (ACAC stores `n_minibatch` and never reads it); no
//! entropy term enters `acac`'s loss (it is computed for the logs only).

use std::borrow::Cow;

use ndarray::{Array1, Array2};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::batch::{AcacBatch, SqueezedEpisode};
use super::gae::{episode_gae_lambdas, GaeEpisode, GaeError};
use super::nets::{AcacCritic, CriticInput};
use crate::autograd::{SeqPacking, Tape};
use crate::nn::AcacActor;
use crate::nn::{Adam, AdamConfig, Gpt2Dropout, Params, TimeEmbedding};

/// HuggingFace GPT-2's default dropout rate, live in ACAC's critic.
pub const GPT2_DROPOUT: f32 = 0.1;

/// What an update fits and how: the one place the three methods differ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Objective {
    /// `acac`, `acac-micro-gae`: macro-level GAE from the target critic with `lambda` applied
    /// as given, PopArt-normalized targets, `n_train_repeat` PPO epochs.
    Ppo(GaeLambda),
    /// `acac-vanilla` (`learner_acac_vanilla.py`, [`super::vanilla`]): n-step returns from the
    /// target critic, `critic_iterations` critic steps, then advantages G - V from the updated
    /// critic and one policy-gradient step per actor weighted by gamma^t, with an entropy bonus.
    Vanilla {
        /// `n_step_TD` (0 or 1: one-step TD).
        n_step: usize,
        /// `c_train_iteration`.
        critic_iterations: usize,
        /// `etrpy_w` of this update.
        entropy_weight: f64,
    },
}

/// How GAE's lambda enters each joint macro-step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum GaeLambda {
    /// `acac`: lambda per joint macro-step.
    PerMacroStep,
    /// `acac_micro_gae`: lambda to the macro-step's duration in primitive steps.
    PerPrimitiveStep,
}

/// The settings one update reads.
#[derive(Debug, Clone, PartialEq)]
pub struct UpdateParams {
    /// Discount per primitive step.
    pub gamma: f64,
    /// GAE's lambda.
    pub lambda: f64,
    /// The method's objective.
    pub objective: Objective,
    /// PPO's clip.
    pub clip_ratio: f64,
    /// PPO epochs.
    pub n_train_repeat: usize,
    /// The exploration weight of the batch (the actors' eps-mixture).
    pub eps: f64,
    /// Element-wise gradient clip (0: off).
    pub grad_clip_value: f64,
    /// Gradient-norm clip per net (0: off).
    pub grad_clip_norm: f64,
    /// ACAC's `--duplicate`: every critic encoder steps at every joint macro-step.
    pub duplicate: bool,
}

/// The nets and optimizers of an ACAC run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcacNets {
    /// One actor per agent.
    pub actors: Vec<AcacActor>,
    /// The online critic.
    pub critic: AcacCritic,
    /// The target critic (GAE's values), hard-copied every `c_target_update_freq` episodes.
    pub critic_target: AcacCritic,
    /// Each actor's Adam (`a_lr`).
    pub actor_adams: Vec<Adam>,
    /// The critic's Adam (`c_lr`).
    pub critic_adam: Adam,
    /// The sinusoidal time embedding (`time_emb`), shared by actors and critic.
    pub time: Option<TimeEmbedding>,
}

impl AcacNets {
    /// Optimizers for `actors` and `critic` with learning rates `a_lr`, `c_lr`.
    pub fn new(
        actors: Vec<AcacActor>,
        critic: AcacCritic,
        time: Option<TimeEmbedding>,
        a_lr: f64,
        c_lr: f64,
    ) -> Self {
        let actor_adams = actors
            .iter()
            .map(|a| Adam::new(AdamConfig::with_lr(a_lr), a))
            .collect();
        let critic_adam = Adam::new(AdamConfig::with_lr(c_lr), &critic);
        AcacNets {
            critic_target: critic.clone(),
            actors,
            critic,
            actor_adams,
            critic_adam,
            time,
        }
    }

    /// Copy the online critic into its target.
    pub fn sync_targets(&mut self) {
        self.critic_target.copy_values_from(&self.critic);
        if let (Some(t), Some(o)) = (self.critic_target.popart_mut(), self.critic.popart()) {
            t.clone_from(o);
        }
    }

    /// Whether every weight is finite.
    pub fn is_finite(&self) -> bool {
        self.critic.all_finite() && self.actors.iter().all(|a| a.all_finite())
    }

    /// Observation rows with their time embeddings appended: [rows, obs + dim].
    fn with_time(&self, obs: &Array2<f32>, time: &[usize]) -> Array2<f32> {
        match &self.time {
            None => obs.clone(),
            Some(t) => {
                let emb = t.lookup(time);
                ndarray::concatenate(ndarray::Axis(1), &[obs.view(), emb.view()])
                    .expect("rows of the same count")
            }
        }
    }
}

/// Where the GPT-2 dropout masks of an update come from.
pub enum DropoutSource<'a> {
    /// No dropout (a test's deterministic critic).
    Off,
    /// Fresh masks from a run's stream, in forward order.
    Draw(&'a mut ChaCha8Rng),
    /// The masks a reference run drew: the bootstrap forward's, then each epoch's.
    Replay(std::slice::Iter<'a, Gpt2Dropout>),
}

impl DropoutSource<'_> {
    pub(super) fn next(
        &mut self,
        rows: usize,
        critic: &AcacCritic,
    ) -> Result<Option<Gpt2Dropout>, UpdateError> {
        let cfg = critic.top.transformer.config();
        let n = critic.encoders.len();
        match self {
            DropoutSource::Off => Ok(None),
            DropoutSource::Draw(rng) => Ok(Some(Gpt2Dropout::draw(
                rows * n,
                cfg.width,
                n,
                cfg.n_head,
                cfg.n_layer,
                GPT2_DROPOUT,
                rng,
            ))),
            DropoutSource::Replay(masks) => match masks.next() {
                Some(m) if m.embd.nrows() == rows * n => Ok(Some(m.clone())),
                Some(m) => Err(UpdateError::Masks(format!(
                    "a mask of {} rows for {} joint rows of {n} agents",
                    m.embd.nrows(),
                    rows
                ))),
                None => Err(UpdateError::Masks(
                    "fewer masks than critic forwards".into(),
                )),
            },
        }
    }
}

/// Why an update cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UpdateError {
    /// An episode's GAE.
    #[error("episode {episode}: {source}")]
    Gae {
        /// The episode's index.
        episode: usize,
        /// Why.
        source: GaeError,
    },
    /// Replayed dropout masks do not fit.
    #[error("dropout masks: {0}")]
    Masks(String),
    /// A batch for other nets.
    #[error("the batch has {batch} agents, the nets {nets}")]
    Agents {
        /// In the batch.
        batch: usize,
        /// Actors.
        nets: usize,
    },
}

/// What one actor's PPO step computed.
#[derive(Debug, Clone, PartialEq)]
pub struct ActorTrace {
    /// The agent.
    pub agent: usize,
    /// Its loss.
    pub loss: f32,
    /// r = pi / pi_old per macro-action (PPO; empty for `acac-vanilla`).
    pub ratios: Vec<f32>,
    /// The entropy of the eps-mixture per macro-action (`acac-vanilla`, whose loss weighs it;
    /// empty for PPO, whose loss does not).
    pub entropies: Vec<f32>,
}

/// Everything an update computed, for tests, goldens and metrics.
#[derive(Debug, Clone, PartialEq)]
pub struct UpdateTrace {
    /// A_k of every joint macro-step, episode by episode (`acac-vanilla`: G_k - V_k with the
    /// critic after its step).
    pub advantages: Vec<f32>,
    /// G_k before PopArt (`acac-vanilla`: its n-step returns).
    pub returns: Vec<f32>,
    /// The critic's regression targets (G_k normalized with PopArt, else G_k).
    pub targets: Vec<f32>,
    /// log pi_old of each agent's macro-actions (empty for `acac-vanilla`).
    pub old_log_pi: Vec<Vec<f32>>,
    /// The critic loss of each epoch.
    pub critic_losses: Vec<f32>,
    /// Per epoch, the actors' steps.
    pub actors: Vec<Vec<ActorTrace>>,
}

/// One episode's critic rows: per agent its observations, each row's time index, and per row
/// which agents' encoders step.
pub(super) type CriticRows<'e> = (&'e [Array2<f32>], Cow<'e, [usize]>, &'e [Vec<bool>]);

/// The critic's input rows for `episodes`: per episode its rows, per agent its observations,
/// its times and which rows step agent i.
pub(super) fn critic_input<'e>(
    nets: &AcacNets,
    episodes: &'e [SqueezedEpisode],
    rows_of: impl Fn(usize, &'e SqueezedEpisode) -> CriticRows<'e>,
    duplicate: bool,
) -> CriticInput {
    let n = nets.actors.len();
    let mut input = CriticInput {
        rows_per_episode: Vec::with_capacity(episodes.len()),
        x: Vec::with_capacity(n),
        lengths: vec![Vec::with_capacity(episodes.len()); n],
        latest: vec![Vec::new(); n],
    };
    let mut parts: Vec<Vec<Array2<f32>>> = vec![Vec::new(); n];
    let mut taken = vec![0usize; n];
    for (k, e) in episodes.iter().enumerate() {
        let (obs, time, steps) = rows_of(k, e);
        input.rows_per_episode.push(steps.len());
        for i in 0..n {
            let rows: Vec<usize> = (0..steps.len())
                .filter(|&k| {
                    if duplicate {
                        steps[k].iter().any(|&s| s)
                    } else {
                        steps[k][i]
                    }
                })
                .collect();
            let picked = obs[i].select(ndarray::Axis(0), &rows);
            let t: Vec<usize> = rows.iter().map(|&k| time[k]).collect();
            parts[i].push(nets.with_time(&picked, &t));
            input.lengths[i].push(rows.len());
            // recover_joint_feature: the latest encoding at or before each row.
            let mut seen = 0usize;
            for step in steps {
                let stepped = if duplicate {
                    step.iter().any(|&s| s)
                } else {
                    step[i]
                };
                seen += usize::from(stepped);
                // Row 0 always steps every agent (checked when squeezing).
                input.latest[i].push(taken[i] + seen.max(1) - 1);
            }
            taken[i] += rows.len();
        }
    }
    for p in parts {
        let views: Vec<_> = p.iter().map(|a| a.view()).collect();
        input
            .x
            .push(ndarray::concatenate(ndarray::Axis(0), &views).expect("same widths"));
    }
    input
}

/// The critic's input for training on `batch`: each joint macro-step's observations, at its
/// start's time, each agent's encoder stepping where it started a macro-action.
pub(super) fn training_critic_input(
    nets: &AcacNets,
    batch: &AcacBatch,
    duplicate: bool,
) -> CriticInput {
    critic_input(
        nets,
        &batch.episodes,
        |_, e| {
            (
                &e.critic_obs,
                Cow::Borrowed(&e.critic_time),
                &e.critic_starts,
            )
        },
        duplicate,
    )
}

/// log pi of the taken macro-actions under the eps-mixture, on `tape`:
/// logsumexp(log pi + ln(1 - eps), ln(eps) - ln |A|) as ACAC's actor forward computes it.
pub(super) fn mixture_log_prob(
    tape: &mut Tape,
    log_pi: crate::autograd::Var,
    actions: &[usize],
    eps: f64,
) -> crate::autograd::Var {
    let n_actions = tape.shape(log_pi).1;
    let rows = actions.len();
    let picked = tape.gather_cols(log_pi, actions);
    let keep = Array2::from_elem((rows, 1), (1.0 - eps).ln() as f32);
    let keep = tape.constant_owned(keep);
    let shifted = tape.add(picked, keep);
    let uniform = (eps.ln() - (n_actions as f64).ln()) as f32;
    let uniform = tape.constant_owned(Array2::from_elem((rows, 1), uniform));
    let pair = tape.concat_cols(&[shifted, uniform]);
    tape.logsumexp(pair)
}

/// One actor's inputs over the batch: rows, per-episode lengths, actions and joint steps.
pub(super) struct ActorInput {
    pub(super) x: Array2<f32>,
    pub(super) lengths: Vec<usize>,
    pub(super) actions: Vec<usize>,
    /// Index into the batch's joint macro-steps (all episodes).
    pub(super) joint: Vec<usize>,
    /// The primitive step at which each macro-action ended.
    pub(super) end_steps: Vec<usize>,
}

pub(super) fn actor_input(nets: &AcacNets, batch: &AcacBatch, agent: usize) -> ActorInput {
    let mut parts = Vec::new();
    let mut input = ActorInput {
        x: Array2::zeros((0, 0)),
        lengths: Vec::new(),
        actions: Vec::new(),
        joint: Vec::new(),
        end_steps: Vec::new(),
    };
    let mut offset = 0;
    for e in &batch.episodes {
        let a = &e.agents[agent];
        parts.push(nets.with_time(&a.obs, &a.time));
        input.lengths.push(a.actions.len());
        input.actions.extend(&a.actions);
        input.end_steps.extend(&a.end_step);
        input.joint.extend(a.joint_step.iter().map(|k| offset + k));
        offset += e.joint_steps;
    }
    let views: Vec<_> = parts.iter().map(|a| a.view()).collect();
    input.x = ndarray::concatenate(ndarray::Axis(0), &views).expect("same widths");
    input
}

/// Element-wise then norm clipping of a gradient set, as `clip_grad_value_` and
/// `clip_grad_norm_` (max_norm / (norm + 1e-6) when the norm exceeds it).
pub(super) fn clip<P: Params>(grads: &mut P, value: f64, norm: f64) {
    if value > 0.0 {
        let v = value as f32;
        for s in grads.slices_mut() {
            for g in s.iter_mut() {
                *g = g.clamp(-v, v);
            }
        }
    }
    if norm > 0.0 {
        let total = grads
            .slices()
            .iter()
            .flat_map(|s| s.iter())
            .map(|g| g * g)
            .sum::<f32>()
            .sqrt();
        let coef = norm as f32 / (total + 1e-6);
        if coef < 1.0 {
            for s in grads.slices_mut() {
                for g in s.iter_mut() {
                    *g *= coef;
                }
            }
        }
    }
}

/// Step 1's results: per joint macro-step, episode by episode.
struct Targets {
    /// A_k.
    advantages: Vec<f32>,
    /// G_k before PopArt.
    returns: Vec<f32>,
    /// G_k normalized with PopArt (the critic's regression targets), else G_k.
    targets: Vec<f32>,
}

/// The advantages and critic targets of `batch` (step 1 of the module docs). Updates the online
/// critic's PopArt statistics.
fn advantages(
    nets: &mut AcacNets,
    batch: &AcacBatch,
    p: &UpdateParams,
    gae_lambda: GaeLambda,
    dropout: &mut DropoutSource<'_>,
    tape: &mut Tape,
) -> Result<Targets, UpdateError> {
    let input = critic_input(
        nets,
        &batch.episodes,
        |_, e| {
            (
                &e.bootstrap_obs,
                Cow::Borrowed(&e.bootstrap_time),
                &e.bootstrap_steps,
            )
        },
        p.duplicate,
    );
    let rows: usize = input.rows_per_episode.iter().sum();
    let masks = dropout.next(rows, &nets.critic_target)?;
    let mut values = nets.critic_target.values(tape, &input, masks.as_ref());
    if let Some(pa) = nets.critic.popart() {
        values = pa
            .denormalize(values.view().insert_axis(ndarray::Axis(1)))
            .column(0)
            .to_owned();
    }
    let (mut adv, mut ret) = (Vec::new(), Vec::new());
    let mut at = 0;
    for (k, e) in batch.episodes.iter().enumerate() {
        let v = &values.as_slice().expect("contiguous")[at..at + e.joint_steps + 1];
        at += e.joint_steps + 1;
        let discounts = end_discounts(&e.end_steps, p.gamma);
        let lambdas: Vec<f32> = match gae_lambda {
            GaeLambda::PerMacroStep => vec![p.lambda as f32; e.joint_steps],
            GaeLambda::PerPrimitiveStep => {
                let pows: Vec<f32> = e
                    .end_steps
                    .iter()
                    .map(|&t| (p.lambda as f32).powf(t as f32))
                    .collect();
                let first = (1.0 / p.lambda) as f32;
                (0..pows.len())
                    .map(|k| pows[k] / if k == 0 { first } else { pows[k - 1] })
                    .collect()
            }
        };
        let g = episode_gae_lambdas(
            GaeEpisode {
                rewards: &e.rewards,
                initial_value: v[0],
                bootstrap: &v[1..],
                discounts: &discounts,
                terminated: e.terminated,
            },
            p.gamma,
            &lambdas,
        )
        .map_err(|source| UpdateError::Gae { episode: k, source })?;
        adv.extend(g.advantages);
        ret.extend(g.returns);
    }
    let targets = match nets.critic.popart_mut() {
        Some(pa) => {
            let g = Array2::from_shape_vec((ret.len(), 1), ret.clone()).expect("a column");
            pa.update(g.view());
            pa.normalize(g.view()).column(0).to_vec()
        }
        None => ret.clone(),
    };
    Ok(Targets {
        advantages: adv,
        returns: ret,
        targets,
    })
}

/// gamma^t of each primitive step t, in f32 as `torch.pow` computes ACAC's `discount`.
pub(super) fn end_discounts(steps: &[usize], gamma: f64) -> Vec<f32> {
    steps
        .iter()
        .map(|&t| (gamma as f32).powf(t as f32))
        .collect()
}

/// The critic's loss sum((G - V)^2) / R on `input` against `targets` [R, 1], and its gradient.
pub fn critic_loss(
    critic: &AcacCritic,
    input: &CriticInput,
    targets: &Array2<f32>,
    masks: Option<&Gpt2Dropout>,
    tape: &mut Tape,
) -> (f32, AcacCritic) {
    let rows = targets.nrows();
    tape.reset();
    let vars = critic.bind(tape);
    let v = vars.forward(tape, input, masks);
    let g = tape.constant(targets.view());
    let td = tape.sub(g, v);
    let sq = tape.square(td);
    let total = tape.sum(sq);
    let loss = tape.scale(total, 1.0 / rows as f32);
    let value = tape.scalar(loss);
    tape.backward(loss);
    let mut grads = critic.zeros_like();
    vars.grads_into(tape, &mut grads);
    (value, grads)
}

/// One actor's PPO loss, its gradient and ratios.
pub struct ActorStep {
    /// -sum(min(r A, clip(r, 1 - c, 1 + c) A)) / M.
    pub loss: f32,
    /// Its gradient.
    pub grads: AcacActor,
    /// r per macro-action.
    pub ratios: Vec<f32>,
}

/// The clipped-ratio loss of `actor` on its inputs with log pi_old `old` and advantages `adv`.
fn actor_loss(
    actor: &AcacActor,
    input: &ActorInput,
    old: &[f32],
    adv: &[f32],
    p: &UpdateParams,
    tape: &mut Tape,
) -> ActorStep {
    let clip_ratio = p.clip_ratio as f32;
    let m = input.actions.len();
    tape.reset();
    let vars = actor.bind(tape);
    let x = tape.constant(input.x.view());
    let log_pi = vars.forward(tape, x, &SeqPacking::new(&input.lengths));
    let mixed = mixture_log_prob(tape, log_pi, &input.actions, p.eps);
    let old = tape.constant_owned(Array2::from_shape_vec((m, 1), old.to_vec()).expect("a column"));
    let diff = tape.sub(mixed, old);
    let ratio = tape.exp(diff);
    let r: Vec<f32> = tape.value(ratio).column(0).to_vec();
    // min(r A, clip(r) A): the gradient flows through r where r is inside the clip range (both
    // branches equal: torch.minimum splits it, clamp passes it) or the unclipped branch is the
    // smaller one.
    let mut loss_value = 0f32;
    let weights: Array1<f32> = r
        .iter()
        .zip(adv)
        .map(|(&r, &a)| {
            let clipped = r.clamp(1.0 - clip_ratio, 1.0 + clip_ratio);
            let (pg1, pg2) = (a * r, a * clipped);
            loss_value += pg1.min(pg2);
            let inside = (1.0 - clip_ratio..=1.0 + clip_ratio).contains(&r);
            if inside || pg1 < pg2 {
                a
            } else {
                0.0
            }
        })
        .collect();
    let w = tape.constant_owned(weights.insert_axis(ndarray::Axis(1)));
    let weighted = tape.mul(ratio, w);
    let total = tape.sum(weighted);
    let loss = tape.scale(total, -1.0 / m as f32);
    tape.backward(loss);
    let mut grads = actor.zeros_like();
    vars.grads_into(tape, &mut grads);
    ActorStep {
        loss: -loss_value / m as f32,
        grads,
        ratios: r,
    }
}

/// One `acac` or `acac-micro-gae` update of `nets` on `batch` with GAE's lambda applied as
/// `gae_lambda` (see the module docs; [`super::train_step::update`] picks the method's).
pub(super) fn ppo_update(
    nets: &mut AcacNets,
    batch: &AcacBatch,
    p: &UpdateParams,
    gae_lambda: GaeLambda,
    mut dropout: DropoutSource<'_>,
    tape: &mut Tape,
) -> Result<UpdateTrace, UpdateError> {
    let n = nets.actors.len();
    let Targets {
        advantages: adv,
        returns,
        targets,
    } = advantages(nets, batch, p, gae_lambda, &mut dropout, tape)?;
    let inputs: Vec<ActorInput> = (0..n).map(|i| actor_input(nets, batch, i)).collect();
    // log pi_old under the batch's eps-mixture.
    let mut old_log_pi = Vec::with_capacity(n);
    for (actor, input) in nets.actors.iter().zip(&inputs) {
        if input.actions.is_empty() {
            old_log_pi.push(Vec::new());
            continue;
        }
        tape.reset();
        let vars = actor.bind(tape);
        let x = tape.constant(input.x.view());
        let log_pi = vars.forward(tape, x, &SeqPacking::new(&input.lengths));
        let mixed = mixture_log_prob(tape, log_pi, &input.actions, p.eps);
        old_log_pi.push(tape.value(mixed).column(0).to_vec());
    }
    let critic_in = training_critic_input(nets, batch, p.duplicate);
    let rows = targets.len();
    let target_col = Array2::from_shape_vec((rows, 1), targets.clone()).expect("a column");
    let mut trace = UpdateTrace {
        advantages: adv.clone(),
        returns,
        targets,
        old_log_pi: old_log_pi.clone(),
        critic_losses: Vec::new(),
        actors: Vec::new(),
    };
    for _ in 0..p.n_train_repeat {
        let masks = dropout.next(rows, &nets.critic)?;
        let (loss, mut grads) =
            critic_loss(&nets.critic, &critic_in, &target_col, masks.as_ref(), tape);
        trace.critic_losses.push(loss);
        clip(&mut grads, p.grad_clip_value, p.grad_clip_norm);
        nets.critic_adam.step(&mut nets.critic, &grads);
        let mut steps = Vec::with_capacity(n);
        for (i, input) in inputs.iter().enumerate() {
            if input.actions.is_empty() {
                continue;
            }
            let a: Vec<f32> = input.joint.iter().map(|&k| adv[k]).collect();
            let step = actor_loss(&nets.actors[i], input, &old_log_pi[i], &a, p, tape);
            let mut grads = step.grads;
            clip(&mut grads, p.grad_clip_value, p.grad_clip_norm);
            nets.actor_adams[i].step(&mut nets.actors[i], &grads);
            steps.push(ActorTrace {
                agent: i,
                loss: step.loss,
                ratios: step.ratios,
                entropies: Vec::new(),
            });
        }
        trace.actors.push(steps);
    }
    Ok(trace)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::algos::actor_critic::episode::{Episode, EpisodeRecorder};
    use crate::envs::MacroEnv;
    use crate::experiment::run::train_run::run_rngs;
    use crate::nn::ValueHead;
    use rand::{Rng, SeedableRng};

    /// `n` Box Pushing 6x6 episodes of horizon 20 under uniformly random macro-actions.
    pub(crate) fn episodes(n: usize) -> (Vec<Episode>, Vec<usize>, Vec<usize>) {
        let spec = crate::envs::bp_ma_v0::spec(6, 20);
        let mut env = spec.build().unwrap();
        let mut env_rng = run_rngs(0).env;
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        env.reset(&mut env_rng);
        let mut rec = EpisodeRecorder::new(&env, 0.95, false);
        let mut out = Vec::new();
        let mut actions = vec![0; env.n_agents()];
        while out.len() < n {
            for (i, a) in actions.iter_mut().enumerate() {
                *a = if rec.free()[i] {
                    rng.gen_range(0..env.n_actions()[i])
                } else {
                    env.executed()[i]
                };
            }
            let outcome = env.step(&actions, &mut env_rng).unwrap();
            rec.record(&env, outcome);
            if outcome.done {
                out.push(rec.episode().clone());
                env.reset(&mut env_rng);
                rec.begin(&env);
            }
        }
        (out, env.obs_sizes().to_vec(), env.n_actions().to_vec())
    }

    pub(crate) fn small_nets(obs: &[usize], actions: &[usize], popart: bool) -> AcacNets {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let time = TimeEmbedding::sinusoidal(20, 2).unwrap();
        let actors = obs
            .iter()
            .zip(actions)
            .map(|(&o, &a)| AcacActor::new(o + 2, [6, 5], 4, a, true, &mut rng))
            .collect();
        let inputs: Vec<usize> = obs.iter().map(|&o| o + 2).collect();
        let critic = AcacCritic::new(&inputs, 6, 4, 2, ValueHead::MeanLinear, popart, &mut rng);
        AcacNets::new(actors, critic, Some(time), 3e-4, 3e-4)
    }

    /// `acac`'s update (these tests' params are PPO's).
    fn update(
        nets: &mut AcacNets,
        batch: &AcacBatch,
        p: &UpdateParams,
        dropout: DropoutSource<'_>,
    ) -> Result<UpdateTrace, UpdateError> {
        ppo_update(
            nets,
            batch,
            p,
            GaeLambda::PerMacroStep,
            dropout,
            &mut Tape::new(),
        )
    }

    fn params(eps: f64) -> UpdateParams {
        UpdateParams {
            gamma: 0.95,
            lambda: 0.9,
            objective: Objective::Ppo(GaeLambda::PerMacroStep),
            clip_ratio: 0.2,
            n_train_repeat: 2,
            eps,
            grad_clip_value: 0.0,
            grad_clip_norm: 0.0,
            duplicate: false,
        }
    }

    /// Central differences of `loss` over every `stride`-th element of `net`, against `grads`.
    pub(crate) fn check_fd<P: Params + Clone>(
        net: &P,
        grads: &P,
        stride: usize,
        loss: impl Fn(&P) -> f32,
    ) -> usize {
        let h = 3e-3f32;
        let (mut checked, mut nonzero) = (0, 0);
        let n_slices = net.slices().len();
        for s in 0..n_slices {
            let len = net.slices()[s].len();
            // At most about 40 elements of a tensor (GPT-2's 1024 position rows are mostly
            // unused by n agents).
            let step = stride.max(len / 40);
            for k in (s % step.min(len)..len).step_by(step) {
                let mut plus = net.clone();
                plus.slices_mut()[s][k] += h;
                let mut minus = net.clone();
                minus.slices_mut()[s][k] -= h;
                let fd = (loss(&plus) - loss(&minus)) / (2.0 * h);
                let an = grads.slices()[s][k];
                assert!(
                    (fd - an).abs() <= 3e-3 + 3e-2 * an.abs(),
                    "tensor {s} element {k}: finite difference {fd}, gradient {an}"
                );
                checked += 1;
                nonzero += usize::from(an.abs() > 1e-3);
            }
        }
        assert!(
            nonzero >= 20,
            "only {nonzero} of {checked} gradients are non-zero"
        );
        checked
    }

    #[test]
    fn critic_loss_gradient_matches_finite_differences_through_encoders_attention_and_popart() {
        let (eps, obs, acts) = episodes(3);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let nets = small_nets(&obs, &acts, true);
        let input = critic_input(
            &nets,
            &batch.episodes,
            |_, e| {
                (
                    &e.critic_obs,
                    Cow::Borrowed(&e.critic_time[..]),
                    &e.critic_starts,
                )
            },
            false,
        );
        let rows: usize = input.rows_per_episode.iter().sum();
        let targets = Array2::from_shape_fn((rows, 1), |(r, _)| (r as f32 * 0.7).sin());
        // Dropout on, with the same masks in every evaluation.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let masks = DropoutSource::Draw(&mut rng)
            .next(rows, &nets.critic)
            .unwrap();
        let (_, grads) = critic_loss(
            &nets.critic,
            &input,
            &targets,
            masks.as_ref(),
            &mut Tape::new(),
        );
        let checked = check_fd(&nets.critic, &grads, 7, |c| {
            critic_loss(c, &input, &targets, masks.as_ref(), &mut Tape::new()).0
        });
        assert!(checked > 60, "{checked}");
    }

    #[test]
    fn ppo_loss_gradient_matches_finite_differences_through_the_actor_and_mixture() {
        let (eps, obs, acts) = episodes(3);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let nets = small_nets(&obs, &acts, true);
        let p = params(0.3);
        let input = actor_input(&nets, &batch, 0);
        let m = input.actions.len();
        // log pi_old away from log pi so that some ratios fall outside the clip range, but not
        // within a finite-difference step of its edges.
        let mut tape = Tape::new();
        let vars = nets.actors[0].bind(&mut tape);
        let x = tape.constant(input.x.view());
        let lp = vars.forward(&mut tape, x, &SeqPacking::new(&input.lengths));
        let now = mixture_log_prob(&mut tape, lp, &input.actions, p.eps);
        let offsets = [-0.4f32, -0.05, 0.0, 0.08, 0.35];
        let old: Vec<f32> = tape
            .value(now)
            .column(0)
            .iter()
            .enumerate()
            .map(|(k, v)| v + offsets[k % offsets.len()])
            .collect();
        let adv: Vec<f32> = (0..m).map(|k| (k as f32 * 1.3).cos()).collect();
        let step = actor_loss(&nets.actors[0], &input, &old, &adv, &p, &mut Tape::new());
        assert!(step.ratios.iter().any(|&r| r > 1.2) && step.ratios.iter().any(|&r| r < 0.8));
        check_fd(&nets.actors[0], &step.grads, 3, |a| {
            actor_loss(a, &input, &old, &adv, &p, &mut Tape::new()).loss
        });
    }

    #[test]
    fn the_clipped_branch_stops_the_gradient_and_the_unclipped_one_does_not() {
        // PPO's min(r A, clip(r) A) with r = e^0.5 > 1 + c: for A > 0 the clipped branch is the
        // smaller and constant (zero gradient); for A < 0 the unclipped one is (gradient).
        let (eps, obs, acts) = episodes(2);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let nets = small_nets(&obs, &acts, false);
        let p = params(0.1);
        let input = actor_input(&nets, &batch, 1);
        let m = input.actions.len();
        let mut tape = Tape::new();
        let vars = nets.actors[1].bind(&mut tape);
        let x = tape.constant(input.x.view());
        let lp = vars.forward(&mut tape, x, &SeqPacking::new(&input.lengths));
        let now = mixture_log_prob(&mut tape, lp, &input.actions, p.eps);
        let old: Vec<f32> = tape.value(now).column(0).iter().map(|v| v - 0.5).collect();
        let up = actor_loss(
            &nets.actors[1],
            &input,
            &old,
            &vec![2.0; m],
            &p,
            &mut Tape::new(),
        );
        assert!(up
            .grads
            .slices()
            .iter()
            .all(|s| s.iter().all(|&g| g == 0.0)));
        // loss = -mean(clip(r) A) = -(1.2 * 2).
        assert!((up.loss + 2.4).abs() < 1e-5, "{}", up.loss);
        let down = actor_loss(
            &nets.actors[1],
            &input,
            &old,
            &vec![-2.0; m],
            &p,
            &mut Tape::new(),
        );
        assert!(down
            .grads
            .slices()
            .iter()
            .any(|s| s.iter().any(|&g| g != 0.0)));
        // loss = -mean(r A) = 2 e^0.5.
        let want = 2.0 * 0.5f32.exp();
        assert!((down.loss - want).abs() < 1e-4, "{} vs {want}", down.loss);
    }

    #[test]
    fn at_eps_one_the_mixture_is_uniform_and_the_actors_do_not_move() {
        let (eps, obs, acts) = episodes(2);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let mut nets = small_nets(&obs, &acts, true);
        let before = nets.actors.clone();
        let trace = update(&mut nets, &batch, &params(1.0), DropoutSource::Off).unwrap();
        let uniform = -(acts[0] as f32).ln();
        assert!(trace.old_log_pi[0]
            .iter()
            .all(|&l| (l - uniform).abs() < 1e-6));
        assert_eq!(nets.actors, before);
        // The critic did move, twice (n_train_repeat 2).
        assert_eq!(trace.critic_losses.len(), 2);
        assert_ne!(nets.critic, nets.critic_target);
    }

    #[test]
    fn popart_targets_are_the_returns_normalized_by_the_updated_statistics() {
        let (eps, obs, acts) = episodes(3);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let mut nets = small_nets(&obs, &acts, true);
        let trace = update(&mut nets, &batch, &params(0.5), DropoutSource::Off).unwrap();
        let pa = nets.critic.popart().unwrap();
        let (mean, var) = pa.debiased_mean_var();
        for (g, t) in trace.returns.iter().zip(&trace.targets) {
            let want = (g - mean[0]) / var[0].sqrt();
            assert!(
                (t - want).abs() < 1e-4 * (1.0 + want.abs()),
                "{t} vs {want}"
            );
        }
        // The statistics moved from their initial (0, 1) toward the returns' mean.
        let ret_mean = trace.returns.iter().sum::<f32>() / trace.returns.len() as f32;
        assert!(
            (mean[0] - ret_mean).abs() < 1e-3 * (1.0 + ret_mean.abs()),
            "{mean} {ret_mean}"
        );
        // One advantage and return per joint macro-step of the batch.
        let steps: usize = batch.episodes.iter().map(|e| e.joint_steps).sum();
        assert_eq!(
            (trace.advantages.len(), trace.targets.len()),
            (steps, steps)
        );
    }

    #[test]
    fn replayed_masks_must_fit_and_give_the_drawn_numbers() {
        let (eps, obs, acts) = episodes(2);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let mut a = small_nets(&obs, &acts, true);
        let mut b = a.clone();
        // Record the masks a draw produces, then replay them.
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let boot_rows: usize = batch.episodes.iter().map(|e| e.joint_steps + 1).sum();
        let rows: usize = batch.episodes.iter().map(|e| e.joint_steps).sum();
        let mut masks = vec![DropoutSource::Draw(&mut rng)
            .next(boot_rows, &a.critic)
            .unwrap()
            .unwrap()];
        for _ in 0..2 {
            masks.push(
                DropoutSource::Draw(&mut rng)
                    .next(rows, &a.critic)
                    .unwrap()
                    .unwrap(),
            );
        }
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let ta = update(&mut a, &batch, &params(0.5), DropoutSource::Draw(&mut rng)).unwrap();
        let tb = update(
            &mut b,
            &batch,
            &params(0.5),
            DropoutSource::Replay(masks.iter()),
        )
        .unwrap();
        assert_eq!(ta, tb);
        assert_eq!(a, b);
        // Too few masks is an error, not a panic.
        let err = update(
            &mut b,
            &batch,
            &params(0.5),
            DropoutSource::Replay(masks[..2].iter()),
        );
        assert!(matches!(err, Err(UpdateError::Masks(_))));
    }
}
