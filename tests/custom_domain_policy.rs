//! A domain defined outside the binary (issue 11, "Your own domain"): trained through the library,
//! exported with `TrainedPolicy::export`, served by `macdec robot` exactly as the library's net
//! answers, and refused by name by every command that would have to simulate it.

mod common;

use common::{robot_process, run};
use macdec::algos::family::FamilyMethod;
use macdec::algos::value::evaluate::{greedy_episode, GreedyPolicy};
use macdec::algos::value::method::ValueMethod;
use macdec::deploy::drive::link::JsonLink;
use macdec::deploy::greedy_action;
use macdec::deploy::serve::protocol::Reply;
use macdec::policy_files::Manifest;
use macdec::policy_files::PolicyEnv;
use macdec::{EnvError, EnvRng, MacroEnv, Method, StepOutcome};
use std::io::{BufRead, BufReader, Write};
use std::net::TcpStream;
use std::path::Path;

const NAME: &str = "beacon";
const HORIZON: usize = 6;
const ACTIONS: [&str; 3] = ["wait", "signal", "move"];

/// Two robots, each seeing a 3-element beacon reading that changes with time; the team earns 1
/// for every step both choose the macro-action the reading points at. Macro-actions last one step.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Beacon {
    t: usize,
    obs: [[f32; 3]; 2],
    executed: [usize; 2],
    mac_done: [bool; 2],
}

impl Beacon {
    fn new() -> Result<Self, EnvError> {
        let mut env = Beacon {
            t: 0,
            obs: [[0.0; 3]; 2],
            executed: [0; 2],
            mac_done: [true; 2],
        };
        env.observe();
        Ok(env)
    }

    fn target(&self) -> usize {
        self.t % 3
    }

    fn observe(&mut self) {
        for (agent, obs) in self.obs.iter_mut().enumerate() {
            *obs = [0.0; 3];
            obs[self.t % 3] = 1.0;
            obs[(self.t + agent) % 3] += 0.5;
        }
    }
}

impl MacroEnv for Beacon {
    fn n_agents(&self) -> usize {
        2
    }
    fn obs_sizes(&self) -> &[usize] {
        &[3, 3]
    }
    fn n_actions(&self) -> &[usize] {
        &[3, 3]
    }
    fn action_names(&self, _agent: usize) -> &'static [&'static str] {
        &ACTIONS
    }
    fn obs_names(&self, _agent: usize) -> Vec<String> {
        ["west", "north", "east"].map(String::from).to_vec()
    }
    fn horizon(&self) -> usize {
        HORIZON
    }
    fn reset(&mut self, _rng: &mut EnvRng) {
        self.t = 0;
        self.mac_done = [true; 2];
        self.observe();
    }
    fn step(&mut self, actions: &[usize], _rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        if self.t >= HORIZON {
            return Err(EnvError::EpisodeOver);
        }
        if actions.len() != 2 {
            return Err(EnvError::WrongActionCount {
                expected: 2,
                got: actions.len(),
            });
        }
        if let Some((agent, &action)) = actions.iter().enumerate().find(|(_, &a)| a >= 3) {
            return Err(EnvError::ActionOutOfRange {
                agent,
                action,
                n_actions: 3,
            });
        }
        let reward = if actions.iter().all(|&a| a == self.target()) {
            1.0
        } else {
            0.0
        };
        self.executed = [actions[0], actions[1]];
        self.t += 1;
        self.observe();
        Ok(StepOutcome {
            reward,
            done: self.t >= HORIZON,
            truncated: false,
        })
    }
    fn obs(&self, agent: usize) -> &[f32] {
        &self.obs[agent]
    }
    fn executed(&self) -> &[usize] {
        &self.executed
    }
    fn mac_done(&self) -> &[bool] {
        &self.mac_done
    }
    fn t(&self) -> usize {
        self.t
    }
    fn render_ascii(&self) -> String {
        format!("t = {}", self.t)
    }
}

/// A few episodes of Our-1 on [`Beacon`] through the library, exported to `dir`.
fn train_and_export(dir: &Path) -> (macdec::TrainedPolicy, Manifest) {
    let mut config = ValueMethod::Our1.defaults(&macdec::envs::warehouse::paper_spec());
    config.total_epi = 12;
    config.eps_l_d_steps = 6;
    config.h_stable_at = 6;
    config.replay_buffer_size = 50;
    config.batch_size = 4;
    config.train_freq = 2;
    config.target_update_freq = 10;
    config.eval_freq = 6;
    config.dec_mlp_layer_size = 8;
    config.dec_rnn_h_size = 8;
    config.cen_mlp_layer_size = 8;
    config.cen_rnn_h_size = 8;
    let config = config.into();
    let trained = macdec::train_policy(
        Beacon::new,
        &config,
        Method::Value(ValueMethod::Our1),
        4,
        |_| {},
    )
    .unwrap();
    assert_eq!(trained.episodes_trained, 12);
    assert!(trained.evals.iter().any(|e| e.updates > 0), "it trained");
    let env = Beacon::new().unwrap();
    let manifest = trained
        .export(dir, &env, PolicyEnv::custom(NAME, &env))
        .unwrap();
    (trained, manifest)
}

/// Send one request line and read its reply.
fn ask(stream: &mut BufReader<TcpStream>, line: &str) -> Reply {
    writeln!(stream.get_mut(), "{line}").unwrap();
    let mut reply = String::new();
    stream.read_line(&mut reply).unwrap();
    serde_json::from_str(&reply).unwrap_or_else(|e| panic!("{e}: {reply}"))
}

#[test]
fn a_robot_serves_a_custom_domain_policy_exactly_as_the_library_net_answers() {
    let dir = tempfile::tempdir().unwrap();
    let policy = dir.path().join("policy");
    let (trained, manifest) = train_and_export(&policy);
    assert_eq!(manifest.env.name(), NAME);
    let agent = 1;
    let robot = robot_process(&policy, agent, false);
    let mut stream = BufReader::new(TcpStream::connect(&robot.addr).unwrap());
    match ask(&mut stream, r#"{"type": "info"}"#) {
        Reply::Info {
            agent: a,
            manifest: theirs,
        } => assert_eq!((a, *theirs), (agent, manifest)),
        other => panic!("{other:?}"),
    }
    // Two decisions in a row: the second depends on the hidden state the first left.
    let net = trained.agents[agent]
        .as_q()
        .expect("Our-1's agents have Q-nets");
    let mut state = net.zero_state();
    for obs in [[0.5f32, 1.0, 0.0], [1.5, 0.0, -2.0]] {
        let expected_q = net.act_step(&obs, &mut state).to_vec();
        let expected = greedy_action(&expected_q);
        let request = serde_json::json!({"type": "observe", "obs": obs, "macro_action_done": true});
        match ask(&mut stream, &request.to_string()) {
            Reply::Decision { action, name, q } => {
                assert_eq!(q, expected_q);
                assert_eq!((action, name.as_str()), (expected, ACTIONS[expected]));
            }
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn commands_that_simulate_the_domain_refuse_a_custom_policy_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let policy = dir.path().join("policy");
    train_and_export(&policy);
    let p = policy.to_str().unwrap();
    let robot = robot_process(&policy, 0, false);
    let gif = dir.path().join("never.gif");
    let gif = gif.to_str().unwrap();
    let commands: [&[&str]; 4] = [
        &["eval", "--policy", p],
        &["deploy", "--policy", p],
        &["domain", "--policy", p, "--robots", &robot.addr],
        &["render", "--run", p, "--out", gif],
    ];
    for args in commands {
        let out = run(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains(&format!("`{NAME}`"))
                && err.contains("not in this binary")
                && !err.contains("panicked"),
            "{args:?}: {err}"
        );
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    assert!(!Path::new(gif).exists());
}

#[test]
fn your_own_program_runs_the_custom_domain_against_its_robots_as_the_learner_evaluates() {
    use rand::SeedableRng;
    let dir = tempfile::tempdir().unwrap();
    let policy = dir.path().join("policy");
    let (trained, manifest) = train_and_export(&policy);
    let robots: Vec<_> = (0..2).map(|i| robot_process(&policy, i, false)).collect();
    let timeout = std::time::Duration::from_secs(20);
    let mut links: Vec<_> = robots
        .iter()
        .enumerate()
        .map(|(i, r)| JsonLink::connect(r.addr.parse().unwrap(), i, &manifest, timeout).unwrap())
        .collect();
    let mut env = Beacon::new().unwrap();
    let traces = macdec::deploy::run_episodes(
        &mut env,
        &mut links,
        manifest.discount,
        2,
        &mut EnvRng::seed_from_u64(0),
    )
    .unwrap();
    let nets: Vec<_> = trained.agents.iter().filter_map(|a| a.as_q()).collect();
    let mut steps = Vec::new();
    let learner = greedy_episode(
        &mut env,
        GreedyPolicy::Dec(&nets),
        trained.config.discount(),
        &mut EnvRng::seed_from_u64(0),
        |e, _, reward| steps.push((e.executed().to_vec(), reward)),
    )
    .unwrap();
    assert_eq!(steps.len(), HORIZON);
    for trace in &traces {
        assert_eq!(trace.discounted_return.to_bits(), learner.to_bits());
        let robots: Vec<_> = trace
            .trajectory
            .iter()
            .map(|s| (s.executed.clone(), s.reward))
            .collect();
        assert_eq!(robots, steps, "the robots chose other macro-actions");
    }
}
