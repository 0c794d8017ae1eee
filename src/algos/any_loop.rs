//! A training loop of whichever family a method belongs to, chosen by value: the run on disk, its
//! checkpoint and the library API hold an [`AnyLoop`] and never name a learner type.

use crate::algos::actor_critic::learner::AcLearner;
use crate::algos::hyper::RunConfig;
use crate::algos::learner::SavedNets;
use crate::algos::method::{Family, Method};
use crate::algos::training_loop::{Advance, EvalPoint, RunRngs, TrainError, TrainingLoop};
use crate::algos::value::learner::ValueLearner;
use crate::envs::{AnyEnv, EnvError, MacroEnv};
use serde::{Deserialize, Serialize};

/// The training loop of one run, by family. Each method is one `match` on the family.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(bound(serialize = "E: Serialize"))]
#[serde(bound(deserialize = "E: serde::de::DeserializeOwned"))]
pub enum AnyLoop<E = AnyEnv> {
    /// The ICRA 2020 Q-learning methods.
    Value(Box<TrainingLoop<ValueLearner, E>>),
    /// MacroMARL's actor-critic methods.
    ActorCritic(Box<TrainingLoop<AcLearner, E>>),
}

/// Forward a method call to the family's loop.
macro_rules! dispatch {
    ($self:expr, $l:ident => $call:expr) => {
        match $self {
            AnyLoop::Value($l) => $call,
            AnyLoop::ActorCritic($l) => $call,
        }
    };
}

impl<E: MacroEnv> AnyLoop<E> {
    /// Build the loop of `method`'s family (see [`TrainingLoop::new`]).
    pub fn new(
        config: &RunConfig,
        method: Method,
        seed: u64,
        rngs: RunRngs,
        make_env: impl Fn() -> Result<E, EnvError>,
    ) -> Result<Self, TrainError> {
        Ok(match method.family() {
            Family::Value => AnyLoop::Value(Box::new(TrainingLoop::new(
                config, method, seed, rngs, make_env,
            )?)),
            Family::ActorCritic => AnyLoop::ActorCritic(Box::new(TrainingLoop::new(
                config, method, seed, rngs, make_env,
            )?)),
        })
    }

    /// Run until a training episode finishes or training is complete.
    pub fn advance(&mut self) -> Result<Advance, TrainError> {
        dispatch!(self, l => l.advance())
    }
    /// The run's configuration.
    pub fn config(&self) -> &RunConfig {
        dispatch!(self, l => l.config())
    }
    /// The method being trained.
    pub fn method(&self) -> Method {
        dispatch!(self, l => l.method())
    }
    /// The run's seed.
    pub fn seed(&self) -> u64 {
        dispatch!(self, l => l.seed())
    }
    /// Completed training episodes.
    pub fn episodes(&self) -> u64 {
        dispatch!(self, l => l.episodes())
    }
    /// Primitive steps taken by the training env(s).
    pub fn env_steps(&self) -> u64 {
        dispatch!(self, l => l.env_steps())
    }
    /// Training iterations run.
    pub fn updates(&self) -> u64 {
        dispatch!(self, l => l.updates())
    }
    /// Every evaluation so far, in order.
    pub fn evals(&self) -> &[EvalPoint] {
        dispatch!(self, l => l.evals())
    }
    /// The family's own metrics columns.
    pub fn metric_columns(&self) -> &'static [&'static str] {
        dispatch!(self, l => l.metric_columns())
    }
    /// A few words of training state for progress lines.
    pub fn progress(&self) -> String {
        dispatch!(self, l => l.progress())
    }
    /// The nets the run saves as policy files.
    pub fn saved_nets(&self) -> SavedNets<'_> {
        dispatch!(self, l => l.saved_nets())
    }
    /// Fold the running segment's time into the saved total (call before checkpointing).
    pub fn mark_time(&mut self) {
        dispatch!(self, l => l.mark_time())
    }
    /// Whether training is complete.
    pub fn is_finished(&self) -> bool {
        dispatch!(self, l => l.is_finished())
    }
}
