//! The net a decentralized agent acts with, whichever family trained it: the ICRA methods'
//! recurrent Q-net ([`QNet`], scores = Q-values), MacroMARL's actor ([`GruActor`], scores =
//! log-probabilities) or ACAC's ([`TimedAcacActor`], log-probabilities). All are stepped one
//! macro-observation at a time with a carried recurrent state, and the greedy macro-action is
//! the highest score, so evaluation, robots and deploy run any of them without knowing which.
//! ACAC's actor also reads when the observation was made (the episode's primitive step, for its
//! time embedding): every caller passes the step, and [`ActingNet::reads_step`] says whether a
//! net uses it, so a robot can refuse an observation sent without one.

use super::acac_actor::{AcacActor, AcacActorState, TimedAcacActor};
use super::gru_actor::{GruActor, GruActorState};
use super::lstm::LstmState;
use super::qnet::QNet;
use super::time_embedding::TimeEmbedding;

/// A decentralized agent's net.
#[derive(Debug, Clone, PartialEq)]
pub enum ActingNet {
    /// Q-values (the ICRA methods' DDRQN).
    Q(QNet),
    /// Log-probabilities (MacroMARL's actors).
    Actor(GruActor),
    /// Log-probabilities of ACAC's actor, which reads the time too.
    Acac(TimedAcacActor),
}

/// An [`ActingNet`] borrowed from whoever owns it: how a learner hands its nets over to be saved
/// (at every checkpoint) without copying them, Q-net or actor alike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ActingNetRef<'a> {
    /// A Q-net.
    Q(&'a QNet),
    /// An actor.
    Actor(&'a GruActor),
    /// An ACAC actor and the time table it reads (held once by its learner for all agents).
    Acac(&'a AcacActor, Option<&'a TimeEmbedding>),
}

impl ActingNetRef<'_> {
    /// An owned copy, for a caller that keeps the net after its owner is gone.
    pub fn to_net(self) -> ActingNet {
        match self {
            ActingNetRef::Q(q) => ActingNet::Q(q.clone()),
            ActingNetRef::Actor(a) => ActingNet::Actor(a.clone()),
            ActingNetRef::Acac(actor, time) => ActingNet::Acac(TimedAcacActor {
                actor: actor.clone(),
                time: time.cloned(),
            }),
        }
    }
}

/// The recurrent state an [`ActingNet`] carries between an agent's decisions.
#[derive(Debug, Clone, PartialEq)]
pub enum ActingState {
    /// A Q-net's LSTM state.
    Lstm(LstmState),
    /// An actor's GRU state.
    Gru(GruActorState),
    /// An ACAC actor's GRU state.
    Acac(AcacActorState),
}

impl ActingNet {
    /// Length of the observation it reads.
    pub fn obs_len(&self) -> usize {
        match self {
            ActingNet::Q(q) => q.config().input,
            ActingNet::Actor(a) => a.config().input,
            ActingNet::Acac(a) => a.obs_len(),
        }
    }

    /// Number of macro-actions it scores.
    pub fn n_actions(&self) -> usize {
        match self {
            ActingNet::Q(q) => q.config().output,
            ActingNet::Actor(a) => a.config().output,
            ActingNet::Acac(a) => a.n_actions(),
        }
    }

    /// The Q-net, if it is one.
    pub fn as_q(&self) -> Option<&QNet> {
        match self {
            ActingNet::Q(q) => Some(q),
            ActingNet::Actor(_) | ActingNet::Acac(_) => None,
        }
    }

    /// What its scores are, for messages: "Q-values" or "log-probabilities".
    pub fn scores(&self) -> &'static str {
        match self {
            ActingNet::Q(_) => "Q-values",
            ActingNet::Actor(_) | ActingNet::Acac(_) => "log-probabilities",
        }
    }

    /// The zero state of an episode's start.
    pub fn zero_state(&self) -> ActingState {
        match self {
            ActingNet::Q(q) => ActingState::Lstm(q.zero_state()),
            ActingNet::Actor(a) => ActingState::Gru(a.zero_state()),
            ActingNet::Acac(a) => ActingState::Acac(a.actor.zero_state()),
        }
    }

    /// Whether the net reads when an observation was made (ACAC's time embedding): a caller
    /// that does not know the step must not use it.
    pub fn reads_step(&self) -> bool {
        match self {
            ActingNet::Acac(a) => a.time.is_some(),
            ActingNet::Q(_) | ActingNet::Actor(_) => false,
        }
    }

    /// One decision: the scores of every macro-action for `x`, an observation made after `step`
    /// primitive steps of the episode (read only if [`Self::reads_step`]), advancing `state`.
    /// Panics if x or the state do not belong to this net.
    pub fn act_step<'s>(&self, x: &[f32], step: usize, state: &'s mut ActingState) -> &'s [f32] {
        match (self, state) {
            (ActingNet::Q(q), ActingState::Lstm(s)) => q.act_step(x, s),
            (ActingNet::Actor(a), ActingState::Gru(s)) => a.act_step(x, s),
            (ActingNet::Acac(a), ActingState::Acac(s)) => a.act_step(x, step, s),
            _ => panic!("act_step: the state belongs to another kind of net"),
        }
    }
}

impl ActingState {
    /// Back to the zero state.
    pub fn reset(&mut self) {
        match self {
            ActingState::Lstm(s) => s.reset(),
            ActingState::Gru(s) => s.reset(),
            ActingState::Acac(s) => s.reset(),
        }
    }

    /// Copy `other` into `self` (same net). Panics if they belong to different kinds of net.
    pub fn copy_from(&mut self, other: &ActingState) {
        match (self, other) {
            (ActingState::Lstm(a), ActingState::Lstm(b)) => a.copy_from(b),
            (ActingState::Gru(a), ActingState::Gru(b)) => a.copy_from(b),
            (ActingState::Acac(a), ActingState::Acac(b)) => a.copy_from(b),
            _ => panic!("copy_from: states of different kinds of net"),
        }
    }

    /// Whether every value of the recurrent state is finite.
    pub fn is_finite(&self) -> bool {
        let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
        match self {
            ActingState::Lstm(s) => finite(s.h()) && finite(s.c()),
            ActingState::Gru(s) => finite(s.h()),
            ActingState::Acac(s) => finite(s.h()),
        }
    }
}
