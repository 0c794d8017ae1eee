//! `macdec domain` (issue 14): the domain runs here and its robots are already running elsewhere,
//! each reachable at its own address and speaking the robot protocol
//! ([`crate::deploy::serve::protocol`]): `macdec robot --listen` on a real robot, or a bridge that
//! forwards every message to a robot's ROS node (`ros/macdec_domain_node.py`). The same handshake
//! ([`JsonLink::connect`] checks each robot's agent and manifest) and the same driver loop as
//! `macdec deploy`, so for the same policy and seed it prints exactly `deploy`'s and `eval`'s
//! episode lines.

use crate::deploy::drive::driver::{run_episodes_with, DeployError, EpisodeTrace};
use crate::deploy::drive::link::JsonLink;
use crate::envs::EnvRng;
use crate::policy_files::Manifest;
use std::net::SocketAddr;
use std::time::Duration;

/// Connect to one robot per agent of `manifest` (`robots[i]` serves agent i), check each one's
/// `info`, and run `episodes` greedy episodes of the manifest's domain on `rng`, handing each
/// episode to `on_episode` as it ends. `timeout` bounds the connection and each reply as a whole,
/// counted from when its request is sent.
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
