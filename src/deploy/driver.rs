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
    /// Every step, in order (left out of the JSON when empty).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
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
    #[error("writing an episode's result: {0}")]
    Output(#[from] std::io::Error),
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
    mut on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    for k in 0..episodes {
        on_episode(run_episode(env, robots, discount, rng, k)?)?;
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
    use crate::deploy::link::{JsonLink, LocalLink};
    use crate::deploy::mock::{mock_manifest, mock_policies, MockPolicy};
    use crate::deploy::robot::RobotSpec;
    use crate::deploy::server::{spawn_server, Limits, PolicyFactory, RobotServer};
    use crate::deploy::{greedy_action, AgentPolicy};
    use crate::envs::EnvSpec;
    use rand::SeedableRng;
    use std::net::TcpListener;
    use std::sync::Arc;
    use std::time::Duration;

    fn rng(seed: u64) -> EnvRng {
        EnvRng::seed_from_u64(seed)
    }

    /// Greedy decentralized execution written out independently of the driver (as
    /// `algos::evaluate::greedy_episode` with `select_dec`): free agents, in index order, query
    /// their own policy on their own observation and take the first maximal Q.
    fn reference_episode(
        env_spec: EnvSpec,
        seed_rng: &mut EnvRng,
    ) -> (f64, Vec<Vec<usize>>, Vec<f64>) {
        let manifest = mock_manifest(env_spec);
        let mut policies = mock_policies(&manifest);
        let mut env = env_spec.build().unwrap();
        env.reset(seed_rng);
        let mut actions = vec![0usize; env.n_agents()];
        let (mut ret, mut weight) = (0.0, 1.0);
        let (mut executed, mut rewards) = (Vec::new(), Vec::new());
        loop {
            for (i, p) in policies.iter_mut().enumerate() {
                if env.is_free(i) {
                    let mut q = vec![0.0; p.n_actions()];
                    p.q_values(env.obs(i), &mut q);
                    actions[i] = greedy_action(&q);
                }
            }
            let out = env.step(&actions, seed_rng).unwrap();
            ret += weight * out.reward;
            weight *= manifest.discount;
            executed.push(env.executed().to_vec());
            rewards.push(out.reward);
            if out.done {
                return (ret, executed, rewards);
            }
        }
    }

    /// One robot server thread per agent, each with its own mock policy, and a link to each.
    fn tcp_robots(
        env_spec: EnvSpec,
    ) -> (
        Vec<RobotServer>,
        Vec<JsonLink<std::io::BufReader<std::net::TcpStream>, std::net::TcpStream>>,
    ) {
        let manifest = mock_manifest(env_spec);
        let servers: Vec<RobotServer> = manifest
            .agents
            .iter()
            .map(|a| {
                let (obs, n, salt) = (a.obs_size, a.n_actions, a.index as u64);
                let factory: PolicyFactory = Arc::new(move || {
                    Box::new(MockPolicy::new(obs, n, salt)) as Box<dyn AgentPolicy>
                });
                let spec = Arc::new(RobotSpec::new(&manifest, a.index).unwrap());
                let listener = TcpListener::bind("127.0.0.1:0").unwrap();
                spawn_server(listener, factory, spec, Limits::default()).unwrap()
            })
            .collect();
        let links = servers
            .iter()
            .enumerate()
            .map(|(i, s)| {
                JsonLink::connect(s.local_addr(), i, &manifest, Duration::from_secs(20)).unwrap()
            })
            .collect();
        (servers, links)
    }

    fn check_equals_reference(env_spec: EnvSpec, seed: u64, episodes: usize) -> Vec<EpisodeTrace> {
        let manifest = mock_manifest(env_spec);
        let (_servers, mut links) = tcp_robots(env_spec);
        let mut env = env_spec.build().unwrap();
        let over_tcp = run_episodes(
            &mut env,
            &mut links,
            manifest.discount,
            episodes,
            &mut rng(seed),
        )
        .unwrap();
        let mut local: Vec<LocalLink<MockPolicy>> = mock_policies(&manifest)
            .into_iter()
            .map(LocalLink::new)
            .collect();
        let in_process = run_episodes(
            &mut env,
            &mut local,
            manifest.discount,
            episodes,
            &mut rng(seed),
        )
        .unwrap();
        assert_eq!(over_tcp, in_process);
        let mut reference_rng = rng(seed);
        for trace in &over_tcp {
            let (ret, executed, rewards) = reference_episode(env_spec, &mut reference_rng);
            assert_eq!(trace.discounted_return, ret);
            let got: Vec<Vec<usize>> = trace
                .trajectory
                .iter()
                .map(|s| s.executed.clone())
                .collect();
            assert_eq!(got, executed);
            let got: Vec<f64> = trace.trajectory.iter().map(|s| s.reward).collect();
            assert_eq!(got, rewards);
            assert_eq!(trace.undiscounted_return, rewards.iter().sum::<f64>());
        }
        // Not vacuous: the mock robots use several macro-actions each.
        for agent in 0..manifest.agents.len() {
            let mut used: Vec<usize> = over_tcp[0]
                .trajectory
                .iter()
                .map(|s| s.executed[agent])
                .collect();
            used.sort();
            used.dedup();
            assert!(
                used.len() >= 2,
                "agent {agent} used only {used:?}: {:?}",
                over_tcp[0]
                    .trajectory
                    .iter()
                    .map(|s| s.executed.clone())
                    .collect::<Vec<_>>()
            );
        }
        over_tcp
    }

    #[test]
    fn box_pushing_over_tcp_equals_in_process_greedy_execution() {
        let traces = check_equals_reference(
            EnvSpec::BoxPushing {
                grid: 10,
                horizon: 100,
            },
            0,
            2,
        );
        assert_eq!(traces.len(), 2);
        assert!(traces[0].trajectory.last().unwrap().done);
    }

    #[test]
    fn noisy_warehouse_over_tcp_equals_in_process_greedy_execution_with_the_same_seed() {
        let spec = EnvSpec::Warehouse {
            horizon: 150,
            tb_m_noisy: 0.3,
        };
        let a = check_equals_reference(spec, 11, 3);
        let b = check_equals_reference(spec, 12, 1);
        // The seed matters (movement noise), so equality above is per seed, not by accident.
        assert_ne!(a[0].trajectory, b[0].trajectory);
    }

    #[test]
    fn wrong_robot_count_is_refused() {
        let spec = EnvSpec::BoxPushing {
            grid: 10,
            horizon: 100,
        };
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
        manifest: &crate::deploy::Manifest,
        replies: &str,
    ) -> JsonLink<std::io::Cursor<Vec<u8>>, Vec<u8>> {
        let info = crate::deploy::protocol::Reply::Info {
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
        let spec = EnvSpec::BoxPushing {
            grid: 10,
            horizon: 100,
        };
        let manifest = mock_manifest(spec);
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
        let spec = EnvSpec::BoxPushing {
            grid: 10,
            horizon: 100,
        };
        let manifest = mock_manifest(spec);
        let info = crate::deploy::protocol::Reply::Info {
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

    /// Speed of decentralized execution over loopback TCP (robot server threads, mock policy) vs
    /// in-process calls. `cargo test --release --lib deploy_speed -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn deploy_speed() {
        use std::time::Instant;
        for spec in [
            EnvSpec::BoxPushing {
                grid: 10,
                horizon: 100,
            },
            EnvSpec::Warehouse {
                horizon: 150,
                tb_m_noisy: 0.0,
            },
        ] {
            let manifest = mock_manifest(spec);
            let mut env = spec.build().unwrap();
            let (_servers, mut links) = tcp_robots(spec);
            let episodes = 200;
            let start = Instant::now();
            let traces = run_episodes(&mut env, &mut links, 0.98, episodes, &mut rng(0)).unwrap();
            let tcp = start.elapsed().as_secs_f64();
            let steps: usize = traces.iter().map(|t| t.steps).sum();
            let messages = steps * manifest.agents.len();
            let mut local: Vec<LocalLink<MockPolicy>> = mock_policies(&manifest)
                .into_iter()
                .map(LocalLink::new)
                .collect();
            let start = Instant::now();
            run_episodes(&mut env, &mut local, 0.98, episodes, &mut rng(0)).unwrap();
            let inproc = start.elapsed().as_secs_f64();
            println!(
                "{}: {episodes} episodes, {steps} steps, {messages} observe round trips: TCP {:.3} s ({:.1} us per round trip, {:.0} steps/s); in-process {:.4} s",
                spec.name(),
                tcp,
                tcp * 1e6 / messages as f64,
                steps as f64 / tcp,
                inproc
            );
        }
    }
}
