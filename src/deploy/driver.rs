//! Decentralized execution of a domain: the environment runs here, and each agent's macro-action
//! comes from its own robot, which sees only that agent's macro-observation (issue 7). The loop
//! is the greedy evaluation episode of spec `algorithms.md` 7.1 with the policy calls replaced by
//! messages, so over any transport it must give the same returns and trajectories as in-process
//! greedy evaluation of the same policy with the same seeds.

use crate::deploy::link::{LinkError, RobotLink};
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
    /// Every step, in order.
    pub trajectory: Vec<StepRecord>,
}

/// Why a deployment stopped.
#[derive(Debug, thiserror::Error)]
pub enum DeployError {
    #[error("the domain has {expected} agents but {got} robots were given")]
    RobotCount { expected: usize, got: usize },
    #[error("robot of agent {agent}: {source}")]
    Link {
        agent: usize,
        #[source]
        source: LinkError,
    },
    #[error("environment: {0}")]
    Env(#[from] EnvError),
    #[error("starting the robot of agent {agent}: {reason}")]
    Spawn { agent: usize, reason: String },
    #[error("policy: {0}")]
    Policy(String),
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
    let n = env.n_agents();
    if robots.len() != n {
        return Err(DeployError::RobotCount {
            expected: n,
            got: robots.len(),
        });
    }
    let link = |agent| move |source| DeployError::Link { agent, source };
    env.reset(rng);
    for (agent, robot) in robots.iter_mut().enumerate() {
        robot.reset().map_err(link(agent))?;
    }
    let mut actions = vec![0usize; n];
    let mut trajectory = Vec::new();
    let (mut discounted, mut undiscounted, mut weight) = (0.0, 0.0, 1.0);
    loop {
        for (agent, robot) in robots.iter_mut().enumerate() {
            let free = env.is_free(agent);
            if let Some(a) = robot.observe(env.obs(agent), free).map_err(link(agent))? {
                actions[agent] = a;
            }
        }
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
    (0..episodes)
        .map(|k| run_episode(env, robots, discount, rng, k))
        .collect()
}
