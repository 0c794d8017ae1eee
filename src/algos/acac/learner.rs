//! The ACAC family's learner as the training loop sees it.
//!
//! **Not implemented yet.** [`AcacLearner::new`] refuses every run with
//! [`AcacError::LearnerMissing`], so `macdec train --methods acac` fails before any step with a
//! message saying so; the type has no values, so nothing else can run. What exists of the
//! learner so far is its pure parts ([`super::gae`]); the nets are in `crate::nn`.

use serde::{Deserialize, Serialize};

use super::config::AcacConfig;
use super::error::AcacError;
use super::method::AcacMethod;
use crate::algos::learner::{
    EvalReturns, LanePlan, Learner, LearnerRngs, MethodName, SavedNets, Schedule,
};
use crate::algos::train_error::TrainError;
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};

/// The ACAC learner: no values exist until it is written (see the module docs).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum AcacLearner {}

/// A training lane of [`AcacLearner`] (none exist either).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum AcacLane {}

impl Learner for AcacLearner {
    type Lane = AcacLane;
    type Method = AcacMethod;
    type Config = AcacConfig;

    /// Always [`AcacError::LearnerMissing`].
    fn new<E: MacroEnv>(
        _config: &AcacConfig,
        method: AcacMethod,
        _seed: u64,
        _env: &E,
        _rngs: LearnerRngs,
    ) -> Result<Self, TrainError> {
        Err(TrainError::Family(Box::new(AcacError::LearnerMissing {
            method: method.name(),
        })))
    }

    fn method(&self) -> AcacMethod {
        match *self {}
    }
    fn seed(&self) -> u64 {
        match *self {}
    }
    fn config(&self) -> &AcacConfig {
        match *self {}
    }
    fn schedule(&self) -> Schedule {
        match *self {}
    }
    fn lanes(&self) -> Vec<LanePlan> {
        match *self {}
    }
    fn begin_lane<E: MacroEnv>(&self, _lane: usize, _env: &E) -> Result<AcacLane, TrainError> {
        match *self {}
    }
    fn act<E: MacroEnv>(&mut self, _lane: &mut AcacLane, _env: &E, _actions: &mut [usize]) {
        match *self {}
    }
    fn record<E: MacroEnv>(
        &mut self,
        _lane: &mut AcacLane,
        _env: &E,
        _outcome: StepOutcome,
    ) -> Result<bool, TrainError> {
        match *self {}
    }
    fn begin_episode<E: MacroEnv>(&self, _lane: &mut AcacLane, _env: &E) -> Result<(), TrainError> {
        match *self {}
    }
    fn train_iteration(&mut self, _lanes: &[&AcacLane], _episodes: u64) -> Result<(), TrainError> {
        match *self {}
    }
    fn sync_targets(&mut self) {
        match *self {}
    }
    fn evaluate<E: MacroEnv>(
        &self,
        _env: &mut E,
        _rng: &mut EnvRng,
    ) -> Result<EvalReturns, EnvError> {
        match *self {}
    }
    fn metric_columns(&self) -> &'static [&'static str] {
        match *self {}
    }
    fn metric_values(&mut self) -> Vec<Option<f64>> {
        match *self {}
    }
    fn progress(&self) -> String {
        match *self {}
    }
    fn saved_nets(&self) -> SavedNets<'_> {
        match *self {}
    }
}
