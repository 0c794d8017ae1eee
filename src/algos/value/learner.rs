//! The value-based family as the training loop drives it: the five ICRA methods' nets,
//! exploration, replay, training iteration and evaluated policy (`docs/ALGORITHMS.md` §4-7).
//! Where the methods differ, [`ValueMethod`]'s exhaustive `match`es decide.

use crate::algos::learner::{
    EvalReturns, LanePlan, Learner, LearnerRngs, MethodName, SavedNets, Schedule,
};
use crate::algos::training_loop::TrainError;
use crate::algos::value::acting::{select_cen, select_dec, ActScratch, Explore};
use crate::algos::value::config::ValueConfig;
use crate::algos::value::evaluate::{evaluate, GreedyPolicy};
use crate::algos::value::method::{EvaluatedPolicy, Exploration, HysteresisRule, ValueMethod};
use crate::algos::value::record::Layout;
use crate::algos::value::recorder::Recorder;
use crate::algos::value::replay::ReplayBuffer;
use crate::algos::value::schedule::EpsilonSchedule;
use crate::algos::value::update::{train_iteration, IterationParams, Nets};
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};
use crate::nn::{LstmState, QNet, QNetConfig};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// The value family's `metrics.csv` columns: the exploration rate and hysteresis value at the
/// evaluation, and the mean total TD loss over the iterations since the previous row (empty
/// before the first).
pub const METRIC_COLUMNS: [&str; 3] = ["epsilon", "hysteresis", "loss"];

/// One training lane's learner state: how it explores, the episode being recorded, its replay
/// and the exploring nets' hidden states.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ValueLane {
    exploration: Exploration,
    recorder: Recorder,
    buffer: ReplayBuffer,
    dec_states: Vec<LstmState>,
    cen_state: Option<LstmState>,
    /// Quirk Q12: Our-1 / Our-1-R under centralized exploration still run the decentralized
    /// selection each step (hidden states advance, draws are consumed) and discard its actions.
    shadow_dec_selection: bool,
    discarded: Vec<usize>,
    #[serde(skip, default)]
    scratch: Option<ActScratch>,
}

/// The nets, schedules and learner-side random streams of a value-based run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ValueLearner {
    config: ValueConfig,
    method: ValueMethod,
    seed: u64,
    layout: Layout,
    /// The horizon, for sizing each lane's recorder.
    horizon: usize,
    /// Whether a greedy episode always gives the same return (one evaluation episode suffices).
    deterministic: bool,
    dec: Vec<Nets>,
    cen: Option<Nets>,
    explore_rng: ChaCha8Rng,
    replay_rng: ChaCha8Rng,
    epsilon: f64,
    h: f64,
    loss_sum: f64,
    loss_count: u64,
}

impl ValueLearner {
    /// The run's keys.
    fn c(&self) -> &ValueConfig {
        &self.config
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

    /// The lanes' explorations: the method's, with Our-2's parallel exploration split into a
    /// decentralized lane and a centralized one (`docs/ALGORITHMS.md` §4.6, 5.5).
    fn lane_explorations(&self) -> Vec<Exploration> {
        match self.method.exploration(self.c().cen_explore) {
            Exploration::Parallel => vec![Exploration::Decentralized, Exploration::Centralized],
            e => vec![e],
        }
    }

    fn non_finite(&self, what: &'static str, episodes: u64) -> TrainError {
        TrainError::non_finite(self.method.name(), self.seed, what, episodes)
    }
}

impl Learner for ValueLearner {
    type Lane = ValueLane;
    type Method = ValueMethod;
    type Config = ValueConfig;

    fn new<E: MacroEnv>(
        config: &ValueConfig,
        method: ValueMethod,
        seed: u64,
        env: &E,
        mut rngs: LearnerRngs,
    ) -> Result<Self, TrainError> {
        let layout = Layout::of_env(env)?;
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
        Ok(ValueLearner {
            h: hysteresis_rule(config).initial(),
            config: config.clone(),
            method,
            seed,
            layout,
            horizon: env.horizon(),
            deterministic: env.deterministic(),
            dec,
            cen,
            explore_rng: rngs.explore,
            replay_rng: rngs.replay,
            epsilon: 1.0,
            loss_sum: 0.0,
            loss_count: 0,
        })
    }

    fn method(&self) -> ValueMethod {
        self.method
    }

    fn seed(&self) -> u64 {
        self.seed
    }

    fn config(&self) -> &ValueConfig {
        &self.config
    }

    fn schedule(&self) -> Schedule {
        Schedule::EveryStep {
            train_freq: self.c().train_freq as u64,
            start_train: self.c().start_train as u64,
            target_update_freq: self.c().target_update_freq as u64,
            eval_freq: self.c().eval_freq as u64,
            first_step: 0,
        }
    }

    fn lanes(&self) -> Vec<LanePlan> {
        // Our-2's centralized lane (the second) does not count training episodes.
        (0..self.lane_explorations().len())
            .map(|i| LanePlan {
                counts_episodes: i == 0,
            })
            .collect()
    }

    fn begin_lane<E: MacroEnv>(&self, lane: usize, env: &E) -> Result<ValueLane, TrainError> {
        let exploration = self.lane_explorations()[lane];
        let c = self.c();
        let mut recorder = Recorder::new(&self.layout, env.first_record_obs(), self.horizon);
        recorder.begin_from_env(env)?;
        let buffer = if c.sample_epi {
            ReplayBuffer::episodes(&self.layout, c.replay_buffer_size)?
        } else {
            ReplayBuffer::windows(&self.layout, c.replay_buffer_size, c.trace_len)?
        };
        Ok(ValueLane {
            exploration,
            recorder,
            buffer,
            dec_states: self.dec.iter().map(|n| n.policy.zero_state()).collect(),
            cen_state: self.cen.as_ref().map(|c| c.policy.zero_state()),
            shadow_dec_selection: self.method.shadow_dec_selection(exploration),
            discarded: vec![0; self.layout.n_agents()],
            scratch: None,
        })
    }

    fn act<E: MacroEnv>(&mut self, lane: &mut ValueLane, env: &E, actions: &mut [usize]) {
        let scratch = lane.scratch.get_or_insert_with(|| ActScratch::new(env));
        let carry = self.c().h_explore;
        let explore_dec = lane.exploration == Exploration::Decentralized;
        if explore_dec || lane.shadow_dec_selection {
            let dec_nets: Vec<&QNet> = self.dec.iter().map(|n| &n.policy).collect();
            let explore = Explore {
                rng: &mut self.explore_rng,
                epsilon: self.epsilon,
                carry_state: carry,
            };
            let out = if explore_dec {
                &mut *actions
            } else {
                &mut lane.discarded
            };
            select_dec(env, &dec_nets, &mut lane.dec_states, Some(explore), out);
        }
        if lane.exploration == Exploration::Centralized {
            let cen = &self
                .cen
                .as_ref()
                .expect("centralized exploration needs the centralized net")
                .policy;
            let explore = Explore {
                rng: &mut self.explore_rng,
                epsilon: self.epsilon,
                carry_state: carry,
            };
            let state = lane
                .cen_state
                .as_mut()
                .expect("a centralized net has a state");
            select_cen(env, cen, state, Some(explore), scratch, actions);
        }
    }

    fn record<E: MacroEnv>(
        &mut self,
        lane: &mut ValueLane,
        env: &E,
        outcome: StepOutcome,
    ) -> Result<bool, TrainError> {
        match lane.recorder.record_from_env(env, outcome)? {
            Some(episode) => {
                lane.buffer.push(episode)?;
                Ok(true)
            }
            None => Ok(false),
        }
    }

    fn begin_episode<E: MacroEnv>(&self, lane: &mut ValueLane, env: &E) -> Result<(), TrainError> {
        lane.recorder.begin_from_env(env)?;
        for s in lane.dec_states.iter_mut() {
            s.reset();
        }
        if let Some(s) = lane.cen_state.as_mut() {
            s.reset();
        }
        Ok(())
    }

    /// One training iteration on batches from the lanes' buffers (`docs/ALGORITHMS.md` §6): the first lane's
    /// for the decentralized nets, Our-2's centralized lane's for the centralized net; h moves
    /// along its schedule before, epsilon after, as the reference does.
    fn train_iteration(&mut self, lanes: &[&ValueLane], episodes: u64) -> Result<(), TrainError> {
        let c = self.c().clone();
        let c = &c;
        let e = episodes as f64;
        self.h = hysteresis_rule(c).at(e, self.epsilon);
        let params = IterationParams {
            method: self.method,
            discount: c.discount as f32,
            h: self.h as f32,
            early_return_skips_all: c.early_return_skips_all,
            sub_trace_len: c.sub_trace_len,
        };
        let dec_batch = lanes[0].buffer.sample(c.batch_size, &mut self.replay_rng)?;
        let cen_batch = match lanes.get(1) {
            Some(l) => Some(l.buffer.sample(c.batch_size, &mut self.replay_rng)?),
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
        if !loss.total.is_finite() {
            return Err(self.non_finite("loss", episodes));
        }
        if self
            .dec
            .iter()
            .chain(self.cen.as_ref())
            .any(|n| !n.is_finite())
        {
            return Err(self.non_finite("parameter", episodes));
        }
        if loss.steps > 0 {
            self.loss_sum += loss.total;
            self.loss_count += 1;
        }
        let c = self.c();
        self.epsilon = if c.eps_l_d {
            EpsilonSchedule::new(c.eps_end, c.eps_l_d_steps as f64)
                .map(|s| s.at(e))
                .unwrap_or(c.eps_end)
        } else {
            // The reference's exponential schedule (`docs/ALGORITHMS.md` §4.1), unused by the paper's runs.
            c.eps_end + (1.0 - c.eps_end) * (-((e / 8.0).floor()) / 2000.0).exp()
        };
        Ok(())
    }

    fn sync_targets(&mut self) {
        for n in self.dec.iter_mut().chain(self.cen.as_mut()) {
            n.sync_target();
        }
    }

    fn evaluate<E: MacroEnv>(
        &self,
        env: &mut E,
        rng: &mut EnvRng,
    ) -> Result<EvalReturns, EnvError> {
        let dec: Vec<&QNet> = self.dec.iter().map(|n| &n.policy).collect();
        let policy = match self.method.evaluated_policy() {
            EvaluatedPolicy::Centralized => GreedyPolicy::Cen(
                &self
                    .cen
                    .as_ref()
                    .expect("a centrally evaluated method has a centralized net")
                    .policy,
            ),
            EvaluatedPolicy::Decentralized => GreedyPolicy::Dec(&dec),
        };
        let c = self.c();
        evaluate(
            env,
            policy,
            c.discount,
            c.eval_num_epi,
            self.deterministic,
            rng,
        )
    }

    fn metric_columns(&self) -> &'static [&'static str] {
        &METRIC_COLUMNS
    }

    fn metric_values(&mut self) -> Vec<Option<f64>> {
        let loss = (self.loss_count > 0).then(|| self.loss_sum / self.loss_count as f64);
        self.loss_sum = 0.0;
        self.loss_count = 0;
        vec![Some(self.epsilon), Some(self.h), loss]
    }

    fn progress(&self) -> String {
        format!("eps {:.3}", self.epsilon)
    }

    fn saved_nets(&self) -> SavedNets<'_> {
        use crate::nn::ActingNetRef;
        use crate::policy_files::SavedNet;
        let central = self.method.evaluated_policy() == EvaluatedPolicy::Centralized;
        let dec = self.dec_policies().into_iter().enumerate();
        dec.map(|(i, q)| SavedNet::agent(i, ActingNetRef::Q(q), !central))
            .chain(
                self.cen_policy()
                    .map(|q| SavedNet::team(ActingNetRef::Q(q), central)),
            )
            .collect()
    }
}

/// The hysteresis settings of a config.
fn hysteresis_rule(c: &ValueConfig) -> HysteresisRule {
    HysteresisRule {
        dynamic: c.dynamic_h,
        init_h: c.init_h,
        end_h: c.end_h,
        h_stable_at: c.h_stable_at as f64,
    }
}
