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
pub mod episode_buffer;
pub mod evaluate;
pub mod learner;
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
    #[error("{what}: expected length {expected}, got {got}")]
    WrongLength {
        what: &'static str,
        expected: usize,
        got: usize,
    },
    #[error("an episode must hold at least one record")]
    EmptyEpisode,
    #[error("cannot sample from an empty replay buffer")]
    EmptyBuffer,
    #[error("`{name}` must be > 0")]
    Zero { name: &'static str },
    #[error("agent {agent} is out of range 0..{n_agents}")]
    AgentOutOfRange { agent: usize, n_agents: usize },
    #[error("agent {agent}: executed macro-action {action} is out of range 0..{n_actions}")]
    ActionOutOfRange {
        agent: usize,
        action: usize,
        n_actions: usize,
    },
    #[error("episode shape ({n_agents} agents, joint observation {joint_obs}) does not match the layout ({expected_agents} agents, joint observation {expected_obs})")]
    LayoutMismatch {
        n_agents: usize,
        joint_obs: usize,
        expected_agents: usize,
        expected_obs: usize,
    },
    #[error("step recorded before the episode started (call `begin` after every env reset)")]
    EpisodeNotStarted,
    #[error("inconsistent replay state: {0}")]
    Corrupt(String),
}
