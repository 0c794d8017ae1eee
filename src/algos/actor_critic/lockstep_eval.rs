//! The evaluation loop of MacroMARL's actor-critic runner (P8), which ACAC's runner keeps: every
//! lane resets, the lanes step in lockstep, a lane whose episode ends records it and starts the
//! next one at once with its actors' states zeroed, until enough episodes completed. The
//! methods differ only in how they choose (the caller's closure) and in which of the completed
//! episodes they average (the caller's window over the returned list).

use super::episode::EpisodeRecorder;
use crate::algos::learner::EvalReturns;
use crate::envs::{EnvError, EnvRng, MacroEnv};
use crate::nn::{AcacActorState, GruActorState};

/// An actor's recurrent state, zeroed when its lane's episode ends.
pub trait ActorState {
    /// Zero the state (a new episode).
    fn reset(&mut self);
}

impl ActorState for GruActorState {
    fn reset(&mut self) {
        GruActorState::reset(self)
    }
}

impl ActorState for AcacActorState {
    fn reset(&mut self) {
        AcacActorState::reset(self)
    }
}

/// Every episode the lanes completed, in the order they completed, stepping until at least
/// `episodes` did (the last sweep over the lanes may complete more). `choose(env, free, states,
/// rng, actions)` writes the free agents' macro-actions for one lane (busy agents' entries are
/// the caller's to fill, as the learners' `choose` does); `zero_states()` gives one lane's
/// actor states at an episode's start.
pub fn lockstep_episodes<E: MacroEnv, S: ActorState>(
    envs: &mut [&mut E],
    gamma: f64,
    episodes: usize,
    rng: &mut EnvRng,
    zero_states: impl Fn() -> Vec<S>,
    mut choose: impl FnMut(&E, &[bool], &mut [S], &mut EnvRng, &mut [usize]),
) -> Result<Vec<EvalReturns>, EnvError> {
    let mut recorders = Vec::with_capacity(envs.len());
    let mut states = Vec::with_capacity(envs.len());
    for e in envs.iter_mut() {
        e.reset(rng);
        recorders.push(EpisodeRecorder::new(&**e, gamma, false));
        states.push(zero_states());
    }
    let mut returns = Vec::new();
    let mut actions = vec![0; envs[0].n_agents()];
    while returns.len() < episodes {
        for k in 0..envs.len() {
            choose(
                &*envs[k],
                recorders[k].free(),
                &mut states[k],
                rng,
                &mut actions,
            );
            let outcome = envs[k].step(&actions, rng)?;
            recorders[k].record(&*envs[k], outcome);
            if outcome.done {
                returns.push(recorders[k].returns());
                envs[k].reset(rng);
                recorders[k].begin(&*envs[k]);
                states[k].iter_mut().for_each(ActorState::reset);
            }
        }
    }
    Ok(returns)
}
