//! `macdec eval` (issue 12): greedy episodes of a policy directory in this process. The same
//! driver loop as `macdec deploy` ([`run_episodes_with`]) with each robot replaced by an
//! in-process link to the same Q-net ([`LocalLink`] over [`NetPolicy`]), so for the same policy
//! and seed it gives exactly deploy's episodes, without starting a process or opening a socket.

use crate::deploy::driver::{run_episodes_with, DeployError, EpisodeTrace};
use crate::deploy::link::LocalLink;
use crate::deploy::net_policy::{load_net, NetPolicy};
use crate::envs::EnvRng;
use crate::policy_files::{Manifest, PolicyError, VerifiedAgent};
use std::sync::Arc;

/// One in-process link per agent, each running that agent's verified net from a zero state.
pub fn local_links(
    manifest: &Manifest,
    verified: &[VerifiedAgent],
) -> Result<Vec<LocalLink<NetPolicy>>, PolicyError> {
    verified
        .iter()
        .map(|v| {
            let net = load_net(manifest, v)?;
            Ok(LocalLink::new(NetPolicy::new(Arc::new(net))))
        })
        .collect()
}

/// Run `episodes` greedy episodes of the manifest's domain on one random stream (`rng`, the
/// caller's choice of seed; deploy uses the evaluation stream of the run's seed), handing each
/// to `on_episode` as it ends.
pub fn eval_policy(
    manifest: &Manifest,
    verified: &[VerifiedAgent],
    episodes: usize,
    rng: &mut EnvRng,
    on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    let mut env = manifest
        .env
        .build()
        .map_err(|e| DeployError::Policy(e.to_string()))?;
    let mut links =
        local_links(manifest, verified).map_err(|e| DeployError::Policy(e.to_string()))?;
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
        crate::deploy::mock::write_mock_policy(dir.path(), spec).unwrap();
        let (manifest, verified) = load_all(dir.path()).unwrap();
        let mut calls = 0;
        let err = eval_policy(
            &manifest,
            &verified,
            5,
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
