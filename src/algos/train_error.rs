//! Why a training loop stopped early: what the loop, the environments and a learner can fail with.

use crate::algos::method::Method;
use crate::algos::value::update::UpdateError;
use crate::algos::value::ReplayError;
use crate::envs::EnvError;

impl TrainError {
    /// A non-finite loss or parameter of `method`'s run `seed` at `episode`.
    pub fn non_finite(method: Method, seed: u64, what: &'static str, episode: u64) -> Self {
        TrainError::NonFinite {
            method,
            seed,
            what,
            episode,
        }
    }
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
    #[error("{0}")]
    Nets(String),
    #[error("{method}: the config holds another method family's keys")]
    WrongFamily { method: Method },
    #[error("{method} asks for {asked} training lanes; runs have random streams for {available}")]
    TooManyLanes {
        method: Method,
        asked: usize,
        available: usize,
    },
}
