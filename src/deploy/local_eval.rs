//! `macdec eval` (issue 12): greedy episodes of a policy directory in this process. The same
//! driver loop as `macdec deploy` ([`run_episodes_with`]) with each robot replaced by an
//! in-process link to the same Q-net ([`LocalLink`] over [`QNetPolicy`]), so for the same policy
//! and seed it gives exactly deploy's episodes, without starting a process or opening a socket.

use crate::deploy::driver::{run_episodes_with, DeployError, EpisodeTrace};
use crate::deploy::link::LocalLink;
use crate::deploy::manifest::{Manifest, ManifestError, VerifiedAgent};
use crate::deploy::qnet_policy::{load_net, QNetPolicy};
use crate::envs::EnvRng;
use std::sync::Arc;

/// One in-process link per agent, each running that agent's verified net from a zero state.
pub fn local_links(
    manifest: &Manifest,
    verified: &[VerifiedAgent],
) -> Result<Vec<LocalLink<QNetPolicy>>, ManifestError> {
    verified
        .iter()
        .map(|v| {
            let net = load_net(manifest, v)?;
            Ok(LocalLink::new(QNetPolicy::new(Arc::new(net))))
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
    use crate::algos::evaluate::{greedy_episode, GreedyPolicy};
    use crate::deploy::architecture::{synthetic_weights, Architecture};
    use crate::deploy::manifest::{load_all, RunInfo};
    use crate::envs::{EnvSpec, MacroEnv};
    use crate::nn::QNet;
    use rand::SeedableRng;

    /// Large pseudo-random weights, so greedy actions change along an episode.
    fn weights(env: &impl MacroEnv, arch: &Architecture) -> Vec<Vec<u8>> {
        (0..env.n_agents())
            .map(|i| {
                synthetic_weights(arch, env.obs_sizes()[i], env.n_actions()[i], |name, k| {
                    let mut h = (k as u64) ^ ((name.len() as u64) << 32) ^ ((i as u64) << 48);
                    for _ in 0..2 {
                        h = (h ^ (h >> 31)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                    }
                    ((h >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 3.0
                })
            })
            .collect()
    }

    #[test]
    fn eval_equals_in_process_greedy_evaluation_and_streams_every_episode() {
        let spec = EnvSpec::Warehouse {
            horizon: 150,
            tb_m_noisy: 0.3,
        };
        let mut env = spec.build().unwrap();
        let arch = Architecture::ddrqn(16, 8);
        let dir = tempfile::tempdir().unwrap();
        let run = RunInfo {
            experiment: "test".into(),
            method: "our1".into(),
            variant: String::new(),
            seed: 0,
            episodes_trained: 0,
            config: serde_json::Value::Null,
        };
        Manifest::write_policy(
            dir.path(),
            spec,
            1.0,
            arch,
            run,
            &weights(&env, &Architecture::ddrqn(16, 8)),
        )
        .unwrap();
        let (manifest, verified) = load_all(dir.path()).unwrap();

        let mut seen = Vec::new();
        eval_policy(
            &manifest,
            &verified,
            3,
            &mut EnvRng::seed_from_u64(9),
            |t| {
                seen.push(t);
                Ok(())
            },
        )
        .unwrap();
        assert_eq!(
            seen.iter().map(|t| t.episode).collect::<Vec<_>>(),
            [0, 1, 2]
        );

        let nets: Vec<QNet> = verified
            .iter()
            .map(|v| load_net(&manifest, v).unwrap())
            .collect();
        let refs: Vec<&QNet> = nets.iter().collect();
        let mut rng = EnvRng::seed_from_u64(9);
        let mut actions = std::collections::BTreeSet::new();
        for trace in &seen {
            let mut steps = Vec::new();
            let ret = greedy_episode(
                &mut env,
                GreedyPolicy::Dec(&refs),
                manifest.discount,
                &mut rng,
                |e, _, r| steps.push((e.executed().to_vec(), r)),
            )
            .unwrap();
            assert_eq!(trace.discounted_return, ret);
            let got: Vec<(Vec<usize>, f64)> = trace
                .trajectory
                .iter()
                .map(|s| (s.executed.clone(), s.reward))
                .collect();
            assert_eq!(got, steps);
            actions.extend(steps.into_iter().map(|(a, _)| a));
        }
        assert!(actions.len() > 1, "{actions:?}");
        // Noise makes the episodes of one stream differ: the stream runs on across episodes.
        assert_ne!(seen[0].trajectory, seen[1].trajectory);
    }

    #[test]
    fn a_callback_error_stops_the_run() {
        let spec = EnvSpec::BoxPushing {
            grid: 10,
            horizon: 100,
        };
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
