//! The value-based family (ICRA 2020, `docs/ALGORITHMS.md`): the five macro-action Q-learning
//! methods. [`learner::ValueLearner`] is the family's [`crate::algos::learner::Learner`]; the
//! rest is its machinery, in data-flow order.
//!
//! Flow: [`recorder::Recorder`] turns every primitive step into a [`record::Episode`] row (spec
//! 1.2); a finished episode goes into a [`replay::ReplayBuffer`] (windows for Box Pushing, whole
//! episodes for Warehouse, `docs/ALGORITHMS.md` §3.1/3.2); a sampled [`replay::Batch`] is squeezed by [`squeeze`]
//! into each agent's macro-level sequences and the joint one (`docs/ALGORITHMS.md` §3.3); [`update`] computes the
//! targets and takes the Adam steps; [`cond_argmax`] picks joint actions under the conditioning
//! of busy agents (`docs/ALGORITHMS.md` §4.5); [`acting`] and [`evaluate`] turn Q-values into actions; [`schedule`]
//! gives epsilon and the hysteresis value from the episode count (`docs/ALGORITHMS.md` §4.1, 5.6).

pub mod acting;
pub mod batch;
pub mod cond_argmax;
pub mod config;
pub mod episode_buffer;
pub mod evaluate;
pub mod family;
pub mod learner;
pub mod method;
pub mod published;
pub mod record;
pub mod recorder;
pub mod replay;
pub mod schedule;
pub mod squeeze;
pub mod update;
pub mod window_buffer;

/// Why a record, an episode, a buffer or a squeeze request was refused. Messages name the
/// offending quantity and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReplayError {
    /// A vector of the wrong length.
    #[error("{what}: expected length {expected}, got {got}")]
    WrongLength {
        /// Which vector (e.g. `obs`).
        what: &'static str,
        /// The length the layout needs.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// An episode with no record was pushed.
    #[error("an episode must hold at least one record")]
    EmptyEpisode,
    /// A sample was asked of an empty buffer.
    #[error("cannot sample from an empty replay buffer")]
    EmptyBuffer,
    /// A count that must be positive was 0.
    #[error("`{name}` must be > 0")]
    Zero {
        /// Its name.
        name: &'static str,
    },
    /// An agent index beyond the layout.
    #[error("agent {agent} is out of range 0..{n_agents}")]
    AgentOutOfRange {
        /// The index given.
        agent: usize,
        /// Agents in the layout.
        n_agents: usize,
    },
    /// An executed macro-action beyond the agent's action count.
    #[error("agent {agent}: executed macro-action {action} is out of range 0..{n_actions}")]
    ActionOutOfRange {
        /// The agent.
        agent: usize,
        /// The macro-action recorded.
        action: usize,
        /// Macro-actions the agent has.
        n_actions: usize,
    },
    /// An episode recorded with another domain's layout.
    #[error("episode shape ({n_agents} agents, joint observation {joint_obs}) does not match the layout ({expected_agents} agents, joint observation {expected_obs})")]
    LayoutMismatch {
        /// The episode's agents.
        n_agents: usize,
        /// The episode's joint observation length.
        joint_obs: usize,
        /// The buffer's agents.
        expected_agents: usize,
        /// The buffer's joint observation length.
        expected_obs: usize,
    },
    /// A step was recorded before `begin`.
    #[error("step recorded before the episode started (call `begin` after every env reset)")]
    EpisodeNotStarted,
    /// A restored buffer state that disagrees with itself; the text says what.
    #[error("inconsistent replay state: {0}")]
    Corrupt(String),
}

/// The value family's errors reach the training loop as [`crate::algos::train_error::TrainError::Family`].
impl From<ReplayError> for crate::algos::train_error::TrainError {
    fn from(e: ReplayError) -> Self {
        crate::algos::train_error::TrainError::Family(Box::new(e))
    }
}

impl From<update::UpdateError> for crate::algos::train_error::TrainError {
    fn from(e: update::UpdateError) -> Self {
        crate::algos::train_error::TrainError::Family(Box::new(e))
    }
}
