//! The actor-critic family as the training loop drives it (`docs/MACROMARL.md` §2): n_env lanes
//! stepped in lockstep, an on-policy batch of the last `train_freq` completed episodes, one
//! update per batch, sampled evaluation on n_env environments. Where the six methods differ,
//! [`AcMethod::design`] decides.

use std::collections::VecDeque;

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::acting::{
    act_centralized, act_centralized_lanes, act_decentralized, ActBuffers, CentralizedLane,
};
use super::config::AcConfig;
use super::episode::{Episode, EpisodeRecorder};
use super::lockstep_eval::lockstep_episodes;
use super::method::{AcActor, AcCritic, AcDesign, AcMethod};
use super::nets::{AcNets, NetSizes};
use super::scripted::{ActingCall, ActionScript};
use super::update::{update, UpdateParams, UpdateTrace};
use crate::algos::learner::{
    ActingLanes, EvalReturns, LanePlan, Learner, LearnerRngs, MethodName, SavedNets, Schedule,
    COMPLETED_EPISODE_STEPS,
};
use crate::algos::scratch::Scratch;
use crate::algos::training_loop::TrainError;
use crate::algos::update_means::UpdateMeans;
use crate::autograd::Tape;
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};
use crate::nn::GruActorState;

/// The family's `metrics.csv` columns: the exploration weight of the batch before the
/// evaluation, the mean critic and actor losses over the updates since the previous row (mean
/// over nets), the mean discounted return of the training episodes completed since then, and
/// the primitive steps of every training episode completed so far (the count ACAC's logs are
/// drawn against, which also leaves out the episodes each batch drops unfinished).
pub const METRIC_COLUMNS: [&str; 5] = [
    "eps",
    "critic_loss",
    "actor_loss",
    "train_return",
    COMPLETED_EPISODE_STEPS,
];

/// One training lane: the episode being recorded and the actors' recurrent states.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AcLane {
    recorder: EpisodeRecorder,
    states: Vec<GruActorState>,
}

/// The nets, the on-policy batch and the learner-side random stream of an actor-critic run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AcLearner {
    config: AcConfig,
    method: AcMethod,
    seed: u64,
    sizes: NetSizes,
    nets: AcNets,
    explore_rng: ChaCha8Rng,
    /// The current batch's exploration weight.
    eps: f64,
    /// The last `train_freq` completed training episodes (`Memory_epi`).
    memory: VecDeque<Episode>,
    /// Losses and training returns since the last metrics row.
    means: UpdateMeans,
    /// Primitive steps of the training episodes completed so far (dropped unfinished ones are
    /// not counted).
    completed_steps: u64,
    /// The updates' tape, reset after every pass.
    #[serde(skip, default)]
    tape: Scratch<Tape>,
    /// The acting path's scratch.
    #[serde(skip, default)]
    buffers: ActBuffers,
    /// Where the free agents' macro-actions come from instead of the actors, if anywhere
    /// (never saved: a resumed run acts with its actors).
    #[serde(skip, default)]
    script: Option<ActionScript>,
}

impl AcLearner {
    /// The run's keys.
    fn c(&self) -> &AcConfig {
        &self.config
    }

    /// The method's actor and critic.
    fn design(&self) -> AcDesign {
        self.method.design()
    }

    fn update_params(&self) -> UpdateParams {
        let c = self.c();
        UpdateParams {
            design: self.design(),
            gamma: c.gamma,
            n_step: c.n_step_td,
            eps: self.eps,
            pg_discount_at_start: c.pg_discount_at_start,
            pg_plain_log_prob: c.pg_plain_log_prob,
            obs_sizes: self.sizes.obs_sizes.clone(),
            n_actions: self.sizes.n_actions.clone(),
        }
    }

    /// The nets (for tests and the golden comparison).
    pub fn nets(&self) -> &AcNets {
        &self.nets
    }

    /// One update on `batch` with exploration weight `eps`, as a training iteration runs it,
    /// returning everything it computed (the golden tests drive the reference's batches
    /// through this).
    pub fn update_traced(&mut self, batch: &[Episode], eps: f64) -> UpdateTrace {
        self.eps = eps;
        let p = self.update_params();
        update(&mut self.nets, &p, batch, &mut self.tape.0)
    }

    /// Mutable nets (the golden tests load the reference's weights into them).
    pub fn nets_mut(&mut self) -> &mut AcNets {
        &mut self.nets
    }

    /// Let `script` choose the free agents' macro-actions while training and evaluating instead
    /// of the actors (`None`: the actors again). Everything else runs as always; the runner
    /// check against the reference replays the reference's own choices through this.
    pub fn set_action_script(&mut self, script: Option<ActionScript>) {
        self.script = script;
    }

    /// The current batch's exploration weight.
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// The last `train_freq` completed training episodes, oldest first: the batch the last
    /// update trained on.
    pub fn batch(&self) -> &VecDeque<Episode> {
        &self.memory
    }

    fn zero_states(&self) -> Vec<GruActorState> {
        self.nets
            .actors
            .iter()
            .map(|a| a.net.zero_state())
            .collect()
    }

    fn non_finite(&self, what: &'static str, episodes: u64) -> TrainError {
        TrainError::non_finite(self.method.name(), self.seed, what, episodes)
    }
}

/// Choose the free agents' macro-actions with `nets`' actors (`actor` says who acts), or with
/// `script` when one is set: `eps` is the exploration mixture's weight while training, `None`
/// when evaluated. Allocates nothing once `buffers` are warm.
#[allow(clippy::too_many_arguments)]
fn choose<E: MacroEnv>(
    script: Option<&ActionScript>,
    nets: &AcNets,
    actor: AcActor,
    n_actions: &[usize],
    env: &E,
    free: &[bool],
    states: &mut [GruActorState],
    eps: Option<f64>,
    rng: &mut ChaCha8Rng,
    buffers: &mut ActBuffers,
    actions: &mut [usize],
) {
    let running = env.executed();
    if let Some(script) = script {
        let call = ActingCall { eps, free, running };
        script.act(call, actions);
        return;
    }
    match actor {
        AcActor::Decentralized => act_decentralized(
            &|i| &nets.actors[i].net,
            states,
            &|i| env.obs(i),
            free,
            running,
            eps,
            rng,
            &mut buffers.probs,
            actions,
        ),
        AcActor::Centralized => {
            let joint = buffers.joint(env.joint_obs_size());
            env.write_joint_obs(joint);
            act_centralized(
                &nets.actors[0].net,
                &mut states[0],
                &buffers.joint,
                free,
                running,
                n_actions,
                eps,
                rng,
                &mut buffers.probs,
                actions,
            );
        }
    }
}

impl Learner for AcLearner {
    type Lane = AcLane;
    type Method = AcMethod;
    type Config = AcConfig;

    fn new<E: MacroEnv>(
        config: &AcConfig,
        method: AcMethod,
        seed: u64,
        env: &E,
        mut rngs: LearnerRngs,
    ) -> Result<Self, TrainError> {
        let design = method.design();
        let needs_state = matches!(design.critic, AcCritic::JointState | AcCritic::AgentState);
        let sizes = NetSizes {
            obs_sizes: env.obs_sizes().to_vec(),
            n_actions: env.n_actions().to_vec(),
            state_size: if needs_state { env.state_size() } else { 0 },
        };
        let nets = AcNets::new(design, config, &sizes, &mut rngs.init)
            .map_err(|e| TrainError::Nets(e.to_string()))?;
        Ok(AcLearner {
            config: config.clone(),
            method,
            seed,
            sizes,
            nets,
            explore_rng: rngs.explore,
            eps: config.eps_start,
            memory: VecDeque::new(),
            means: UpdateMeans::default(),
            completed_steps: 0,
            tape: Scratch::default(),
            buffers: ActBuffers::default(),
            script: None,
        })
    }

    fn method(&self) -> AcMethod {
        self.method
    }

    fn seed(&self) -> u64 {
        self.seed
    }

    fn config(&self) -> &AcConfig {
        &self.config
    }

    fn schedule(&self) -> Schedule {
        let c = self.c();
        Schedule::EpisodeBatches {
            train_freq: c.train_freq as u64,
            target_update_freq: c.c_target_update_freq as u64,
            eval_period: c.eval_period() as u64,
            eval_after_update: false,
        }
    }

    fn lanes(&self) -> Vec<LanePlan> {
        vec![
            LanePlan {
                counts_episodes: true
            };
            self.c().n_env
        ]
    }

    fn begin_lane<E: MacroEnv>(&self, _lane: usize, env: &E) -> Result<AcLane, TrainError> {
        let with_state = self.sizes.state_size > 0;
        Ok(AcLane {
            recorder: EpisodeRecorder::new(env, self.c().gamma, with_state),
            states: self.zero_states(),
        })
    }

    fn begin_batch(&mut self, episodes: u64) {
        self.eps = self.c().eps_at(episodes);
    }

    fn act<E: MacroEnv>(&mut self, lane: &mut AcLane, env: &E, actions: &mut [usize]) {
        choose(
            self.script.as_ref(),
            &self.nets,
            self.method.design().actor,
            &self.sizes.n_actions,
            env,
            lane.recorder.free(),
            &mut lane.states,
            Some(self.eps),
            &mut self.explore_rng,
            &mut self.buffers,
            actions,
        );
    }

    fn act_lanes<E: MacroEnv>(&mut self, lanes: &mut dyn ActingLanes<AcLane, E>) {
        if self.script.is_some() || self.design().actor != AcActor::Centralized {
            for i in 0..lanes.len() {
                let (lane, env, actions) = lanes.lane(i);
                self.act(lane, env, actions);
            }
            return;
        }
        act_centralized_lanes(
            &self.nets.actors[0].net,
            lanes.len(),
            &mut |i, f| {
                let (lane, env, actions) = lanes.lane(i);
                f(CentralizedLane {
                    state: &mut lane.states[0],
                    free: lane.recorder.free(),
                    running: env.executed(),
                    write_joint_obs: &|out| env.write_joint_obs(out),
                    actions,
                })
            },
            &self.sizes.n_actions,
            Some(self.eps),
            &mut self.explore_rng,
            &mut self.buffers,
        );
    }

    fn record<E: MacroEnv>(
        &mut self,
        lane: &mut AcLane,
        env: &E,
        outcome: StepOutcome,
    ) -> Result<bool, TrainError> {
        lane.recorder.record(env, outcome);
        if !outcome.done {
            return Ok(false);
        }
        self.means.record_return(lane.recorder.returns().discounted);
        self.completed_steps += lane.recorder.episode().steps as u64;
        self.memory.push_back(lane.recorder.episode().clone());
        while self.memory.len() > self.c().train_freq {
            self.memory.pop_front();
        }
        Ok(true)
    }

    fn begin_episode<E: MacroEnv>(&self, lane: &mut AcLane, env: &E) -> Result<(), TrainError> {
        lane.recorder.begin(env);
        for s in &mut lane.states {
            s.reset();
        }
        Ok(())
    }

    fn train_iteration(&mut self, _lanes: &[&AcLane], episodes: u64) -> Result<(), TrainError> {
        // The batch is the memory itself, in order: nothing is copied.
        let p = self.update_params();
        let batch = self.memory.make_contiguous();
        let trace = update(&mut self.nets, &p, batch, &mut self.tape.0);
        let critic: Vec<f64> = trace
            .critics
            .iter()
            .flatten()
            .map(|c| f64::from(c.loss))
            .collect();
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

    /// The reference's evaluation (P8): `n_env` environments reset and stepped in lockstep with
    /// actions sampled from the plain actors, until `eval_num_epi` episodes completed; the mean
    /// discounted return of the last `eval_num_epi` to complete.
    fn evaluate_lanes<E: MacroEnv>(
        &self,
        envs: &mut [&mut E],
        rng: &mut EnvRng,
    ) -> Result<EvalReturns, EnvError> {
        let c = self.c();
        let mut buffers = ActBuffers::default();
        let actor = self.design().actor;
        let returns = lockstep_episodes(
            envs,
            c.gamma,
            c.eval_num_epi,
            rng,
            || self.zero_states(),
            |env, free, states, rng, actions| {
                let n_actions = &self.sizes.n_actions;
                choose(
                    self.script.as_ref(),
                    &self.nets,
                    actor,
                    n_actions,
                    env,
                    free,
                    states,
                    None,
                    rng,
                    &mut buffers,
                    actions,
                )
            },
        )?;
        Ok(EvalReturns::mean(
            &returns[returns.len() - c.eval_num_epi..],
        ))
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

    fn metric_values(&mut self) -> Vec<Option<f64>> {
        let [critic, actor, ret] = self.means.take_row();
        let steps = Some(self.completed_steps as f64);
        vec![Some(self.eps), critic, actor, ret, steps]
    }

    fn progress(&self) -> String {
        format!("eps {:.3}", self.eps)
    }

    fn saved_nets(&self) -> SavedNets<'_> {
        use crate::nn::ActingNetRef;
        use crate::policy_files::SavedNet;
        // Actors only (critics are for training): agent i's, or Mac-CAC's one for the team;
        // the evaluated policy is the actors either way.
        let central = self.design().actor == AcActor::Centralized;
        let actors = self.nets.actors.iter().enumerate();
        actors
            .map(|(i, a)| {
                let net = ActingNetRef::Actor(&a.net);
                if central {
                    SavedNet::team(net, true)
                } else {
                    SavedNet::agent(i, net, true)
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
    use crate::envs::AnyEnv;
    use crate::experiment::run::train_run::run_rngs;

    /// Mac-IAICC on Box Pushing 6x6 with `n_env` lanes and batches of `train_freq` episodes.
    fn short_run(n_env: usize, train_freq: usize) -> TrainingLoop<AcLearner, AnyEnv> {
        let spec = crate::envs::bp_ma_v0::spec(6, 30);
        let method = AcMethod::MacIaicc;
        let mut c = method.defaults(&spec);
        (c.n_env, c.train_freq, c.c_target_update_freq) = (n_env, train_freq, 4 * train_freq);
        (c.eval_freq, c.eval_num_epi, c.total_epi) = (4 * train_freq, 2, 16 * train_freq);
        (c.a_mlp_layer_size, c.a_rnn_layer_size) = (vec![8, 8], 8);
        (c.c_mlp_layer_size, c.c_rnn_layer_size) = (vec![8, 8], 8);
        TrainingLoop::new(&c, method, 0, run_rngs(0), || spec.build()).unwrap()
    }

    fn completed_steps(l: &mut TrainingLoop<AcLearner, AnyEnv>) -> Vec<(u64, u64)> {
        while let Advance::Episode { .. } = l.advance().unwrap() {}
        let at = METRIC_COLUMNS.len() - 1;
        l.evals()
            .iter()
            .map(|e| (e.family[at].unwrap() as u64, e.env_steps))
            .collect()
    }

    #[test]
    fn one_lane_with_batches_of_one_episode_drops_nothing_so_both_counts_agree() {
        let counts = completed_steps(&mut short_run(1, 1));
        assert!(
            counts.len() > 3 && counts.last().unwrap().0 > 0,
            "{counts:?}"
        );
        assert!(
            counts.iter().all(|(done, taken)| done == taken),
            "{counts:?}"
        );
    }

    #[test]
    fn lockstep_lanes_leave_out_the_steps_of_the_episodes_each_batch_drops() {
        let counts = completed_steps(&mut short_run(4, 2));
        assert!(counts.windows(2).all(|w| w[0].0 <= w[1].0), "{counts:?}");
        assert!(
            counts.iter().all(|(done, taken)| done <= taken),
            "{counts:?}"
        );
        // Four lanes, two episodes a batch: the other lanes' steps are dropped every batch.
        let (done, taken) = *counts.last().unwrap();
        assert!(done > 0 && done < taken, "{counts:?}");
    }
}
