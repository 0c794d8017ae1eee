//! Why a training loop stopped early: what the loop, the environments and a learner can fail with.

use crate::envs::EnvError;

impl TrainError {
    /// A non-finite loss or parameter of `method`'s run `seed` at `episode`.
    pub fn non_finite(method: &'static str, seed: u64, what: &'static str, episode: u64) -> Self {
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
    /// An environment refused a step or reset.
    #[error(transparent)]
    Env(#[from] EnvError),
    /// A family's own machinery failed (a replay buffer refused a record, an update failed);
    /// the family's error says what.
    #[error(transparent)]
    Family(Box<dyn std::error::Error + Send + Sync>),
    /// A loss or parameter became NaN or infinite.
    #[error("{method} seed {seed}: non-finite {what} at episode {episode}")]
    NonFinite {
        /// The method trained (its command-line name).
        method: &'static str,
        /// The run's seed.
        seed: u64,
        /// `loss` or `parameter`.
        what: &'static str,
        /// Training episodes completed.
        episode: u64,
    },
    /// The method's nets cannot be built for the domain; the text says why.
    #[error("{0}")]
    Nets(String),
    /// The config is another family's.
    #[error("{method}: the config holds another method family's keys")]
    WrongFamily {
        /// The method asked for (its command-line name).
        method: &'static str,
    },
    /// More training lanes (parallel environments) than a run has random streams for.
    #[error("{method} asks for {asked} training lanes; runs have random streams for {available}")]
    TooManyLanes {
        /// The method (its command-line name).
        method: &'static str,
        /// Lanes the config asks for.
        asked: usize,
        /// The most lanes a run supports (`MAX_LANES`).
        available: usize,
    },
}
