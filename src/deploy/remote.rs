//! `macdec domain` (issue 14): the domain runs here and its robots are already running elsewhere,
//! each reachable at its own address and speaking the robot protocol ([`crate::deploy::protocol`]):
//! `macdec robot --listen` on a real robot, or a bridge that forwards every message to a robot's
//! ROS node (`ros/macdec_domain_node.py`). The same handshake ([`JsonLink::connect`] checks each
//! robot's agent and manifest) and the same driver loop as `macdec deploy`, so for the same policy
//! and seed it prints exactly `deploy`'s and `eval`'s episode lines.

use crate::deploy::driver::{run_episodes_with, DeployError, EpisodeTrace};
use crate::deploy::link::JsonLink;
use crate::deploy::manifest::Manifest;
use crate::envs::EnvRng;
use std::net::SocketAddr;
use std::time::Duration;

/// Connect to one robot per agent of `manifest` (`robots[i]` serves agent i), check each one's
/// `info`, and run `episodes` greedy episodes of the manifest's domain on `rng`, handing each
/// episode to `on_episode` as it ends. `timeout` bounds the connection and every reply.
pub fn run_with_robots_at(
    manifest: &Manifest,
    robots: &[SocketAddr],
    episodes: usize,
    rng: &mut EnvRng,
    timeout: Duration,
    on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    let n = manifest.agents.len();
    if robots.len() != n {
        return Err(DeployError::RobotCount {
            expected: n,
            got: robots.len(),
        });
    }
    let mut env = manifest
        .env
        .build()
        .map_err(|e| DeployError::Policy(e.to_string()))?;
    let mut links = robots
        .iter()
        .enumerate()
        .map(|(agent, &addr)| {
            JsonLink::connect(addr, agent, manifest, timeout)
                .map_err(|source| DeployError::Link { agent, source })
        })
        .collect::<Result<Vec<_>, _>>()?;
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
    use crate::deploy::link::LocalLink;
    use crate::deploy::mock::{mock_manifest, mock_policies, MockPolicy};
    use crate::deploy::robot::RobotSpec;
    use crate::deploy::run_episodes;
    use crate::deploy::server::{spawn_server, Limits, PolicyFactory, RobotServer};
    use crate::deploy::AgentPolicy;
    use crate::envs::EnvSpec;
    use rand::SeedableRng;
    use std::net::TcpListener;
    use std::sync::Arc;

    /// A robot server thread serving agent `agent` of `manifest` with a mock policy salted
    /// `salt` (the agent's own salt is its index).
    fn robot(manifest: &Manifest, agent: usize, salt: u64) -> RobotServer {
        let a = &manifest.agents[agent];
        let (obs, n) = (a.obs_size, a.n_actions);
        let factory: PolicyFactory =
            Arc::new(move || Box::new(MockPolicy::new(obs, n, salt)) as Box<dyn AgentPolicy>);
        let spec = Arc::new(RobotSpec::new(manifest, agent).unwrap());
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        spawn_server(listener, factory, spec, Limits::default()).unwrap()
    }

    fn spec() -> EnvSpec {
        EnvSpec::Warehouse {
            horizon: 150,
            tb_m_noisy: 0.3,
        }
    }

    #[test]
    fn robots_at_addresses_give_the_in_process_episodes() {
        let manifest = mock_manifest(spec());
        let servers: Vec<RobotServer> = (0..manifest.agents.len())
            .map(|i| robot(&manifest, i, i as u64))
            .collect();
        let addrs: Vec<SocketAddr> = servers.iter().map(|s| s.local_addr()).collect();
        let mut remote = Vec::new();
        run_with_robots_at(
            &manifest,
            &addrs,
            2,
            &mut EnvRng::seed_from_u64(5),
            Duration::from_secs(20),
            |t| {
                remote.push(t);
                Ok(())
            },
        )
        .unwrap();
        let mut local: Vec<LocalLink<MockPolicy>> = mock_policies(&manifest)
            .into_iter()
            .map(LocalLink::new)
            .collect();
        let mut env = spec().build().unwrap();
        let expected = run_episodes(
            &mut env,
            &mut local,
            manifest.discount,
            2,
            &mut EnvRng::seed_from_u64(5),
        )
        .unwrap();
        assert_eq!(remote, expected);
        assert!(remote[0].steps > 1);
    }

    #[test]
    fn robots_in_the_wrong_order_or_number_are_refused_by_name() {
        let manifest = mock_manifest(spec());
        let servers: Vec<RobotServer> = (0..manifest.agents.len())
            .map(|i| robot(&manifest, i, i as u64))
            .collect();
        let mut addrs: Vec<SocketAddr> = servers.iter().map(|s| s.local_addr()).collect();
        let run = |addrs: &[SocketAddr]| {
            run_with_robots_at(
                &manifest,
                addrs,
                1,
                &mut EnvRng::seed_from_u64(0),
                Duration::from_secs(20),
                |_| Ok(()),
            )
            .unwrap_err()
            .to_string()
        };
        let err = run(&addrs[..2]);
        assert_eq!(err, "the domain has 3 agents but 2 robots were given");
        addrs.swap(0, 1);
        let err = run(&addrs);
        assert!(
            err.starts_with("robot of agent 0: ") && err.contains("serves agent 1"),
            "{err}"
        );
    }
}
