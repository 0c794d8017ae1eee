//! MacroMARL's value-based team as the training loop drives it (`algs/value_based/mac_dec_q.py:
//! learn`, `mac_cen_q.py: learn`; `docs/MACROMARL.md` §8.2): every main-loop step (counted from 1)
//! steps each of the `n_env` lanes once; when the step is a multiple of `train_freq` and
//! `start_train` episodes are done, the hysteresis is set from the episodes since `start_train`,
//! `n_env` updates run, and then epsilon is set from the same count; targets are copied every
//! `target_update_freq` steps. One greedy episode is evaluated before training and whenever the
//! episode count reaches a multiple of `eval_freq`.

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::acting::{act_cen, act_dec, Explore};
use super::choice::Dims;
use super::config::MacValueConfig;
use super::episode::{Recorder, Step};
use super::memory::Memory;
use super::method::{MacValueMethod, QNets};
use super::update::{update_cen, update_dec, update_dec_cen, QNet, UpdateScratch};
use crate::algos::learner::{
    EvalReturns, LanePlan, Learner, LearnerRngs, MethodName, SavedNets, Schedule,
};
use crate::algos::scratch::Scratch;
use crate::algos::train_error::TrainError;
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};
use crate::nn::{GruActorConfig, GruActorState, Params};

/// The family's `metrics.csv` columns.
pub const METRIC_COLUMNS: [&str; 3] = ["epsilon", "hysteresis", "loss"];

/// One training lane: the runner's accumulators and the nets' recurrent states.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Lane {
    recorder: Recorder,
    states: Vec<GruActorState>,
    /// Parallel-MacDec-DDRQN's centralized lanes: the centralized net explores, the episodes go
    /// to its memory and do not count as training episodes.
    explores_centrally: bool,
}

/// A run's learner (any of the family's methods).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MacValueLearner {
    method: MacValueMethod,
    seed: u64,
    config: MacValueConfig,
    dims: Dims,
    /// One per agent (MacDec-Q) or the team's one (MacCen-Q).
    nets: Vec<QNet>,
    memory: Memory,
    /// Parallel-MacDec-DDRQN's second memory, filled by the centralized net's exploration.
    cen_memory: Option<Memory>,
    explore: ChaCha8Rng,
    replay: ChaCha8Rng,
    epsilon: f64,
    hysteresis: f64,
    loss_sum: f64,
    loss_count: u64,
    episodes: u64,
    /// The updates' tape and buffers.
    #[serde(skip, default)]
    scratch: Scratch<UpdateScratch>,
}

impl MacValueLearner {
    /// The Q-nets (one per agent, or the team's one).
    pub fn nets(&self) -> &[QNet] {
        &self.nets
    }

    /// The replay memory.
    pub fn memory(&self) -> &Memory {
        &self.memory
    }

    fn zero_states(&self) -> Vec<GruActorState> {
        self.nets.iter().map(|q| q.net.zero_state()).collect()
    }

    /// Pick the free agents' macro-actions from `states`, exploring with `explore`.
    fn choose<E: MacroEnv>(
        &self,
        states: &mut [GruActorState],
        env: &E,
        explore: Option<Explore<'_>>,
        actions: &mut [usize],
    ) {
        match self.method.nets() {
            QNets::Decentralized => act_dec(&self.nets, states, env, &self.dims, explore, actions),
            // The decentralized nets act (the reference's default, without `cen_explore`).
            QNets::DecWithCen => {
                let n = self.nets.len() - 1;
                act_dec(
                    &self.nets[..n],
                    &mut states[..n],
                    env,
                    &self.dims,
                    explore,
                    actions,
                )
            }
            QNets::Centralized => act_cen(
                &self.nets[0],
                &mut states[0],
                env,
                &self.dims,
                explore,
                actions,
            ),
        }
    }
}

impl Learner for MacValueLearner {
    type Lane = Lane;
    type Method = MacValueMethod;
    type Config = MacValueConfig;

    fn new<E: MacroEnv>(
        config: &MacValueConfig,
        method: MacValueMethod,
        seed: u64,
        env: &E,
        mut rngs: LearnerRngs,
    ) -> Result<Self, TrainError> {
        let dims = Dims {
            obs_sizes: env.obs_sizes().to_vec(),
            n_actions: env.n_actions().to_vec(),
        };
        let layers = |mlp: &[usize], hidden, input, output| GruActorConfig {
            input,
            mlp: [mlp[0], mlp[1]],
            hidden,
            output,
        };
        let joint_input = dims.obs_sizes.iter().sum();
        let (mlp, h) = (&config.mlp_layer_size, config.rnn_h_size);
        let (dec_mlp, dec_h) = (&config.dec_mlp_layer_size, config.dec_rnn_h_size);
        let agents = |mlp, h| -> Vec<GruActorConfig> {
            (0..env.n_agents())
                .map(|i| layers(mlp, h, dims.obs_sizes[i], dims.n_actions[i]))
                .collect()
        };
        let shapes = match method.nets() {
            QNets::Decentralized => agents(mlp, h),
            QNets::Centralized => vec![layers(mlp, h, joint_input, dims.n_joint())],
            // The agents' nets, then the centralized one (`create_agents`, then the controller).
            QNets::DecWithCen => {
                let mut s = agents(dec_mlp, dec_h);
                s.push(layers(
                    &config.cen_mlp_layer_size,
                    config.cen_rnn_h_size,
                    joint_input,
                    dims.n_joint(),
                ));
                s
            }
        };
        let nets = shapes
            .into_iter()
            .map(|cfg: GruActorConfig| QNet::new(cfg, config.l_rate, &mut rngs.init))
            .collect();
        Ok(MacValueLearner {
            method,
            seed,
            config: config.clone(),
            dims,
            nets,
            memory: Memory::new(
                config.sample_epi,
                config.trace_len,
                config.replay_buffer_size,
            ),
            cen_memory: method.parallel().then(|| {
                Memory::new(
                    config.sample_epi,
                    config.trace_len,
                    config.replay_buffer_size,
                )
            }),
            explore: rngs.explore,
            replay: rngs.replay,
            // `EPS_START`, and the hysteresis's initial value (`Team.__init__`).
            epsilon: 1.0,
            hysteresis: config.init_h,
            loss_sum: 0.0,
            loss_count: 0,
            episodes: 0,
            scratch: Scratch::default(),
        })
    }

    fn method(&self) -> MacValueMethod {
        self.method
    }

    fn seed(&self) -> u64 {
        self.seed
    }

    fn config(&self) -> &MacValueConfig {
        &self.config
    }

    fn schedule(&self) -> Schedule {
        Schedule::EveryStep {
            train_freq: self.config.train_freq as u64,
            start_train: self.config.start_train as u64,
            target_update_freq: self.config.target_update_freq as u64,
            eval_freq: self.config.eval_freq as u64,
            first_step: 1,
        }
    }

    fn lanes(&self) -> Vec<LanePlan> {
        // Parallel-MacDec-DDRQN: the agents' runner's environments step first, then the
        // centralized runner's (`Team_RNN.step`), whose episodes do not count.
        let n = self.config.n_env;
        let central = if self.method.parallel() { n } else { 0 };
        (0..n + central)
            .map(|k| LanePlan {
                counts_episodes: k < n,
            })
            .collect()
    }

    fn begin_lane<E: MacroEnv>(&self, lane: usize, env: &E) -> Result<Lane, TrainError> {
        Ok(Lane {
            recorder: Recorder::new(env, self.config.discount),
            states: self.zero_states(),
            explores_centrally: self.method.parallel() && lane >= self.config.n_env,
        })
    }

    fn act<E: MacroEnv>(&mut self, lane: &mut Lane, env: &E, actions: &mut [usize]) {
        if !self.config.h_explore {
            // The reference's runner keeps the reset state (None) for every decision.
            lane.states.iter_mut().for_each(GruActorState::reset);
        }
        let mut rng = std::mem::replace(&mut self.explore, rand::SeedableRng::seed_from_u64(0));
        let explore = Explore {
            epsilon: self.epsilon,
            rng: &mut rng,
        };
        if lane.explores_centrally {
            let cen = self.nets.len() - 1;
            let q = &self.nets[cen];
            act_cen(
                q,
                &mut lane.states[cen],
                env,
                &self.dims,
                Some(explore),
                actions,
            );
        } else {
            self.choose(&mut lane.states, env, Some(explore), actions);
        }
        self.explore = rng;
    }

    fn record<E: MacroEnv>(
        &mut self,
        lane: &mut Lane,
        env: &E,
        outcome: StepOutcome,
    ) -> Result<bool, TrainError> {
        match lane.recorder.record(env, outcome) {
            Some(episode) => {
                match (&mut self.cen_memory, lane.explores_centrally) {
                    (Some(cen_memory), true) => cen_memory.push(episode),
                    _ => {
                        self.memory.push(episode);
                        self.episodes += 1;
                    }
                }
                Ok(true)
            }
            None => Ok(false),
        }
    }

    fn begin_episode<E: MacroEnv>(&self, lane: &mut Lane, env: &E) -> Result<(), TrainError> {
        lane.recorder = Recorder::new(env, self.config.discount);
        lane.states.iter_mut().for_each(GruActorState::reset);
        Ok(())
    }

    fn train_iteration(&mut self, _lanes: &[&Lane], episodes: u64) -> Result<(), TrainError> {
        let c = &self.config;
        let since = episodes.saturating_sub(c.start_train as u64);
        self.hysteresis = c.hysteresis_at(since, self.epsilon);
        let sampling = |e| TrainError::Family(Box::new(e));
        for _ in 0..c.n_env {
            // Parallel-MacDec-DDRQN samples the centralized memory first (`Team_RNN.train`).
            let cen_batch = match &self.cen_memory {
                Some(m) => Some(m.sample(c.batch_size, &mut self.replay).map_err(sampling)?),
                None => None,
            };
            let picks = self
                .memory
                .sample_indices(c.batch_size, &mut self.replay)
                .map_err(sampling)?;
            let batch: Vec<&[Step]> = picks.iter().map(|&i| self.memory.entry(i)).collect();
            let ids = self.memory.episode_ids(&picks, self.episodes);
            if ids.is_some() {
                // A whole-episode memory keeps the last `len` of the episodes stored.
                let oldest = self.episodes - self.memory.len() as u64;
                self.scratch.0.forget_episodes_before(oldest);
            }
            let losses: Vec<f32> = match self.method.nets() {
                QNets::Decentralized => update_dec(
                    &mut self.nets,
                    &batch,
                    ids.as_deref(),
                    &self.dims,
                    self.hysteresis,
                    c.discount,
                    c.sub_trace_len,
                    &mut self.scratch.0,
                )
                .map(|t| t.iter().map(|t| t.loss).collect())
                .unwrap_or_default(),
                QNets::Centralized => update_cen(
                    &mut self.nets[0],
                    &batch,
                    ids.as_deref(),
                    &self.dims,
                    self.hysteresis,
                    c.discount,
                    c.sub_trace_len,
                    &mut self.scratch.0,
                )
                .map(|t| vec![t.loss])
                .unwrap_or_default(),
                QNets::DecWithCen => {
                    let n_dec = self.nets.len() - 1;
                    let (decs, cen) = self.nets.split_at_mut(n_dec);
                    update_dec_cen(
                        &mut cen[0],
                        decs,
                        cen_batch.as_deref().unwrap_or(&batch),
                        &batch,
                        &self.dims,
                        self.hysteresis,
                        c.discount,
                        c.sub_trace_len,
                        &mut self.scratch.0,
                    )
                    .map(|(cen, decs)| {
                        std::iter::once(cen.loss)
                            .chain(decs.iter().map(|t| t.loss))
                            .collect()
                    })
                    .unwrap_or_default()
                }
            };
            for loss in losses {
                if !loss.is_finite() {
                    return Err(TrainError::NonFinite {
                        method: self.method.name(),
                        seed: self.seed,
                        what: "loss",
                        episode: episodes,
                    });
                }
                self.loss_sum += f64::from(loss);
                self.loss_count += 1;
            }
        }
        self.epsilon = c.epsilon_at(since);
        Ok(())
    }

    fn sync_targets(&mut self) {
        for q in &mut self.nets {
            q.target.copy_values_from(&q.net);
        }
        self.scratch.0.targets_changed();
    }

    /// One greedy episode (`evaluate(n_episode=1)`), the nets' states carried through it; the
    /// return is the sum of discount^t x the agents' mean reward.
    fn evaluate<E: MacroEnv>(
        &self,
        env: &mut E,
        rng: &mut EnvRng,
    ) -> Result<EvalReturns, EnvError> {
        env.reset(rng);
        let mut states = self.zero_states();
        let mut actions = vec![0; env.n_agents()];
        let (mut discounted, mut undiscounted, mut scale) = (0.0, 0.0, 1.0);
        loop {
            self.choose(&mut states, env, None, &mut actions);
            let outcome = env.step(&actions, rng)?;
            discounted += scale * outcome.reward;
            undiscounted += outcome.reward;
            scale *= self.config.discount;
            if outcome.done {
                return Ok(EvalReturns {
                    discounted,
                    undiscounted,
                });
            }
        }
    }

    fn metric_columns(&self) -> &'static [&'static str] {
        &METRIC_COLUMNS
    }

    fn metric_values(&mut self) -> Vec<Option<f64>> {
        let loss = (self.loss_count > 0).then(|| self.loss_sum / self.loss_count as f64);
        self.loss_sum = 0.0;
        self.loss_count = 0;
        vec![Some(self.epsilon), Some(self.hysteresis), loss]
    }

    fn progress(&self) -> String {
        format!("eps {:.3} h {:.3}", self.epsilon, self.hysteresis)
    }

    fn saved_nets(&self) -> SavedNets<'_> {
        use crate::nn::ActingNetRef;
        use crate::policy_files::SavedNet;
        // The policy files' net kinds are Q-nets (the ICRA LSTM) and actors (MacroMARL's GRU
        // layers); these Q-nets have the actor's layers, so they are saved as that kind: the
        // greedy macro-action (argmax of the scores) is the same, log_softmax being monotonic.
        let n_dec = match self.method.nets() {
            QNets::Decentralized => self.nets.len(),
            QNets::Centralized => 0,
            QNets::DecWithCen => self.nets.len() - 1,
        };
        let central = self.method.nets() == QNets::Centralized;
        self.nets
            .iter()
            .enumerate()
            .map(|(i, q)| {
                let net = ActingNetRef::Actor(&q.net);
                if i < n_dec {
                    SavedNet::agent(i, net, true)
                } else {
                    // MacCen-Q acts with it; MacDec-DDRQN's centralized net only trains.
                    SavedNet::team(net, central)
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::family::FamilyMethod;
    use crate::algos::training_loop::{Advance, TrainingLoop};
    use crate::experiment::run::train_run::run_rngs;

    /// A few episodes of Box Pushing 8x8 (horizon 30) with updates from the third episode on.
    fn short_run(
        method: MacValueMethod,
        seed: u64,
    ) -> TrainingLoop<MacValueLearner, crate::envs::AnyEnv> {
        let spec = crate::envs::bp_ma_v0::spec(8, 30);
        let mut c = method.defaults(&spec);
        (c.total_epi, c.start_train, c.eval_freq) = (6, 2, 2);
        (c.batch_size, c.train_freq, c.target_update_freq) = (4, 5, 20);
        (c.mlp_layer_size, c.rnn_h_size) = (vec![8, 8], 8);
        (c.init_h, c.end_h, c.h_stable_at) = (0.2, 0.4, 4);
        TrainingLoop::new(&c, method, seed, run_rngs(seed), || spec.build()).unwrap()
    }

    fn finish(l: &mut TrainingLoop<MacValueLearner, crate::envs::AnyEnv>) {
        while let Advance::Episode { .. } = l.advance().unwrap() {}
    }

    fn weights(l: &TrainingLoop<MacValueLearner, crate::envs::AnyEnv>) -> Vec<Vec<f32>> {
        l.learner()
            .nets()
            .iter()
            .flat_map(|q| [&q.net, &q.target])
            .map(|n| n.slices().concat())
            .collect()
    }

    #[test]
    fn every_method_trains_the_same_numbers_from_the_same_seed_and_from_a_checkpoint() {
        for &method in MacValueMethod::ALL {
            let mut a = short_run(method, 3);
            finish(&mut a);
            assert!(a.updates() > 0, "{method:?} never updated");
            let mut b = short_run(method, 3);
            // Stop halfway, round-trip through a checkpoint's serialization, finish.
            for _ in 0..3 {
                b.advance().unwrap();
            }
            let json = serde_json::to_string(&b).unwrap();
            let mut b: TrainingLoop<MacValueLearner, crate::envs::AnyEnv> =
                serde_json::from_str(&json).unwrap();
            finish(&mut b);
            assert_eq!(a.evals().len(), b.evals().len(), "{method:?}");
            for (x, y) in a.evals().iter().zip(b.evals()) {
                assert_eq!(
                    (x.eval_return, &x.family, x.env_steps, x.updates),
                    (y.eval_return, &y.family, y.env_steps, y.updates),
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
    fn epsilon_stays_at_one_until_the_first_update_and_hysteresis_rises_after_start_train() {
        let mut l = short_run(MacValueMethod::MacDecQ, 0);
        finish(&mut l);
        let first = &l.evals()[0];
        assert_eq!(first.family[0], Some(1.0));
        // After the last update, epsilon is the linear decay at episodes - start_train.
        let last = l.evals().last().unwrap();
        let c = l.config();
        let eps = last.family[0].unwrap();
        assert!(eps < 1.0 && eps >= c.eps_end, "{eps}");
        let h = last.family[1].unwrap();
        assert!(h > c.init_h && h <= c.end_h, "{h}");
    }

    #[test]
    fn parallel_runs_count_only_the_agents_episodes_and_fill_both_memories() {
        let mut l = short_run(MacValueMethod::ParallelMacDecDdrqn, 1);
        finish(&mut l);
        let learner = l.learner();
        assert_eq!(learner.episodes, 6);
        let cen = learner.cen_memory.as_ref().unwrap();
        assert!(!cen.is_empty() && !learner.memory().is_empty());
        // Two lanes stepped in lockstep: twice the primitive steps of the main loop.
        assert_eq!(l.env_steps() % 2, 0);
    }
}
