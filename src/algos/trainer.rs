//! The training loop shared by all five methods (spec `algorithms.md` 6): act, record, replay,
//! train every `train_freq` steps, copy targets every `target_update_freq` steps, evaluate every
//! `eval_freq` episodes.
//!
//! The whole trainer is one serializable value, so a checkpoint is the trainer itself and a
//! resumed run continues with exactly the numbers of an uninterrupted one.

use crate::algos::acting::{select_cen, select_dec, ActScratch, Explore};
use crate::algos::evaluate::{evaluate, GreedyPolicy};
use crate::algos::hyper::RunConfig;
use crate::algos::method::{EvaluatedPolicy, Exploration, HysteresisRule, Method};
use crate::algos::record::Layout;
use crate::algos::recorder::Recorder;
use crate::algos::replay::ReplayBuffer;
use crate::algos::schedule::EpsilonSchedule;
use crate::algos::update::{train_iteration, IterationParams, Nets, UpdateError};
use crate::algos::ReplayError;
use crate::envs::{AnyEnv, EnvError, EnvRng, MacroEnv};
use crate::nn::{LstmState, QNet, QNetConfig};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Independent random streams of one run (one per role, spec 8).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunRngs {
    pub init: ChaCha8Rng,
    pub explore: ChaCha8Rng,
    pub replay: ChaCha8Rng,
    pub env: EnvRng,
    pub cen_env: EnvRng,
    pub eval_env: EnvRng,
}

/// Why training stopped early.
#[derive(Debug, thiserror::Error)]
pub enum TrainError {
    #[error(transparent)]
    Env(#[from] EnvError),
    #[error(transparent)]
    Replay(#[from] ReplayError),
    #[error(transparent)]
    Update(#[from] UpdateError),
    #[error("{method} seed {seed}: non-finite {what} at episode {episode}")]
    NonFinite {
        method: Method,
        seed: u64,
        what: &'static str,
        episode: u64,
    },
}

/// One training environment with everything needed to act in it and record from it.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Lane<E> {
    env: E,
    rng: EnvRng,
    exploration: Exploration,
    recorder: Recorder,
    buffer: ReplayBuffer,
    dec_states: Vec<LstmState>,
    cen_state: Option<LstmState>,
    actions: Vec<usize>,
    /// Quirk Q12: Our-1 / Our-1-R under centralized exploration still run the decentralized
    /// selection each step (hidden states advance, draws are consumed) and discard its actions.
    shadow_dec_selection: bool,
    discarded: Vec<usize>,
    #[serde(skip, default)]
    scratch: Option<ActScratch>,
}

/// One evaluation point, as the metrics file records it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EvalPoint {
    pub episode: u64,
    pub env_steps: u64,
    pub updates: u64,
    pub eval_return: f64,
    pub epsilon: f64,
    pub hysteresis: f64,
    pub loss: Option<f64>,
    /// Wall-clock seconds since the run started, over all resumed segments (not reproducible).
    pub wall_seconds: f64,
}

/// What [`Trainer::advance`] stopped at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Advance {
    /// A training episode finished; `checkpoint_due` when the episode count hits checkpoint_freq.
    Episode { checkpoint_due: bool },
    /// `total_epi` episodes are done.
    Finished,
}

/// The complete state of a training run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Trainer<E = AnyEnv> {
    config: RunConfig,
    method: Method,
    seed: u64,
    layout: Layout,
    dec: Vec<Nets>,
    cen: Option<Nets>,
    /// The training env; Our-2's decentralized-exploring env.
    lane: Lane<E>,
    /// Our-2's centralized-exploring env.
    cen_lane: Option<Lane<E>>,
    eval_env: E,
    rngs: RunRngs,
    epsilon: f64,
    h: f64,
    episodes: u64,
    step: u64,
    env_steps: u64,
    updates: u64,
    evaluated_once: bool,
    loss_sum: f64,
    loss_count: u64,
    evals: Vec<EvalPoint>,
    /// Wall-clock seconds of earlier segments of this run (before the last resume).
    elapsed_before: f64,
    #[serde(skip, default)]
    segment_start: Option<std::time::Instant>,
}

impl Trainer<AnyEnv> {
    /// Build nets, envs and buffers for `method` with seed `seed` (spec 2.2, 6) on the domain
    /// the config names ([`RunConfig::env`]).
    pub fn new(
        config: RunConfig,
        method: Method,
        seed: u64,
        rngs: RunRngs,
    ) -> Result<Self, TrainError> {
        let spec = config.env;
        Self::with_env(config, method, seed, rngs, || spec.build())
    }
}

impl<E: MacroEnv> Trainer<E> {
    /// Build nets, envs and buffers for `method` with seed `seed` (spec 2.2, 6) on the domain
    /// `make_env` builds, called once per environment the method needs (evaluation, training,
    /// Our-2's centralized lane). What the learner needs to know about the domain comes from
    /// its [`MacroEnv`] implementation; the config's `env` is not read here.
    pub fn with_env(
        config: RunConfig,
        method: Method,
        seed: u64,
        mut rngs: RunRngs,
        make_env: impl Fn() -> Result<E, EnvError>,
    ) -> Result<Self, TrainError> {
        let eval_env = make_env()?;
        let horizon = eval_env.horizon();
        let layout = Layout::of_env(&eval_env)?;
        let dec: Vec<Nets> = if method.has_dec_nets() {
            (0..layout.n_agents())
                .map(|i| {
                    let cfg = QNetConfig {
                        input: layout.obs_sizes()[i],
                        mlp: config.dec_mlp_layer_size,
                        hidden: config.dec_rnn_h_size,
                        output: layout.n_actions()[i],
                    };
                    Nets::new(QNet::new(cfg, &mut rngs.init), config.l_rate)
                })
                .collect()
        } else {
            Vec::new()
        };
        let cen = method.has_cen_net().then(|| {
            let cfg = QNetConfig {
                input: layout.joint_obs_size(),
                mlp: config.cen_mlp_layer_size,
                hidden: config.cen_rnn_h_size,
                output: layout.n_joint_actions(),
            };
            Nets::new(QNet::new(cfg, &mut rngs.init), config.l_rate)
        });
        let exploration = method.exploration(config.cen_explore);
        let (main_exploration, cen_lane_exploration) = match exploration {
            Exploration::Parallel => (Exploration::Decentralized, Some(Exploration::Centralized)),
            e => (e, None),
        };
        let make_lane =
            |exploration: Exploration, mut rng: EnvRng| -> Result<Lane<E>, TrainError> {
                let mut env = make_env()?;
                env.reset(&mut rng);
                let mut recorder = Recorder::new(&layout, env.first_record_obs(), horizon);
                recorder.begin_from_env(&env)?;
                let buffer = if config.sample_epi {
                    ReplayBuffer::episodes(&layout, config.replay_buffer_size)?
                } else {
                    ReplayBuffer::windows(&layout, config.replay_buffer_size, config.trace_len)?
                };
                Ok(Lane {
                    dec_states: dec_zero_states(&dec),
                    cen_state: cen.as_ref().map(|c| c.policy.zero_state()),
                    actions: vec![0; layout.n_agents()],
                    shadow_dec_selection: method.shadow_dec_selection(exploration),
                    discarded: vec![0; layout.n_agents()],
                    scratch: None,
                    env,
                    rng,
                    exploration,
                    recorder,
                    buffer,
                })
            };
        let lane = make_lane(main_exploration, rngs.env.clone())?;
        let cen_lane = cen_lane_exploration
            .map(|e| make_lane(e, rngs.cen_env.clone()))
            .transpose()?;
        let h = hysteresis_rule(&config).initial();
        Ok(Trainer {
            config,
            method,
            seed,
            layout,
            dec,
            cen,
            lane,
            cen_lane,
            eval_env,
            rngs,
            epsilon: 1.0,
            h,
            episodes: 0,
            step: 0,
            env_steps: 0,
            updates: 0,
            evaluated_once: false,
            loss_sum: 0.0,
            loss_count: 0,
            evals: Vec::new(),
            elapsed_before: 0.0,
            segment_start: None,
        })
    }

    /// The run's configuration.
    pub fn config(&self) -> &RunConfig {
        &self.config
    }

    /// The method being trained.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The run's seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The policy the paper evaluates for this method (spec 7.1): the decentralized nets, or the
    /// centralized net for Cen-DDRQN. `dec` must be [`Self::dec_policies`].
    pub fn greedy_policy<'a>(&'a self, dec: &'a [&'a QNet]) -> GreedyPolicy<'a> {
        policy_of(self.method, dec, self.cen.as_ref())
    }

    /// Completed training episodes.
    pub fn episodes(&self) -> u64 {
        self.episodes
    }

    /// Primitive steps taken by the training env(s).
    pub fn env_steps(&self) -> u64 {
        self.env_steps
    }

    /// Training iterations run.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// Every evaluation so far, in order.
    pub fn evals(&self) -> &[EvalPoint] {
        &self.evals
    }

    /// The current exploration rate.
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// The trained decentralized policy nets (empty for Cen-DDRQN).
    pub fn dec_policies(&self) -> Vec<&QNet> {
        self.dec.iter().map(|n| &n.policy).collect()
    }

    /// The trained centralized policy net, if the method has one.
    pub fn cen_policy(&self) -> Option<&QNet> {
        self.cen.as_ref().map(|n| &n.policy)
    }

    /// Wall-clock seconds this run has trained, over all segments.
    pub fn wall_seconds(&self) -> f64 {
        self.elapsed_before
            + self
                .segment_start
                .map_or(0.0, |t| t.elapsed().as_secs_f64())
    }

    /// Fold the running segment's time into the saved total (call before checkpointing).
    pub fn mark_time(&mut self) {
        self.elapsed_before = self.wall_seconds();
        self.segment_start = Some(std::time::Instant::now());
    }

    /// Whether training is complete.
    pub fn is_finished(&self) -> bool {
        self.episodes >= self.config.total_epi as u64
    }

    /// Run main-loop iterations until a training episode finishes or training is complete.
    pub fn advance(&mut self) -> Result<Advance, TrainError> {
        self.segment_start
            .get_or_insert_with(std::time::Instant::now);
        loop {
            if self.is_finished() {
                return Ok(Advance::Finished);
            }
            let finished = self.main_loop_iteration()?;
            if finished {
                let due = self
                    .episodes
                    .is_multiple_of(self.config.checkpoint_freq as u64);
                return Ok(Advance::Episode {
                    checkpoint_due: due,
                });
            }
        }
    }

    /// One main-loop iteration (spec 6). Returns whether a training episode finished.
    fn main_loop_iteration(&mut self) -> Result<bool, TrainError> {
        if !self.evaluated_once {
            self.evaluated_once = true;
            self.evaluate()?;
        }
        // Our-2: the dec env steps first, then the cen env (spec 4.6).
        let finished = self.step_lane(false)?;
        if self.cen_lane.is_some() {
            self.step_lane(true)?;
        }
        if finished {
            self.episodes += 1;
            if self.episodes.is_multiple_of(self.config.eval_freq as u64) {
                self.evaluate()?;
            }
        }
        let c = self.config.clone();
        if self.step.is_multiple_of(c.train_freq as u64) && self.episodes >= c.start_train as u64 {
            let e = self.episodes as f64;
            self.h = hysteresis_rule(&c).at(e, self.epsilon);
            self.train()?;
            self.epsilon = if c.eps_l_d {
                EpsilonSchedule::new(c.eps_end, c.eps_l_d_steps as f64)
                    .map(|s| s.at(e))
                    .unwrap_or(c.eps_end)
            } else {
                // The reference's exponential schedule (spec 4.1), unused by the paper's runs.
                c.eps_end + (1.0 - c.eps_end) * (-((e / 8.0).floor()) / 2000.0).exp()
            };
        }
        if self
            .step
            .is_multiple_of(self.config.target_update_freq as u64)
        {
            for n in self.dec.iter_mut().chain(self.cen.as_mut()) {
                n.sync_target();
            }
        }
        self.step += 1;
        Ok(finished)
    }

    /// One primitive step of a training lane with its exploration; a finished episode goes to
    /// that lane's buffer and the env resets. Returns whether the episode finished.
    fn step_lane(&mut self, cen_lane: bool) -> Result<bool, TrainError> {
        let lane = if cen_lane {
            self.cen_lane
                .as_mut()
                .expect("Our-2 has a centralized lane")
        } else {
            &mut self.lane
        };
        let scratch = lane
            .scratch
            .get_or_insert_with(|| ActScratch::new(&lane.env));
        let dec_nets: Vec<&QNet> = self.dec.iter().map(|n| &n.policy).collect();
        let carry = self.config.h_explore;
        let explore_dec = lane.exploration == Exploration::Decentralized;
        if explore_dec || lane.shadow_dec_selection {
            let explore = Explore {
                rng: &mut self.rngs.explore,
                epsilon: self.epsilon,
                carry_state: carry,
            };
            let out = if explore_dec {
                &mut lane.actions
            } else {
                &mut lane.discarded
            };
            select_dec(
                &lane.env,
                &dec_nets,
                &mut lane.dec_states,
                Some(explore),
                out,
            );
        }
        if lane.exploration == Exploration::Centralized {
            let cen = &self
                .cen
                .as_ref()
                .expect("centralized exploration needs the centralized net")
                .policy;
            let explore = Explore {
                rng: &mut self.rngs.explore,
                epsilon: self.epsilon,
                carry_state: carry,
            };
            let state = lane
                .cen_state
                .as_mut()
                .expect("a centralized net has a state");
            select_cen(
                &lane.env,
                cen,
                state,
                Some(explore),
                scratch,
                &mut lane.actions,
            );
        }
        let outcome = lane.env.step(&lane.actions, &mut lane.rng)?;
        self.env_steps += 1;
        let episode = lane.recorder.record_from_env(&lane.env, outcome)?;
        let Some(episode) = episode else {
            return Ok(false);
        };
        lane.buffer.push(episode)?;
        lane.env.reset(&mut lane.rng);
        lane.recorder.begin_from_env(&lane.env)?;
        for s in lane.dec_states.iter_mut() {
            s.reset();
        }
        if let Some(s) = lane.cen_state.as_mut() {
            s.reset();
        }
        Ok(!cen_lane)
    }

    /// One training iteration on batches from the buffer(s).
    fn train(&mut self) -> Result<(), TrainError> {
        let c = &self.config;
        let params = IterationParams {
            method: self.method,
            discount: c.discount as f32,
            h: self.h as f32,
            early_return_skips_all: c.early_return_skips_all,
            sub_trace_len: c.sub_trace_len,
        };
        let dec_batch = self
            .lane
            .buffer
            .sample(c.batch_size, &mut self.rngs.replay)?;
        let cen_batch = match &self.cen_lane {
            Some(l) => Some(l.buffer.sample(c.batch_size, &mut self.rngs.replay)?),
            None => None,
        };
        let loss = train_iteration(
            params,
            &self.layout,
            &mut self.dec,
            self.cen.as_mut(),
            &dec_batch,
            cen_batch.as_ref().unwrap_or(&dec_batch),
        )?;
        self.updates += 1;
        if !loss.total.is_finite() {
            return Err(self.non_finite("loss"));
        }
        if self
            .dec
            .iter()
            .chain(self.cen.as_ref())
            .any(|n| !n.is_finite())
        {
            return Err(self.non_finite("parameter"));
        }
        if loss.steps > 0 {
            self.loss_sum += loss.total;
            self.loss_count += 1;
        }
        Ok(())
    }

    fn non_finite(&self, what: &'static str) -> TrainError {
        TrainError::NonFinite {
            method: self.method,
            seed: self.seed,
            what,
            episode: self.episodes,
        }
    }

    /// Greedy evaluation (spec 7.1), appended to the curve.
    fn evaluate(&mut self) -> Result<(), TrainError> {
        let c = &self.config;
        let dec: Vec<&QNet> = self.dec.iter().map(|n| &n.policy).collect();
        let policy = policy_of(self.method, &dec, self.cen.as_ref());
        let deterministic = self.eval_env.deterministic();
        let eval_return = evaluate(
            &mut self.eval_env,
            policy,
            c.discount,
            c.eval_num_epi,
            deterministic,
            &mut self.rngs.eval_env,
        )?;
        let loss = (self.loss_count > 0).then(|| self.loss_sum / self.loss_count as f64);
        self.loss_sum = 0.0;
        self.loss_count = 0;
        self.evals.push(EvalPoint {
            episode: self.episodes,
            env_steps: self.env_steps,
            updates: self.updates,
            eval_return,
            epsilon: self.epsilon,
            hysteresis: self.h,
            loss,
            wall_seconds: self.wall_seconds(),
        });
        Ok(())
    }
}

/// The evaluated policy of `method` (spec 7.1): Cen-DDRQN acts centrally, all others by agent.
fn policy_of<'a>(method: Method, dec: &'a [&'a QNet], cen: Option<&'a Nets>) -> GreedyPolicy<'a> {
    match method.evaluated_policy() {
        EvaluatedPolicy::Centralized => GreedyPolicy::Cen(
            &cen.expect("a centrally evaluated method has a centralized net")
                .policy,
        ),
        EvaluatedPolicy::Decentralized => GreedyPolicy::Dec(dec),
    }
}

/// The hysteresis settings of a config.
fn hysteresis_rule(c: &RunConfig) -> HysteresisRule {
    HysteresisRule {
        dynamic: c.dynamic_h,
        init_h: c.init_h,
        end_h: c.end_h,
        h_stable_at: c.h_stable_at as f64,
    }
}

fn dec_zero_states(dec: &[Nets]) -> Vec<LstmState> {
    dec.iter().map(|n| n.policy.zero_state()).collect()
}
