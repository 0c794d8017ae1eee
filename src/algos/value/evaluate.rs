//! Greedy evaluation (`docs/ALGORITHMS.md` §7.1): the learned policies on a separate env copy, no
//! exploration, hidden state carried through the episode, return discounted per primitive step.

use crate::algos::learner::EvalReturns;
use crate::algos::value::acting::{select_cen, select_dec, ActScratch};
use crate::envs::{EnvError, EnvRng, MacroEnv};
use crate::nn::{LstmState, QNet};

/// Which nets act greedily: the decentralized ones (every method but Cen-DDRQN) or the
/// centralized one with the conditional argmax (Cen-DDRQN).
#[derive(Clone, Copy)]
pub enum GreedyPolicy<'a> {
    /// Each agent's decentralized net, in agent order.
    Dec(&'a [&'a QNet]),
    /// The centralized net, acting through the conditional argmax.
    Cen(&'a QNet),
}

/// One greedy episode from reset to done. Returns sum_k gamma^k r_{k+1} over primitive steps
/// (quirks Q5, Q13) and calls `on_step` after every step (for renders and trajectories).
pub fn greedy_episode<E: MacroEnv + ?Sized>(
    env: &mut E,
    policy: GreedyPolicy<'_>,
    discount: f64,
    rng: &mut EnvRng,
    mut on_step: impl FnMut(&E, &[usize], f64),
) -> Result<f64, EnvError> {
    env.reset(rng);
    let mut scratch = ActScratch::new(env);
    let mut actions = vec![0usize; env.n_agents()];
    let mut actor = GreedyActor::new(policy);
    let mut ret = 0.0;
    let mut weight = 1.0;
    loop {
        actor.choose(&*env, &mut scratch, &mut actions);
        let out = env.step(&actions, rng)?;
        ret += weight * out.reward;
        weight *= discount;
        on_step(env, &actions, out.reward);
        if out.done {
            return Ok(ret);
        }
    }
}

/// A greedy policy with its hidden state(s), stepped one primitive step at a time.
pub enum GreedyActor<'a> {
    /// Each agent's net and its hidden state.
    Dec(&'a [&'a QNet], Vec<LstmState>),
    /// The centralized net and its hidden state.
    Cen(&'a QNet, LstmState),
}

impl<'a> GreedyActor<'a> {
    /// Fresh (zero) hidden states, as at the start of an episode.
    pub fn new(policy: GreedyPolicy<'a>) -> Self {
        match policy {
            GreedyPolicy::Dec(nets) => {
                GreedyActor::Dec(nets, nets.iter().map(|n| n.zero_state()).collect())
            }
            GreedyPolicy::Cen(net) => GreedyActor::Cen(net, net.zero_state()),
        }
    }

    /// Fill the free agents' entries of `actions` greedily.
    pub fn choose<E: MacroEnv + ?Sized>(
        &mut self,
        env: &E,
        scratch: &mut ActScratch,
        actions: &mut [usize],
    ) {
        match self {
            GreedyActor::Dec(nets, states) => select_dec(env, nets, states, None, actions),
            GreedyActor::Cen(net, state) => select_cen(env, net, state, None, scratch, actions),
        }
    }
}

/// Mean greedy returns over `episodes` episodes. When the env draws no random numbers the
/// episodes are identical (`docs/ALGORITHMS.md` §7.1), so one is run and its returns used for
/// all.
pub fn evaluate<E: MacroEnv + ?Sized>(
    env: &mut E,
    policy: GreedyPolicy<'_>,
    discount: f64,
    episodes: usize,
    deterministic: bool,
    rng: &mut EnvRng,
) -> Result<EvalReturns, EnvError> {
    let runs = if deterministic { 1 } else { episodes.max(1) };
    let mut discounted = 0.0;
    let mut undiscounted = 0.0;
    for _ in 0..runs {
        let mut plain = 0.0;
        discounted += greedy_episode(env, policy, discount, rng, |_, _, r| plain += r)?;
        undiscounted += plain;
    }
    Ok(EvalReturns {
        discounted: discounted / runs as f64,
        undiscounted: undiscounted / runs as f64,
    })
}
