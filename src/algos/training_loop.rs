//! The one training loop every method family runs (`docs/ALGORITHMS.md` §6 for its schedule):
//! step the training lanes, count episodes and steps, train and sync targets when the learner's
//! [`Schedule`] says, evaluate before training and every `eval_freq` training episodes.
//!
//! The whole loop is one serializable value, so a checkpoint is the loop itself and a resumed run
//! continues with exactly the numbers of an uninterrupted one.

use crate::algos::learner::{
    ActingLanes, FamilyConfig, Learner, LearnerRngs, MethodName, SavedNets, Schedule,
};
use crate::envs::{EnvError, EnvRng, MacroEnv};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Independent random streams of one run (one per role, `docs/ALGORITHMS.md` §8).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunRngs {
    /// Initial net weights.
    pub init: ChaCha8Rng,
    /// Exploration (epsilon-greedy draws, actor sampling).
    pub explore: ChaCha8Rng,
    /// Replay sampling.
    pub replay: ChaCha8Rng,
    /// The first training lane's environment.
    pub env: EnvRng,
    /// The second training lane's environment (Our-2's centralized lane).
    pub cen_env: EnvRng,
    /// The evaluation environment.
    pub eval_env: EnvRng,
}

pub use super::train_error::TrainError;

/// Training lanes one run may have (MacroMARL's `n_env`; published at most 48).
pub const MAX_LANES: usize = crate::algos::actor_critic::config::MAX_N_ENV;
/// Stream ids of lanes beyond the second: clear of the per-role ids.
const EXTRA_LANE_STREAMS: u64 = 1 << 32;

/// One evaluation point, as the metrics file records it (one `metrics.csv` row).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvalPoint {
    /// Training episodes completed.
    pub episode: u64,
    /// Primitive steps taken by the training environments.
    pub env_steps: u64,
    /// Training updates (iterations) done.
    pub updates: u64,
    /// Mean evaluation return, discounted per primitive step (`docs/ALGORITHMS.md` §7.1).
    pub eval_return: f64,
    /// Mean evaluation return, undiscounted ([`crate::algos::learner::EvalReturns`]); `None` in
    /// the metrics files of runs trained before the column existed.
    pub eval_return_undiscounted: Option<f64>,
    /// The family's own columns, in the order of [`Learner::metric_columns`] (value-based:
    /// `epsilon`, `hysteresis`, `loss`); `None` is an empty cell.
    pub family: Vec<Option<f64>>,
    /// Wall-clock seconds since the run started, over all resumed segments (not reproducible).
    pub wall_seconds: f64,
}

/// What [`TrainingLoop::advance`] stopped at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Advance {
    /// A training episode finished; `checkpoint_due` when the episode count hits checkpoint_freq.
    Episode {
        /// Whether a checkpoint is due now.
        checkpoint_due: bool,
    },
    /// `total_epi` episodes are done.
    Finished,
}

/// One training environment with its random stream, the learner's state for it and the
/// actions of its next step.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(bound(serialize = "E: Serialize, S: Serialize"))]
#[serde(bound(deserialize = "E: serde::de::DeserializeOwned, S: serde::de::DeserializeOwned"))]
struct Lane<E, S> {
    env: E,
    rng: EnvRng,
    state: S,
    actions: Vec<usize>,
    counts_episodes: bool,
}

/// The loop's lanes as [`Learner::act_lanes`] reads them.
struct LanesForActing<'a, E, S>(&'a mut [Lane<E, S>]);

impl<E, S> ActingLanes<S, E> for LanesForActing<'_, E, S> {
    fn len(&self) -> usize {
        self.0.len()
    }

    fn lane(&mut self, i: usize) -> (&mut S, &E, &mut [usize]) {
        let lane = &mut self.0[i];
        (&mut lane.state, &lane.env, &mut lane.actions)
    }
}

/// The complete state of a training run: learner, lanes, evaluation env and counters.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(bound(serialize = "E: Serialize, L: Serialize"))]
#[serde(bound(deserialize = "E: serde::de::DeserializeOwned, L: serde::de::DeserializeOwned"))]
pub struct TrainingLoop<L: Learner, E> {
    learner: L,
    lanes: Vec<Lane<E, L::Lane>>,
    eval_env: E,
    eval_rng: EnvRng,
    episodes: u64,
    step: u64,
    env_steps: u64,
    updates: u64,
    evaluated_once: bool,
    evals: Vec<EvalPoint>,
    /// Wall-clock seconds of earlier segments of this run (before the last resume).
    elapsed_before: f64,
    #[serde(skip, default)]
    segment_start: Option<std::time::Instant>,
}

impl<L: Learner, E: MacroEnv> TrainingLoop<L, E> {
    /// Build the learner, the lanes and the evaluation env for `method` with seed `seed` on the
    /// domain `make_env` builds, called once per environment (evaluation first, then each lane).
    /// What the learner needs to know about the domain comes from its [`MacroEnv`]
    /// implementation; the config's `env` is not read here.
    pub fn new(
        config: &L::Config,
        method: L::Method,
        seed: u64,
        rngs: RunRngs,
        make_env: impl Fn() -> Result<E, EnvError>,
    ) -> Result<Self, TrainError> {
        let eval_env = make_env()?;
        let learner_rngs = LearnerRngs {
            init: rngs.init,
            explore: rngs.explore,
            replay: rngs.replay,
        };
        let learner = L::new(config, method, seed, &eval_env, learner_rngs)?;
        let plans = learner.lanes();
        if plans.len() > MAX_LANES {
            return Err(TrainError::TooManyLanes {
                method: method.name(),
                asked: plans.len(),
                available: MAX_LANES,
            });
        }
        // The first two lanes keep their roles' streams (the value methods' runs are unchanged);
        // further lanes (MacroMARL's n_env environments) take streams of the env stream's key.
        let mut streams = vec![rngs.env.clone(), rngs.cen_env];
        for k in 2..plans.len() {
            let mut s = rngs.env.clone();
            s.set_stream(EXTRA_LANE_STREAMS + k as u64);
            s.set_word_pos(0);
            streams.push(s);
        }
        streams.truncate(plans.len());
        let mut lanes = Vec::with_capacity(plans.len());
        for (index, (plan, mut rng)) in plans.into_iter().zip(streams).enumerate() {
            let mut env = make_env()?;
            env.reset(&mut rng);
            let state = learner.begin_lane(index, &env)?;
            lanes.push(Lane {
                actions: vec![0; env.n_agents()],
                env,
                rng,
                state,
                counts_episodes: plan.counts_episodes,
            });
        }
        Ok(TrainingLoop {
            learner,
            lanes,
            eval_env,
            eval_rng: rngs.eval_env,
            episodes: 0,
            step: 0,
            env_steps: 0,
            updates: 0,
            evaluated_once: false,
            evals: Vec::new(),
            elapsed_before: 0.0,
            segment_start: None,
        })
    }

    /// The learner (its nets, method, seed and config).
    pub fn learner(&self) -> &L {
        &self.learner
    }

    /// The learner, to change how it acts (e.g. an actor-critic learner's action script); its
    /// nets and counters belong to the loop.
    pub fn learner_mut(&mut self) -> &mut L {
        &mut self.learner
    }

    /// The run's configuration.
    pub fn config(&self) -> &L::Config {
        self.learner.config()
    }

    /// The method being trained.
    pub fn method(&self) -> L::Method {
        self.learner.method()
    }

    /// The run's seed.
    pub fn seed(&self) -> u64 {
        self.learner.seed()
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

    /// The names of the family's own metrics columns ([`EvalPoint::family`]).
    pub fn metric_columns(&self) -> &'static [&'static str] {
        self.learner.metric_columns()
    }

    /// A few words of training state for progress lines.
    pub fn progress(&self) -> String {
        self.learner.progress()
    }

    /// The nets the run saves as policy files.
    pub fn saved_nets(&self) -> SavedNets<'_> {
        self.learner.saved_nets()
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
        self.learner.is_finished(self.episodes)
    }

    /// Run until a training episode (an [`Schedule::EpisodeBatches`] batch) finishes or
    /// training is complete.
    pub fn advance(&mut self) -> Result<Advance, TrainError> {
        self.segment_start
            .get_or_insert_with(std::time::Instant::now);
        let checkpoint_freq = self.config().checkpoint_freq() as u64;
        loop {
            if self.is_finished() {
                return Ok(Advance::Finished);
            }
            let before = self.episodes;
            let finished = match self.learner.schedule() {
                Schedule::EveryStep {
                    train_freq,
                    start_train,
                    target_update_freq,
                    eval_freq,
                    first_step,
                } => self.main_loop_iteration(
                    [train_freq, start_train, target_update_freq, eval_freq],
                    first_step,
                )?,
                Schedule::EpisodeBatches {
                    train_freq,
                    target_update_freq,
                    eval_period,
                    eval_after_update,
                } => {
                    self.batch_iteration(
                        train_freq,
                        target_update_freq,
                        eval_period,
                        eval_after_update,
                    )?;
                    true
                }
            };
            if finished {
                // Due when the count reached or passed a multiple of checkpoint_freq.
                let due = self.episodes / checkpoint_freq > before / checkpoint_freq;
                return Ok(Advance::Episode {
                    checkpoint_due: due,
                });
            }
        }
    }

    /// One update of MacroMARL's loop (`docs/MACROMARL.md` §2.3): evaluate when due, reset every
    /// lane, step them in lockstep until `train_freq` episodes completed, train, count exactly
    /// `train_freq` episodes, sync targets when due (then evaluate when due, for ACAC's order).
    fn batch_iteration(
        &mut self,
        train_freq: u64,
        target_update_freq: u64,
        eval_period: u64,
        eval_after_update: bool,
    ) -> Result<(), TrainError> {
        if !eval_after_update && self.episodes.is_multiple_of(eval_period) {
            self.evaluate()?;
        }
        self.learner.begin_batch(self.episodes);
        for lane in &mut self.lanes {
            lane.env.reset(&mut lane.rng);
            self.learner.begin_episode(&mut lane.state, &lane.env)?;
        }
        let mut completed = 0u64;
        while completed < train_freq {
            // A whole lockstep step, then the check (`while n_epi_count < n_epis: _step()`):
            // every lane chooses, then each steps in order (acting reads only its own lane).
            self.learner.act_lanes(&mut LanesForActing(&mut self.lanes));
            for lane in 0..self.lanes.len() {
                completed += u64::from(self.step_acted_lane(lane)?);
            }
        }
        let lanes: Vec<&L::Lane> = self.lanes.iter().map(|l| &l.state).collect();
        self.learner.train_iteration(&lanes, self.episodes)?;
        self.updates += 1;
        self.episodes += train_freq;
        self.step += 1;
        if self.episodes.is_multiple_of(target_update_freq) {
            self.learner.sync_targets();
        }
        if eval_after_update && self.episodes.is_multiple_of(eval_period) {
            self.evaluate()?;
        }
        Ok(())
    }

    /// One main-loop iteration (`docs/ALGORITHMS.md` §6) of the [`Schedule::EveryStep`] schedule. Returns
    /// whether a training episode finished.
    fn main_loop_iteration(
        &mut self,
        [train_freq, start_train, target_update_freq, eval_freq]: [u64; 4],
        first_step: u64,
    ) -> Result<bool, TrainError> {
        if !self.evaluated_once {
            self.evaluated_once = true;
            self.evaluate()?;
        }
        // Lanes step in order: Our-2's decentralized lane first, then its centralized one (4.6).
        let mut finished = 0u64;
        for lane in 0..self.lanes.len() {
            finished += u64::from(self.step_lane(lane)?);
        }
        for _ in 0..finished {
            self.episodes += 1;
            if self.episodes.is_multiple_of(eval_freq) {
                self.evaluate()?;
            }
        }
        let counted = self.step + first_step;
        if counted.is_multiple_of(train_freq) && self.episodes >= start_train {
            let lanes: Vec<&L::Lane> = self.lanes.iter().map(|l| &l.state).collect();
            self.learner.train_iteration(&lanes, self.episodes)?;
            self.updates += 1;
        }
        if counted.is_multiple_of(target_update_freq) {
            self.learner.sync_targets();
        }
        self.step += 1;
        Ok(finished > 0)
    }

    /// One primitive step of a training lane; a finished episode resets its env. Returns whether
    /// a counted training episode finished.
    fn step_lane(&mut self, index: usize) -> Result<bool, TrainError> {
        let lane = &mut self.lanes[index];
        self.learner
            .act(&mut lane.state, &lane.env, &mut lane.actions);
        self.step_acted_lane(index)
    }

    /// [`Self::step_lane`] after the lane's actions were chosen.
    fn step_acted_lane(&mut self, index: usize) -> Result<bool, TrainError> {
        let lane = &mut self.lanes[index];
        let outcome = lane.env.step(&lane.actions, &mut lane.rng)?;
        self.env_steps += 1;
        if !self.learner.record(&mut lane.state, &lane.env, outcome)? {
            return Ok(false);
        }
        lane.env.reset(&mut lane.rng);
        self.learner.begin_episode(&mut lane.state, &lane.env)?;
        Ok(lane.counts_episodes)
    }

    /// Evaluate the learner's policy (`docs/ALGORITHMS.md` §7.1), appended to the curve.
    fn evaluate(&mut self) -> Result<(), TrainError> {
        let returns = match self.learner.schedule() {
            Schedule::EveryStep { .. } => self
                .learner
                .evaluate(&mut self.eval_env, &mut self.eval_rng)?,
            Schedule::EpisodeBatches { .. } => {
                let mut envs: Vec<&mut E> = self.lanes.iter_mut().map(|l| &mut l.env).collect();
                self.learner.evaluate_lanes(&mut envs, &mut self.eval_rng)?
            }
        };
        let family = self.learner.metric_values();
        self.evals.push(EvalPoint {
            episode: self.episodes,
            env_steps: self.env_steps,
            updates: self.updates,
            eval_return: returns.discounted,
            eval_return_undiscounted: Some(returns.undiscounted),
            family,
            wall_seconds: self.wall_seconds(),
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::family::FamilyMethod;
    use crate::algos::learner::{EvalReturns, LanePlan};
    use crate::algos::value::config::ValueConfig;
    use crate::algos::value::method::ValueMethod;
    use crate::envs::StepOutcome;
    use crate::experiment::run::train_run::run_rngs;

    /// A learner that acts with macro-action 0 and logs when the loop calls it, so the loop's
    /// schedule can be checked apart from any method. Its second lane does not count episodes.
    #[derive(Debug, Clone, Serialize, Deserialize)]
    struct Probe {
        config: ValueConfig,
        trains: Vec<(usize, u64)>,
        syncs: u64,
        evals: u64,
        lane_steps: [u64; 2],
    }

    impl Learner for Probe {
        type Lane = usize;
        type Method = ValueMethod;
        type Config = ValueConfig;
        fn new<E: MacroEnv>(
            config: &ValueConfig,
            _: ValueMethod,
            _: u64,
            _: &E,
            _: LearnerRngs,
        ) -> Result<Self, TrainError> {
            Ok(Probe {
                config: config.clone(),
                trains: Vec::new(),
                syncs: 0,
                evals: 0,
                lane_steps: [0; 2],
            })
        }
        fn method(&self) -> ValueMethod {
            ValueMethod::Our2
        }
        fn seed(&self) -> u64 {
            0
        }
        fn config(&self) -> &ValueConfig {
            &self.config
        }
        fn schedule(&self) -> Schedule {
            Schedule::EveryStep {
                train_freq: 3,
                start_train: 1,
                target_update_freq: 5,
                eval_freq: 2,
                first_step: 0,
            }
        }
        fn lanes(&self) -> Vec<LanePlan> {
            vec![
                LanePlan {
                    counts_episodes: true,
                },
                LanePlan {
                    counts_episodes: false,
                },
            ]
        }
        fn begin_lane<E: MacroEnv>(&self, lane: usize, _: &E) -> Result<usize, TrainError> {
            Ok(lane)
        }
        fn act<E: MacroEnv>(&mut self, lane: &mut usize, _: &E, actions: &mut [usize]) {
            self.lane_steps[*lane] += 1;
            actions.fill(0);
        }
        fn record<E: MacroEnv>(
            &mut self,
            _: &mut usize,
            _: &E,
            outcome: StepOutcome,
        ) -> Result<bool, TrainError> {
            Ok(outcome.done)
        }
        fn begin_episode<E: MacroEnv>(&self, _: &mut usize, _: &E) -> Result<(), TrainError> {
            Ok(())
        }
        fn train_iteration(&mut self, lanes: &[&usize], episodes: u64) -> Result<(), TrainError> {
            assert_eq!(lanes, [&0, &1]);
            let steps = self.lane_steps[0] as usize;
            self.trains.push((steps, episodes));
            Ok(())
        }
        fn sync_targets(&mut self) {
            self.syncs += 1;
        }
        fn evaluate<E: MacroEnv>(
            &self,
            _: &mut E,
            _: &mut EnvRng,
        ) -> Result<EvalReturns, EnvError> {
            Ok(EvalReturns {
                discounted: self.trains.len() as f64,
                undiscounted: -(self.trains.len() as f64),
            })
        }
        fn metric_columns(&self) -> &'static [&'static str] {
            &["evals_before"]
        }
        fn metric_values(&mut self) -> Vec<Option<f64>> {
            self.evals += 1;
            vec![Some(self.evals as f64 - 1.0)]
        }
        fn progress(&self) -> String {
            String::new()
        }
        fn saved_nets(&self) -> SavedNets<'_> {
            Vec::new()
        }
    }

    #[test]
    fn the_loop_trains_syncs_and_evaluates_on_the_learners_schedule() {
        // Box Pushing 8x8 with horizon 10 and every agent always on action 0: each episode runs
        // to the horizon, so episode k ends at main-loop step 10k - 1.
        let spec = crate::envs::box_pushing::spec(8, 10);
        let mut config = ValueMethod::Our2.defaults(&spec);
        config.total_epi = 4;
        config.eval_freq = 2;
        config.checkpoint_freq = 3;
        let mut l: TrainingLoop<Probe, _> =
            TrainingLoop::new(&config, ValueMethod::Our2, 0, run_rngs(0), || spec.build()).unwrap();
        let mut stops = Vec::new();
        while let Advance::Episode { checkpoint_due } = l.advance().unwrap() {
            stops.push((l.episodes(), checkpoint_due));
        }
        assert_eq!(stops, [(1, false), (2, false), (3, true), (4, false)]);
        // 40 main-loop steps; both lanes stepped each; only the first lane counted episodes.
        assert_eq!(l.env_steps(), 80);
        assert_eq!(l.learner().lane_steps, [40, 40]);
        // Training every third step (0, 3, ...) once one episode is done (the first ends in
        // step 9): steps 9, 12, ..., 39, with the episode count at the time.
        let expected: Vec<(usize, u64)> = (9..40)
            .step_by(3)
            .map(|s| (s + 1, (s as u64 + 1) / 10))
            .collect();
        assert_eq!(l.learner().trains, expected);
        assert_eq!(l.updates(), expected.len() as u64);
        assert_eq!(l.learner().syncs, 8);
        // Evaluations before training and after episodes 2 and 4 (4 and 10 iterations done by
        // then), with the learner's columns.
        let points: Vec<(u64, f64, Vec<Option<f64>>)> = l
            .evals()
            .iter()
            .map(|p| (p.episode, p.eval_return, p.family.clone()))
            .collect();
        assert_eq!(
            points,
            [
                (0, 0.0, vec![Some(0.0)]),
                (2, 4.0, vec![Some(1.0)]),
                (4, 10.0, vec![Some(2.0)]),
            ]
        );
    }
}
