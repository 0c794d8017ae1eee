//! Decentralized execution of a domain: the environment runs here, and each agent's macro-action
//! comes from its own robot, which sees only that agent's macro-observation (issue 7). The loop
//! is the greedy evaluation episode of `docs/ALGORITHMS.md` §7.1 with the policy calls replaced by
//! messages, so over any transport it must give the same returns and trajectories as in-process
//! greedy evaluation of the same policy with the same seeds.

use crate::deploy::drive::link::{LinkError, RobotLink};
use crate::envs::{EnvError, EnvRng, MacroEnv};
use serde::{Deserialize, Serialize};

/// One primitive step of a deployed episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepRecord {
    /// Primitive steps since reset, after this step.
    pub t: usize,
    /// The macro-action each agent executed in this step.
    pub executed: Vec<usize>,
    /// The team reward of this step.
    pub reward: f64,
    /// Which agents finished their macro-action in this step.
    pub mac_done: Vec<bool>,
    /// The episode ended with this step.
    pub done: bool,
}

/// One deployed episode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpisodeTrace {
    /// Episode number, from 0.
    pub episode: usize,
    /// sum_k gamma^k r_{k+1} over primitive steps, as greedy evaluation reports it (quirks Q5,
    /// Q13).
    #[serde(rename = "return")]
    pub discounted_return: f64,
    /// Plain sum of the team rewards.
    pub undiscounted_return: f64,
    /// Primitive steps taken.
    pub steps: usize,
    /// Every step, in order (left out of the JSON when empty).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trajectory: Vec<StepRecord>,
}

/// Why a deployment stopped.
#[derive(Debug, thiserror::Error)]
pub enum DeployError {
    /// Not one robot per agent.
    #[error("the domain has {expected} agents but {got} robots were given")]
    RobotCount {
        /// Agents in the domain.
        expected: usize,
        /// Robots given.
        got: usize,
    },
    /// Talking to a robot failed.
    #[error("robot of agent {agent}: {source}")]
    Link {
        /// The robot's agent.
        agent: usize,
        /// What failed.
        #[source]
        source: LinkError,
    },
    /// The simulated environment refused a step.
    #[error("environment: {0}")]
    Env(#[from] EnvError),
    /// A robot process could not be started.
    #[error("starting the robot of agent {agent}: {reason}")]
    Spawn {
        /// The robot's agent.
        agent: usize,
        /// Why.
        reason: String,
    },
    /// The policy could not be loaded or does not fit; the text says why.
    #[error("policy: {0}")]
    Policy(String),
    /// An episode's result could not be written.
    #[error("writing an episode's result: {0}")]
    Output(#[from] std::io::Error),
}

/// Whoever picks the free agents' macro-actions in an episode: one robot per agent over its link
/// ([`Robots`]), or a team acting in this process
/// ([`crate::deploy::drive::team::Team`]). The episode loop ([`play_episode`]) is the same for
/// all, so `eval`'s episodes of a centralized policy are counted and reported as deploy's are.
pub trait TeamDecisions {
    /// A new episode (the environment was just reset): zero every hidden state.
    fn reset(&mut self) -> Result<(), DeployError>;
    /// Write each free agent's next macro-action into `actions`; busy agents' entries stay.
    fn decide<E: MacroEnv + ?Sized>(
        &mut self,
        env: &E,
        actions: &mut [usize],
    ) -> Result<(), DeployError>;
}

/// One robot per agent, in agent order: each gets its agent's observation, the primitive steps
/// taken so far and whether its macro-action just finished, every primitive step.
pub struct Robots<'a, L>(pub &'a mut [L]);

impl<L: RobotLink> TeamDecisions for Robots<'_, L> {
    fn reset(&mut self) -> Result<(), DeployError> {
        for (agent, robot) in self.0.iter_mut().enumerate() {
            robot
                .reset()
                .map_err(|source| DeployError::Link { agent, source })?;
        }
        Ok(())
    }

    fn decide<E: MacroEnv + ?Sized>(
        &mut self,
        env: &E,
        actions: &mut [usize],
    ) -> Result<(), DeployError> {
        for (agent, robot) in self.0.iter_mut().enumerate() {
            let free = env.is_free(agent);
            let chosen = robot
                .observe(env.obs(agent), env.t(), free)
                .map_err(|source| DeployError::Link { agent, source })?;
            if let Some(a) = chosen {
                actions[agent] = a;
            }
        }
        Ok(())
    }
}

/// Run one episode from reset to done. Every primitive step, each agent's robot gets that agent's
/// observation and whether its macro-action just finished (all agents after reset); the robots
/// of free agents answer with their next macro-action. Robots are reset first.
pub fn run_episode<E: MacroEnv + ?Sized, L: RobotLink>(
    env: &mut E,
    robots: &mut [L],
    discount: f64,
    rng: &mut EnvRng,
    episode: usize,
) -> Result<EpisodeTrace, DeployError> {
    check_robot_count(env, robots.len())?;
    play_episode(env, &mut Robots(robots), discount, rng, episode)
}

fn check_robot_count<E: MacroEnv + ?Sized>(env: &E, robots: usize) -> Result<(), DeployError> {
    if robots != env.n_agents() {
        return Err(DeployError::RobotCount {
            expected: env.n_agents(),
            got: robots,
        });
    }
    Ok(())
}

/// One episode from reset to done with `team` choosing: the environment is reset, then the
/// team; every primitive step the team decides, the environment steps and the step is recorded.
pub fn play_episode<E: MacroEnv + ?Sized, T: TeamDecisions>(
    env: &mut E,
    team: &mut T,
    discount: f64,
    rng: &mut EnvRng,
    episode: usize,
) -> Result<EpisodeTrace, DeployError> {
    env.reset(rng);
    team.reset()?;
    let mut actions = vec![0usize; env.n_agents()];
    let mut trajectory = Vec::new();
    let (mut discounted, mut undiscounted, mut weight) = (0.0, 0.0, 1.0);
    loop {
        team.decide(&*env, &mut actions)?;
        let out = env.step(&actions, rng)?;
        discounted += weight * out.reward;
        undiscounted += out.reward;
        weight *= discount;
        trajectory.push(StepRecord {
            t: env.t(),
            executed: env.executed().to_vec(),
            reward: out.reward,
            mac_done: env.mac_done().to_vec(),
            done: out.done,
        });
        if out.done {
            return Ok(EpisodeTrace {
                episode,
                discounted_return: discounted,
                undiscounted_return: undiscounted,
                steps: trajectory.len(),
                trajectory,
            });
        }
    }
}

/// Run `episodes` episodes in a row on one env and one random stream (episode k continues the
/// stream where episode k - 1 left it, as evaluation does).
pub fn run_episodes<E: MacroEnv + ?Sized, L: RobotLink>(
    env: &mut E,
    robots: &mut [L],
    discount: f64,
    episodes: usize,
    rng: &mut EnvRng,
) -> Result<Vec<EpisodeTrace>, DeployError> {
    let mut traces = Vec::with_capacity(episodes);
    run_episodes_with(env, robots, discount, episodes, rng, |trace| {
        traces.push(trace);
        Ok(())
    })?;
    Ok(traces)
}

/// [`run_episodes`], handing each episode to `on_episode` as soon as it ends (so a caller can
/// print it at once) instead of collecting them. An error from `on_episode` stops the run.
pub fn run_episodes_with<E: MacroEnv + ?Sized, L: RobotLink>(
    env: &mut E,
    robots: &mut [L],
    discount: f64,
    episodes: usize,
    rng: &mut EnvRng,
    on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    check_robot_count(env, robots.len())?;
    play_episodes_with(
        env,
        &mut Robots(robots),
        discount,
        episodes,
        rng,
        on_episode,
    )
}

/// [`run_episodes_with`] for any [`TeamDecisions`]: `episodes` episodes of [`play_episode`] in a
/// row on one random stream, each handed to `on_episode` as it ends.
pub fn play_episodes_with<E: MacroEnv + ?Sized, T: TeamDecisions>(
    env: &mut E,
    team: &mut T,
    discount: f64,
    episodes: usize,
    rng: &mut EnvRng,
    mut on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    for k in 0..episodes {
        on_episode(play_episode(env, team, discount, rng, k)?)?;
    }
    Ok(())
}

impl EpisodeTrace {
    /// The episode's JSON line as `macdec deploy` and `macdec eval` print it (no newline):
    /// `{"episode":..,"return":..,"undiscounted_return":..,"steps":..}`, plus `"trajectory"`
    /// when `with_trajectory`.
    pub fn json_line(&self, with_trajectory: bool) -> String {
        let line = if with_trajectory || self.trajectory.is_empty() {
            serde_json::to_string(self)
        } else {
            serde_json::to_string(&EpisodeTrace {
                trajectory: Vec::new(),
                ..self.clone()
            })
        };
        line.expect("serializing plain numbers and vectors to a string cannot fail")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deploy::drive::link::{JsonLink, LocalLink};
    use crate::deploy::policy::mock::{mock_manifest, MockPolicy};

    use rand::SeedableRng;

    fn rng(seed: u64) -> EnvRng {
        EnvRng::seed_from_u64(seed)
    }

    #[test]
    fn wrong_robot_count_is_refused() {
        let spec = crate::envs::box_pushing::spec(10, 100);
        let mut env = spec.build().unwrap();
        let mut one = vec![LocalLink::new(MockPolicy::new(5, 8, 0))];
        let err = run_episode(&mut env, &mut one, 0.98, &mut rng(0), 0).unwrap_err();
        assert!(
            matches!(
                err,
                DeployError::RobotCount {
                    expected: 2,
                    got: 1
                }
            ),
            "{err}"
        );
    }

    /// A link to a scripted robot: the info reply, then `replies`, then a closed stream.
    fn scripted(
        agent: usize,
        manifest: &crate::policy_files::Manifest,
        replies: &str,
    ) -> JsonLink<std::io::Cursor<Vec<u8>>, Vec<u8>> {
        let info = crate::deploy::serve::protocol::Reply::Info {
            agent,
            manifest: Box::new(manifest.clone()),
        }
        .to_line();
        let script = format!("{info}\n{replies}");
        JsonLink::open(
            std::io::Cursor::new(script.into_bytes()),
            Vec::new(),
            agent,
            manifest,
        )
        .unwrap()
    }

    #[test]
    fn a_robot_hanging_up_or_misbehaving_mid_episode_is_named() {
        let spec = crate::envs::box_pushing::spec(10, 100);
        let manifest = mock_manifest(spec.clone());
        let mut env = spec.build().unwrap();
        // Stay (7) lasts one step, so the good robot decides every step; GT_SB0 (0) takes several.
        let decision = r#"{"action":7,"name":"Stay","q":[0,0,0,0,0,0,0,1]}"#;
        let busy = r#"{"action":0,"name":"GT_SB0","q":[1,0,0,0,0,0,0,0]}"#;
        let cases = [
            (
                format!("{{\"ok\":\"reset\"}}\n{busy}\n"),
                "closed the connection",
            ),
            (
                r#"{"ok":"reset"}"#.to_string() + "\n" + r#"{"action":9,"name":"x","q":[]}"# + "\n",
                "out of range 0..8",
            ),
            (
                r#"{"ok":"reset"}"#.to_string() + "\n" + r#"{"ok":"continue"}"# + "\n",
                "expected a decision",
            ),
            (
                r#"{"error":"obs has 4 values"}"#.to_string() + "\n",
                "refused the request: obs has 4 values",
            ),
            ("not json\n".to_string(), "unreadable reply"),
        ];
        for (replies, needle) in cases {
            let good = scripted(
                0,
                &manifest,
                &format!(
                    "{{\"ok\":\"reset\"}}\n{}",
                    format!("{decision}\n").repeat(200)
                ),
            );
            let mut links = vec![good, scripted(1, &manifest, &replies)];
            let err = run_episode(&mut env, &mut links, 0.98, &mut rng(0), 0)
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with("robot of agent 1: ") && err.contains(needle),
                "{err}"
            );
        }
    }

    #[test]
    fn a_robot_for_another_agent_or_policy_fails_the_handshake() {
        let spec = crate::envs::box_pushing::spec(10, 100);
        let manifest = mock_manifest(spec.clone());
        let info = crate::deploy::serve::protocol::Reply::Info {
            agent: 1,
            manifest: Box::new(manifest.clone()),
        }
        .to_line()
            + "\n";
        let err = JsonLink::open(
            std::io::Cursor::new(info.clone().into_bytes()),
            Vec::new(),
            0,
            &manifest,
        )
        .err()
        .unwrap();
        assert_eq!(
            err,
            LinkError::WrongAgent {
                expected: 0,
                got: 1
            }
        );
        let mut other = manifest.clone();
        other.run.seed = 99;
        let err = JsonLink::open(
            std::io::Cursor::new(info.into_bytes()),
            Vec::new(),
            1,
            &other,
        )
        .err()
        .unwrap();
        assert_eq!(err, LinkError::WrongPolicy);
    }
}
