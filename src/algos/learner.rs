//! The seam between the training loop and a method family: what the loop asks of a learner.
//!
//! The loop ([`crate::algos::training_loop::TrainingLoop`]) owns the environments, their random
//! streams, the counters, the evaluation schedule, the metrics rows and the checkpoint; it knows
//! nothing of nets, replay or losses. A family (the value-based methods of
//! [`crate::algos::value`], the actor-critic methods next) implements [`Learner`]: how its
//! training lanes act and what they record, what one training iteration and a target sync do,
//! how its evaluated policy acts, which metrics columns it adds and which nets it saves.
//!
//! Adding a family is a folder under `src/algos/` with one type implementing this trait and
//! its methods' enum implementing [`crate::algos::family::FamilyMethod`], and one line in the
//! list of families ([`crate::algos::families`]).

use crate::algos::train_error::TrainError;
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};
use rand_chacha::ChaCha8Rng;
use serde::de::DeserializeOwned;
use serde::Serialize;

/// When the loop trains and syncs targets, in terms of its own counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Schedule {
    /// The ICRA main loop (`docs/ALGORITHMS.md` §6): every main-loop step advances each lane by one
    /// primitive step; a training iteration runs every `train_freq` steps once `start_train`
    /// training episodes are done; targets are hard-copied every `target_update_freq` steps.
    EveryStep {
        /// Main-loop steps between training iterations.
        train_freq: u64,
        /// Training episodes to complete before the first iteration.
        start_train: u64,
        /// Main-loop steps between hard target copies.
        target_update_freq: u64,
        /// Evaluate before training and every `eval_freq` training episodes.
        eval_freq: u64,
        /// The number of the first main-loop step in the train and target-sync checks: 0 for
        /// the ICRA loop, 1 for MacroMARL's value-based `learn()` (`step += 1` comes first).
        first_step: u64,
    },
    /// MacroMARL's collection (`docs/MACROMARL.md` §2.3): every update first resets every lane,
    /// steps them in lockstep until at least `train_freq` episodes have completed (the
    /// unfinished ones are dropped), trains once and counts exactly `train_freq` episodes;
    /// targets are hard-copied when the count is a multiple of `target_update_freq`. An
    /// evaluation precedes every update whose episode count is a multiple of `eval_period`.
    EpisodeBatches {
        /// Completed episodes per update.
        train_freq: u64,
        /// Episodes between hard target copies.
        target_update_freq: u64,
        /// Episodes between evaluations.
        eval_period: u64,
        /// Evaluate after the update that brings the count to a multiple of `eval_period` (ACAC's
        /// `learn()`: never at episode 0) instead of before the next batch (MacroMARL's).
        eval_after_update: bool,
    },
}

/// What one evaluation measured: the evaluated policy's mean return over its episodes, both ways
/// the field reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EvalReturns {
    /// Discounted per primitive step with the training discount (`docs/ALGORITHMS.md` §7.1):
    /// what the references plot and `metrics.csv`'s `eval_return` holds.
    pub discounted: f64,
    /// The plain sum over primitive steps of the team reward (the agents' mean reward where the
    /// reference's rewards are per agent): what ACAC and later work report
    /// (`eval_return_undiscounted`).
    pub undiscounted: f64,
}

impl EvalReturns {
    /// The mean of both returns over `episodes` (not empty).
    pub fn mean(episodes: &[EvalReturns]) -> EvalReturns {
        let n = episodes.len() as f64;
        EvalReturns {
            discounted: episodes.iter().map(|r| r.discounted).sum::<f64>() / n,
            undiscounted: episodes.iter().map(|r| r.undiscounted).sum::<f64>() / n,
        }
    }
}

/// One training lane a learner asks for: an environment the loop steps and resets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LanePlan {
    /// Whether the lane's finished episodes are training episodes (`total_epi`, `eval_freq` and
    /// `checkpoint_freq` count them). Our-2's centralized-exploring lane does not count (`docs/ALGORITHMS.md` §5.5).
    pub counts_episodes: bool,
}

/// The random streams a learner draws from (one per role, `docs/ALGORITHMS.md` §8); the loop keeps
/// the environments' streams.
#[derive(Debug, Clone)]
pub struct LearnerRngs {
    /// Net initialisation.
    pub init: ChaCha8Rng,
    /// Exploration draws while training.
    pub explore: ChaCha8Rng,
    /// Replay sampling.
    pub replay: ChaCha8Rng,
}

/// The nets a learner saves as the run's policy files: one list, each entry saying what the net is
/// (a Q-net or an actor), whose (one agent's, or the team's centralized net) and whether the
/// evaluated policy acts with it. The run writer, `api` and the policy files read only this list,
/// so nothing outside a family's folder asks which family it is.
pub type SavedNets<'a> = Vec<crate::policy_files::SavedNet<'a>>;

/// A family's method as the training loop names it in messages.
pub trait MethodName: Copy + std::fmt::Debug {
    /// The command-line and directory name (`our1`, `mac-iac`).
    fn name(self) -> &'static str;
}

/// A family's resolved hyperparameters: every key concrete, under the family's reference's flag
/// names. What the training loop and the run layer need of every family's config.
pub trait FamilyConfig:
    Clone + PartialEq + std::fmt::Debug + Serialize + DeserializeOwned + Send + Sync + 'static
{
    /// Training episodes (`total_epi`).
    fn total_epi(&self) -> usize;
    /// Set the number of training episodes (a shortened run in a benchmark or test).
    fn set_total_epi(&mut self, episodes: usize);
    /// Training episodes between checkpoints.
    fn checkpoint_freq(&self) -> usize;
    /// The discount per primitive step of evaluation returns and exported policies.
    fn discount(&self) -> f64;
}

/// The family column of step counts ACAC's logs are drawn against (their `Timesteps`): the
/// primitive steps of completed training episodes, cumulative at each evaluation. The families
/// whose runners drop the episodes still running when a batch is complete (actor-critic, ACAC)
/// write it under this one name, so one axis (`--x acac_timesteps`) reads them all and compares
/// them with ACAC's published curves; files of runs trained before a family wrote it lack it.
pub const COMPLETED_EPISODE_STEPS: &str = "acac_timesteps";

/// The training lanes as [`Learner::act_lanes`] sees them: each lane's learner state, its
/// environment and the actions it will step with (not its random stream).
pub trait ActingLanes<S, E> {
    /// How many lanes.
    fn len(&self) -> usize;
    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Lane `i`'s learner state, environment and actions. Panics if `i` is out of range.
    fn lane(&mut self, i: usize) -> (&mut S, &E, &mut [usize]);
}

/// A method family, as the training loop drives it. The learner is saved inside every checkpoint
/// (with its lanes' state), so a resumed run continues with exactly the numbers of an
/// uninterrupted one.
pub trait Learner: Sized + Clone + std::fmt::Debug + Serialize + DeserializeOwned {
    /// What the learner keeps per training lane besides the environment: hidden states, the
    /// episode being recorded, the lane's replay.
    type Lane: Clone + std::fmt::Debug + Serialize + DeserializeOwned;
    /// The family's methods.
    type Method: MethodName;
    /// The family's resolved keys.
    type Config: FamilyConfig;

    /// Build the nets and buffers of `method` for the domain `env` is an instance of (its sizes,
    /// horizon and first-record rule; `env` is in its reset state). Errors name the bad setting.
    fn new<E: MacroEnv>(
        config: &Self::Config,
        method: Self::Method,
        seed: u64,
        env: &E,
        rngs: LearnerRngs,
    ) -> Result<Self, TrainError>;

    /// The method being trained.
    fn method(&self) -> Self::Method;
    /// The run's seed.
    fn seed(&self) -> u64;
    /// The run's configuration.
    fn config(&self) -> &Self::Config;

    /// When the loop calls [`Self::train_iteration`] and [`Self::sync_targets`].
    fn schedule(&self) -> Schedule;
    /// Whether the run's budget is spent after `episodes` training episodes. By default
    /// `total_epi` episodes; a family that budgets otherwise (ACAC: primitive steps) says so.
    fn is_finished(&self, episodes: u64) -> bool {
        episodes >= self.config().total_epi() as u64
    }
    /// The training lanes, in the order the loop steps them within one main-loop step.
    fn lanes(&self) -> Vec<LanePlan>;
    /// The state of lane `lane` at the start of its first episode (`env` just reset).
    fn begin_lane<E: MacroEnv>(&self, lane: usize, env: &E) -> Result<Self::Lane, TrainError>;

    /// Choose the free agents' macro-actions for the next primitive step of a training lane.
    fn act<E: MacroEnv>(&mut self, lane: &mut Self::Lane, env: &E, actions: &mut [usize]);
    /// Choose the next macro-actions of every training lane of one lockstep step of an
    /// [`Schedule::EpisodeBatches`] batch, before any of them steps: by default [`Self::act`]
    /// on each lane in order. A learner may compute them together (Mac-CAC reads its wide
    /// output layer once for all lanes) if every lane gets exactly what [`Self::act`], called
    /// lane by lane in order, would give it; acting never depends on another lane's step.
    fn act_lanes<E: MacroEnv>(&mut self, lanes: &mut dyn ActingLanes<Self::Lane, E>) {
        for i in 0..lanes.len() {
            let (state, env, actions) = lanes.lane(i);
            self.act(state, env, actions);
        }
    }
    /// Record the step `env` just took. Returns whether the episode ended; the loop then resets
    /// the environment and calls [`Self::begin_episode`].
    fn record<E: MacroEnv>(
        &mut self,
        lane: &mut Self::Lane,
        env: &E,
        outcome: StepOutcome,
    ) -> Result<bool, TrainError>;
    /// Start a lane's next episode (`env` just reset).
    fn begin_episode<E: MacroEnv>(&self, lane: &mut Self::Lane, env: &E) -> Result<(), TrainError>;

    /// Called before the lanes collect an [`Schedule::EpisodeBatches`] batch, with the training
    /// episodes done so far (the batch's exploration rate follows from it).
    fn begin_batch(&mut self, episodes: u64) {
        let _ = episodes;
    }

    /// One training iteration on what the lanes collected (in [`Self::lanes`] order);
    /// `episodes` is the number of training episodes done.
    fn train_iteration(&mut self, lanes: &[&Self::Lane], episodes: u64) -> Result<(), TrainError>;
    /// Copy the online nets into their targets.
    fn sync_targets(&mut self);

    /// The evaluated policy's mean returns over `config().eval_num_epi` episodes of `env`
    /// (one if the domain is deterministic).
    fn evaluate<E: MacroEnv>(&self, env: &mut E, rng: &mut EnvRng)
        -> Result<EvalReturns, EnvError>;

    /// The evaluation of an [`Schedule::EpisodeBatches`] learner, on the training lanes'
    /// environments (MacroMARL evaluates on its workers; the lanes are reset before the next
    /// batch anyway). By default [`Self::evaluate`] on the first lane.
    fn evaluate_lanes<E: MacroEnv>(
        &self,
        envs: &mut [&mut E],
        rng: &mut EnvRng,
    ) -> Result<EvalReturns, EnvError> {
        self.evaluate(&mut *envs[0], rng)
    }

    /// The family's own `metrics.csv` columns, after `eval_return` and before `wall_seconds`.
    fn metric_columns(&self) -> &'static [&'static str];
    /// The values of [`Self::metric_columns`] at an evaluation (`None` writes an empty cell);
    /// running means restart afterwards.
    fn metric_values(&mut self) -> Vec<Option<f64>>;
    /// A few words of training state for progress lines (e.g. `eps 0.512`).
    fn progress(&self) -> String;

    /// The nets written as the run's policy files.
    fn saved_nets(&self) -> SavedNets<'_>;
}
