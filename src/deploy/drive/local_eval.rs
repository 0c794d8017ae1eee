//! The agents of `macdec eval` (issue 12): each robot of `macdec deploy` replaced by an
//! in-process link to the same net ([`LocalLink`] over [`NetPolicy`]), so for the same policy
//! and seed eval gives exactly deploy's episodes, without starting a process or opening a
//! socket ([`crate::deploy::drive::team`] plays them). Actor policies can also be evaluated as
//! MacroMARL does, sampling each macro-action from the actor's distribution
//! ([`Choice::Sampled`]; each agent draws from its own stream of the seed, a team policy from
//! [`TEAM_STREAM`]).

use crate::deploy::drive::link::LocalLink;
use crate::deploy::policy::net_policy::{load_net, NetPolicy};
use crate::envs::EnvRng;
use crate::policy_files::{Manifest, PolicyError, VerifiedAgent};
use std::sync::Arc;

/// How each agent picks its macro-action from its net's scores.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// The highest score (greedy; Q-nets and actors alike).
    Greedy,
    /// A draw from the actor's distribution (its scores are log-probabilities).
    Sampled,
}

/// One in-process link per agent, each running that agent's verified net from a zero state;
/// with [`Choice::Sampled`], agent i draws from stream `i` of `rng`'s key (actors only).
pub fn local_links(
    manifest: &Manifest,
    verified: &[VerifiedAgent],
    choice: Choice,
    rng: &EnvRng,
) -> Result<Vec<LocalLink<NetPolicy>>, PolicyError> {
    verified
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let net = load_net(manifest, v)?;
            let sampler = match choice {
                Choice::Greedy => None,
                Choice::Sampled if net.as_q().is_some() => {
                    return Err(PolicyError::NotAnActor {
                        whose: format!("agent {}'s net", v.index),
                    })
                }
                Choice::Sampled => Some(agent_sampler(rng, i)),
            };
            Ok(LocalLink::with_sampler(
                NetPolicy::new(Arc::new(net)),
                sampler,
            ))
        })
        .collect()
}

/// Stream ids of the agents' sampling streams: clear of the evaluation env's own.
const SAMPLING_STREAMS: u64 = 1 << 33;

/// The stream agent `agent` samples its macro-actions from ([`Choice::Sampled`]): stream
/// `2^33 + agent` of `rng`'s key, from its start.
pub fn agent_sampler(rng: &EnvRng, agent: usize) -> EnvRng {
    sampler(rng, SAMPLING_STREAMS + agent as u64)
}

/// The stream a team policy (Mac-CAC's centralized actor) samples from: clear of the agents'.
pub const TEAM_STREAM: u64 = SAMPLING_STREAMS - 1;

/// Stream `id` of `rng`'s key, from its start: the draws of one sampler, independent of the
/// environment's and of every other sampler's.
pub fn sampler(rng: &EnvRng, id: u64) -> EnvRng {
    let mut s = rng.clone();
    s.set_stream(id);
    s.set_word_pos(0);
    s
}
