//! The ACAC family's learner as the training loop drives it (`algs/acac.py: learn`,
//! `envs_runner.py`): `n_env` lanes stepped in lockstep until `train_freq` episodes completed
//! (the unfinished are dropped), one PPO update on the last `train_freq` completed
//! ([`super::update`]), the target critic hard-copied every `c_target_update_freq` episodes,
//! then an evaluation every `eval_freq - eval_freq % train_freq` episodes, until
//! `env_terminate_step x total_epi` primitive steps of completed training episodes, counted at
//! evaluations as ACAC counts them (`total_timesteps` grows in `log_diagnostics`).
//!
//! The three methods differ only in the update's [`Objective`] ([`AcacLearner::update_params`]).

use std::collections::VecDeque;

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::batch::AcacBatch;
use super::config::AcacConfig;
use super::error::AcacError;
use super::method::AcacMethod;
use super::nets::AcacCritic;
use super::train_step::update;
use super::update::{AcacNets, DropoutSource, GaeLambda, Objective, UpdateParams, UpdateTrace};
use crate::algos::actor_critic::episode::{Episode, EpisodeRecorder};
use crate::algos::actor_critic::lockstep_eval::lockstep_episodes;
use crate::algos::learner::{
    EvalReturns, LanePlan, Learner, LearnerRngs, MethodName, SavedNets, Schedule,
    COMPLETED_EPISODE_STEPS,
};
use crate::algos::scratch::Scratch;
use crate::algos::train_error::TrainError;
use crate::algos::update_means::UpdateMeans;
use crate::autograd::Tape;
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};
use crate::nn::sampling::{mixture, sample_weighted};
use crate::nn::{AcacActor, AcacActorState};
use crate::nn::{ActingNetRef, TimeEmbedding};
use crate::policy_files::SavedNet;

/// The family's `metrics.csv` columns: ACAC's `Timesteps` (primitive steps of the completed
/// training episodes, the x-axis of its curves), the exploration weight, the mean critic and
/// actor losses of the updates since the previous row, and the mean undiscounted return of the
/// training episodes completed since then (ACAC's `Train/Return`).
pub const METRIC_COLUMNS: [&str; 5] = [
    COMPLETED_EPISODE_STEPS,
    "eps",
    "critic_loss",
    "actor_loss",
    "train_return_undiscounted",
];

/// One training lane: the episode being recorded and the actors' recurrent states.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AcacLane {
    recorder: EpisodeRecorder,
    states: Vec<AcacActorState>,
}

/// The nets, the batch memory and the learner's streams of an ACAC run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AcacLearner {
    config: AcacConfig,
    method: AcacMethod,
    seed: u64,
    obs_sizes: Vec<usize>,
    horizon: usize,
    nets: AcacNets,
    explore_rng: ChaCha8Rng,
    /// The critic's dropout masks.
    dropout_rng: ChaCha8Rng,
    eps: f64,
    /// The entropy weight of the batch (`etrpy_w`, read by `acac-vanilla`).
    entropy_weight: f64,
    /// The last `train_freq` completed training episodes (`Memory_epi`).
    memory: VecDeque<Episode>,
    /// ACAC's `total_timesteps`: steps of completed training episodes, counted at evaluations.
    timesteps: u64,
    /// Steps of training episodes completed since the last evaluation.
    pending_steps: u64,
    /// Losses and training returns since the last metrics row.
    means: UpdateMeans,
    /// The updates' tape, reset before every forward.
    #[serde(skip, default)]
    tape: Scratch<Tape>,
    #[serde(skip, default)]
    probs: Vec<f64>,
}

impl AcacLearner {
    fn c(&self) -> &AcacConfig {
        &self.config
    }

    /// The update's settings with exploration weight `eps` and entropy weight
    /// `entropy_weight`: where the three methods differ.
    pub fn update_params(&self, eps: f64, entropy_weight: f64) -> UpdateParams {
        let c = self.c();
        UpdateParams {
            gamma: c.gamma,
            lambda: c.gae_lambda,
            objective: match self.method {
                AcacMethod::Acac => Objective::Ppo(GaeLambda::PerMacroStep),
                AcacMethod::AcacMicroGae => Objective::Ppo(GaeLambda::PerPrimitiveStep),
                AcacMethod::AcacVanilla => Objective::Vanilla {
                    n_step: c.n_step_td,
                    critic_iterations: c.c_train_iteration,
                    entropy_weight,
                },
            },
            clip_ratio: c.clip_ratio,
            n_train_repeat: c.n_train_repeat,
            eps,
            grad_clip_value: c.grad_clip_value,
            grad_clip_norm: c.grad_clip_norm,
            duplicate: c.duplicate,
        }
    }

    /// The nets (tests, goldens).
    pub fn nets(&self) -> &AcacNets {
        &self.nets
    }

    /// The nets, mutable (goldens load the reference's weights).
    pub fn nets_mut(&mut self) -> &mut AcacNets {
        &mut self.nets
    }

    /// ACAC's primitive-step budget: `env_terminate_step x total_epi`.
    pub fn budget_steps(&self) -> u64 {
        self.horizon as u64 * self.c().total_epi as u64
    }

    fn zero_states(&self) -> Vec<AcacActorState> {
        self.nets.actors.iter().map(|a| a.zero_state()).collect()
    }

    fn non_finite(&self, what: &'static str, episodes: u64) -> TrainError {
        TrainError::non_finite(self.method.name(), self.seed, what, episodes)
    }

    fn family_error(&self, e: impl std::fmt::Display, episodes: u64) -> TrainError {
        TrainError::Family(Box::new(AcacError::Update {
            method: self.method.name(),
            seed: self.seed,
            episodes,
            reason: e.to_string(),
        }))
    }

    /// Free agents sample their macro-actions (busy ones keep theirs): the eps-mixture while
    /// training (`eps` Some), the plain policy when evaluated. Each reads the time as every
    /// ACAC policy does: the environment's primitive steps since reset ([`MacroEnv::t`]), as
    /// `eval` and robots pass it ([`crate::nn::acting_input`]).
    #[allow(clippy::too_many_arguments)]
    fn choose<E: MacroEnv>(
        nets: &AcacNets,
        env: &E,
        free: &[bool],
        states: &mut [AcacActorState],
        eps: Option<f64>,
        rng: &mut ChaCha8Rng,
        probs: &mut Vec<f64>,
        actions: &mut [usize],
    ) {
        let running = env.executed();
        let step = env.t();
        for (i, state) in states.iter_mut().enumerate() {
            if !free[i] {
                actions[i] = running[i];
                continue;
            }
            let logp = nets.actors[i].act_at(env.obs(i), nets.time.as_ref(), step, state);
            mixture(logp, eps, probs);
            actions[i] = sample_weighted(probs, rng);
        }
    }

    /// One update on the memory with the current exploration weight, returning its trace.
    pub fn update_traced(&mut self, episodes: u64) -> Result<UpdateTrace, TrainError> {
        let batch = AcacBatch::from_episodes(self.memory.iter(), &self.obs_sizes)
            .map_err(|e| self.family_error(e, episodes))?;
        let p = self.update_params(self.eps, self.entropy_weight);
        update(
            &mut self.nets,
            &batch,
            &p,
            DropoutSource::Draw(&mut self.dropout_rng),
            &mut self.tape.0,
        )
        .map_err(|e| self.family_error(e, episodes))
    }
}

impl Learner for AcacLearner {
    type Lane = AcacLane;
    type Method = AcacMethod;
    type Config = AcacConfig;

    fn new<E: MacroEnv>(
        config: &AcacConfig,
        method: AcacMethod,
        seed: u64,
        env: &E,
        mut rngs: LearnerRngs,
    ) -> Result<Self, TrainError> {
        let c = config;
        let horizon = env.horizon();
        let time = if c.time_emb {
            Some(
                TimeEmbedding::sinusoidal(horizon, c.time_emb_dim)
                    .map_err(|e| TrainError::Nets(e.to_string()))?,
            )
        } else {
            None
        };
        let emb = time.as_ref().map_or(0, |t| t.dim());
        let obs_sizes = env.obs_sizes().to_vec();
        let init = &mut rngs.init;
        let actors: Vec<AcacActor> = obs_sizes
            .iter()
            .zip(env.n_actions())
            .map(|(&o, &a)| {
                AcacActor::new(
                    o + emb,
                    [c.a_mlp_layer_size[0], c.a_mlp_layer_size[1]],
                    c.a_rnn_layer_size,
                    a,
                    c.use_actor_ln,
                    init,
                )
            })
            .collect();
        let inputs: Vec<usize> = obs_sizes.iter().map(|&o| o + emb).collect();
        let critic = AcacCritic::new(
            &inputs,
            c.c_mlp_layer_size[0],
            c.c_rnn_layer_size,
            c.cc_n_head,
            c.value_head,
            c.use_popart,
            init,
        );
        let nets = AcacNets::new(actors, critic, time, c.a_lr, c.c_lr);
        // Dropout masks from the replay role's stream (ACAC keeps no replay).
        Ok(AcacLearner {
            config: config.clone(),
            method,
            seed,
            obs_sizes,
            horizon,
            nets,
            explore_rng: rngs.explore,
            dropout_rng: rngs.replay,
            eps: config.eps_start,
            entropy_weight: config.etrpy_w_start,
            memory: VecDeque::new(),
            timesteps: 0,
            pending_steps: 0,
            means: UpdateMeans::default(),
            tape: Scratch::default(),
            probs: Vec::new(),
        })
    }

    fn method(&self) -> AcacMethod {
        self.method
    }

    fn seed(&self) -> u64 {
        self.seed
    }

    fn config(&self) -> &AcacConfig {
        &self.config
    }

    fn schedule(&self) -> Schedule {
        let c = self.c();
        Schedule::EpisodeBatches {
            train_freq: c.train_freq as u64,
            target_update_freq: c.c_target_update_freq as u64,
            eval_period: c.eval_period() as u64,
            eval_after_update: true,
        }
    }

    /// ACAC's `while self.total_timesteps < self.max_timesteps`.
    fn is_finished(&self, _episodes: u64) -> bool {
        self.timesteps >= self.budget_steps()
    }

    fn lanes(&self) -> Vec<LanePlan> {
        vec![
            LanePlan {
                counts_episodes: true
            };
            self.c().n_env
        ]
    }

    fn begin_lane<E: MacroEnv>(&self, _lane: usize, env: &E) -> Result<AcacLane, TrainError> {
        Ok(AcacLane {
            recorder: EpisodeRecorder::new(env, self.c().gamma, false),
            states: self.zero_states(),
        })
    }

    fn begin_batch(&mut self, episodes: u64) {
        self.eps = self.c().epsilon_at(episodes);
        self.entropy_weight = self.c().entropy_weight_at(episodes);
    }

    fn act<E: MacroEnv>(&mut self, lane: &mut AcacLane, env: &E, actions: &mut [usize]) {
        Self::choose(
            &self.nets,
            env,
            lane.recorder.free(),
            &mut lane.states,
            Some(self.eps),
            &mut self.explore_rng,
            &mut self.probs,
            actions,
        );
    }

    fn record<E: MacroEnv>(
        &mut self,
        lane: &mut AcacLane,
        env: &E,
        outcome: StepOutcome,
    ) -> Result<bool, TrainError> {
        lane.recorder.record(env, outcome);
        if !outcome.done {
            return Ok(false);
        }
        self.means
            .record_return(lane.recorder.returns().undiscounted);
        self.pending_steps += lane.recorder.episode().steps as u64;
        self.memory.push_back(lane.recorder.episode().clone());
        while self.memory.len() > self.c().train_freq {
            self.memory.pop_front();
        }
        Ok(true)
    }

    fn begin_episode<E: MacroEnv>(&self, lane: &mut AcacLane, env: &E) -> Result<(), TrainError> {
        lane.recorder.begin(env);
        for s in &mut lane.states {
            s.reset();
        }
        Ok(())
    }

    fn train_iteration(&mut self, _lanes: &[&AcacLane], episodes: u64) -> Result<(), TrainError> {
        let trace = self.update_traced(episodes)?;
        let critic: Vec<f64> = trace.critic_losses.iter().map(|&l| f64::from(l)).collect();
        let actor: Vec<f64> = trace
            .actors
            .iter()
            .flatten()
            .map(|a| f64::from(a.loss))
            .collect();
        if self.means.record_update(&critic, &actor).is_err() {
            return Err(self.non_finite("loss", episodes));
        }
        if !self.nets.is_finite() {
            return Err(self.non_finite("parameter", episodes));
        }
        Ok(())
    }

    fn sync_targets(&mut self) {
        self.nets.sync_targets();
    }

    /// ACAC's evaluation (`envs_runner.run(test_mode=True)`): every lane reset and stepped in
    /// lockstep with macro-actions sampled from the plain actors until `eval_num_epi` episodes
    /// completed; the mean over every episode completed in that run (`Eval/Return`,
    /// `Eval/DiscReturn`: rewards averaged over agents, summed over primitive steps,
    /// undiscounted and discounted).
    fn evaluate_lanes<E: MacroEnv>(
        &self,
        envs: &mut [&mut E],
        rng: &mut EnvRng,
    ) -> Result<EvalReturns, EnvError> {
        let c = self.c();
        let mut probs = Vec::new();
        let returns = lockstep_episodes(
            envs,
            c.gamma,
            c.eval_num_epi,
            rng,
            || self.zero_states(),
            |env, free, states, rng, actions| {
                Self::choose(
                    &self.nets, env, free, states, None, rng, &mut probs, actions,
                )
            },
        )?;
        Ok(EvalReturns::mean(&returns))
    }

    /// One environment: the lockstep evaluation with a single lane.
    fn evaluate<E: MacroEnv>(
        &self,
        env: &mut E,
        rng: &mut EnvRng,
    ) -> Result<EvalReturns, EnvError> {
        self.evaluate_lanes(&mut [env], rng)
    }

    fn metric_columns(&self) -> &'static [&'static str] {
        &METRIC_COLUMNS
    }

    /// Called at each evaluation: ACAC adds the completed episodes' steps to its
    /// `total_timesteps` here (`log_diagnostics`).
    fn metric_values(&mut self) -> Vec<Option<f64>> {
        self.timesteps += self.pending_steps;
        self.pending_steps = 0;
        let [critic, actor, ret] = self.means.take_row();
        vec![
            Some(self.timesteps as f64),
            Some(self.eps),
            critic,
            actor,
            ret,
        ]
    }

    fn progress(&self) -> String {
        format!(
            "eps {:.3} steps {}/{}",
            self.eps,
            self.timesteps,
            self.budget_steps()
        )
    }

    /// Every agent's actor with the time table it reads: the policy its evaluations run (the
    /// critic only trains them).
    fn saved_nets(&self) -> SavedNets<'_> {
        let time = self.nets.time.as_ref();
        self.nets
            .actors
            .iter()
            .enumerate()
            .map(|(i, a)| SavedNet::agent(i, ActingNetRef::Acac(a, time), true))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::family::FamilyMethod;
    use crate::algos::training_loop::{Advance, TrainingLoop};
    use crate::envs::AnyEnv;
    use crate::experiment::run::train_run::run_rngs;
    use crate::nn::Params;

    fn short_run(method: AcacMethod, seed: u64) -> TrainingLoop<AcacLearner, AnyEnv> {
        let spec = crate::envs::bp_ma_v0::spec(6, 30);
        let mut c = method.defaults(&spec);
        (c.n_env, c.train_freq, c.c_target_update_freq) = (3, 2, 4);
        (c.eval_freq, c.eval_num_epi, c.total_epi) = (4, 2, 8);
        (c.a_mlp_layer_size, c.a_rnn_layer_size) = (vec![8, 8], 8);
        (c.c_mlp_layer_size, c.c_rnn_layer_size) = (vec![8, 8], 8);
        c.eps_stable_at = 10;
        TrainingLoop::new(&c, method, seed, run_rngs(seed), || spec.build()).unwrap()
    }

    fn finish(l: &mut TrainingLoop<AcacLearner, AnyEnv>) {
        while let Advance::Episode { .. } = l.advance().unwrap() {}
    }

    fn weights(l: &TrainingLoop<AcacLearner, AnyEnv>) -> Vec<Vec<f32>> {
        let n = l.learner().nets();
        let mut out: Vec<Vec<f32>> = n.actors.iter().map(|a| a.slices().concat()).collect();
        out.push(n.critic.slices().concat());
        out.push(n.critic_target.slices().concat());
        out
    }

    #[test]
    fn the_same_seed_and_a_checkpoint_halfway_give_the_same_numbers() {
        for &method in <AcacMethod as crate::algos::family::FamilyMethod>::ALL {
            let mut a = short_run(method, 3);
            finish(&mut a);
            assert!(a.updates() > 2, "{method:?}: {} updates", a.updates());
            let mut b = short_run(method, 3);
            for _ in 0..2 {
                b.advance().unwrap();
            }
            // Round-trip through bincode, as checkpoints are written.
            let bytes = bincode::serialize(&b).unwrap();
            let mut b: TrainingLoop<AcacLearner, AnyEnv> = bincode::deserialize(&bytes).unwrap();
            finish(&mut b);
            assert_eq!(a.evals().len(), b.evals().len(), "{method:?}");
            for (x, y) in a.evals().iter().zip(b.evals()) {
                assert_eq!(
                    (
                        x.eval_return,
                        x.eval_return_undiscounted,
                        &x.family,
                        x.env_steps
                    ),
                    (
                        y.eval_return,
                        y.eval_return_undiscounted,
                        &y.family,
                        y.env_steps
                    ),
                    "{method:?}"
                );
            }
            assert_eq!(weights(&a), weights(&b), "{method:?}");
            let mut c = short_run(method, 4);
            finish(&mut c);
            assert_ne!(weights(&a), weights(&c), "{method:?}: another seed");
        }
    }

    #[test]
    fn training_stops_at_acacs_primitive_step_budget_counted_at_evaluations() {
        let mut l = short_run(AcacMethod::Acac, 0);
        finish(&mut l);
        let budget = 30 * 8;
        let evals = l.evals();
        // Evaluations after every 4 episodes (eval_freq 4, train_freq 2), never at 0.
        let episodes: Vec<u64> = evals.iter().map(|e| e.episode).collect();
        let want: Vec<u64> = (1..=evals.len() as u64).map(|k| 4 * k).collect();
        assert_eq!(episodes, want);
        let steps: Vec<f64> = evals.iter().map(|e| e.family[0].unwrap()).collect();
        assert!(steps.windows(2).all(|w| w[0] < w[1]), "{steps:?}");
        // The last evaluation reached the budget; the one before did not.
        assert!(*steps.last().unwrap() >= budget as f64, "{steps:?}");
        assert!(steps[steps.len() - 2] < budget as f64, "{steps:?}");
        // Steps of completed episodes only: at most the loop's count of every lane step.
        assert!(evals
            .iter()
            .all(|e| e.family[0].unwrap() <= e.env_steps as f64));
        // Box Pushing's undiscounted return is at least its discounted one when positive.
        for e in evals {
            let u = e.eval_return_undiscounted.unwrap();
            assert!(u.is_finite() && e.eval_return.is_finite());
        }
    }
}
