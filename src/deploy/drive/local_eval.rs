//! `macdec eval` (issue 12): greedy episodes of a policy directory in this process. The same
//! driver loop as `macdec deploy` ([`run_episodes_with`]) with each robot replaced by an
//! in-process link to the same Q-net ([`LocalLink`] over [`NetPolicy`]), so for the same policy
//! and seed it gives exactly deploy's episodes, without starting a process or opening a socket.
//! Actor policies can also be evaluated as MacroMARL does, sampling each macro-action from the
//! actor's distribution ([`Choice::Sampled`]; each agent draws from its own stream of the seed).

use crate::deploy::drive::driver::{run_episodes_with, DeployError, EpisodeTrace};
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
                    return Err(PolicyError::NotAnActor { agent: v.index })
                }
                Choice::Sampled => Some(sampler(rng, SAMPLING_STREAMS + i as u64)),
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

/// Run `episodes` episodes of the manifest's domain on one random stream (`rng`, the caller's
/// choice of seed; deploy uses the evaluation stream of the run's seed), each agent choosing by
/// `choice`, handing each episode to `on_episode` as it ends.
pub fn eval_policy(
    manifest: &Manifest,
    verified: &[VerifiedAgent],
    episodes: usize,
    choice: Choice,
    rng: &mut EnvRng,
    on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    let mut env = manifest
        .env
        .build()
        .map_err(|e| DeployError::Policy(e.to_string()))?;
    let mut links = local_links(manifest, verified, choice, rng)
        .map_err(|e| DeployError::Policy(e.to_string()))?;
    run_episodes_with(
        &mut env,
        &mut links,
        manifest.discount,
        episodes,
        rng,
        on_episode,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy_files::load_all;
    use rand::SeedableRng;

    #[test]
    fn a_callback_error_stops_the_run() {
        let spec = crate::envs::box_pushing::spec(10, 100);
        let dir = tempfile::tempdir().unwrap();
        crate::deploy::policy::mock::write_mock_policy(dir.path(), spec).unwrap();
        let (manifest, verified) = load_all(dir.path()).unwrap();
        let mut calls = 0;
        let err = eval_policy(
            &manifest,
            &verified,
            5,
            Choice::Greedy,
            &mut EnvRng::seed_from_u64(0),
            |_| {
                calls += 1;
                Err(DeployError::Policy("stdout closed".into()))
            },
        )
        .unwrap_err();
        assert_eq!(calls, 1);
        assert!(err.to_string().contains("stdout closed"), "{err}");
    }
}
