//! Helpers shared by the integration tests that run the `macdec` binary, start robots or build
//! policy directories (issue 11): one copy of each fixture, so changing one changes it for all.

// Every test binary compiles this module and uses only part of it.
#![allow(dead_code)]

use macdec::deploy::drive::driver::EpisodeTrace;
use macdec::deploy::policy::import::{reference_state_dict, Naming};
use macdec::deploy::policy::mock::MockPolicy;
use macdec::deploy::serve::robot::RobotSpec;
use macdec::deploy::serve::server::{spawn_server, Limits, PolicyFactory, RobotServer};
use macdec::deploy::AgentPolicy;
use macdec::envs::{EnvSpec, MacroEnv};
use macdec::policy_files::architecture::{synthetic_weights, Architecture};
use macdec::policy_files::{Manifest, RunInfo};
use std::io::{BufRead, BufReader};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::Arc;

/// The `macdec` binary under test.
pub const BIN: &str = env!("CARGO_BIN_EXE_macdec");

/// A tiny Box Pushing experiment, `tiny/our1/seed-1`: a second of training.
pub const TINY_RUN: &str = r#"
name = "tiny"
methods = ["our1"]
seeds = "1..2"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 20
total_epi = 20
eps_l_d_steps = 10
batch_size = 8
replay_buffer_size = 500
eval_freq = 10
checkpoint_freq = 10
"#;

/// Train [`TINY_RUN`] into `dir/results` and return its run directory.
pub fn train_tiny_run(dir: &Path) -> PathBuf {
    train_config(dir, TINY_RUN).join("tiny/our1/seed-1")
}

/// Train the experiment `config` (written to `dir/tiny.toml`) quietly into `dir/results`,
/// asserting success, and return the results root.
pub fn train_config(dir: &Path, config: &str) -> PathBuf {
    let path = dir.join("tiny.toml");
    std::fs::write(&path, config).unwrap();
    let results = dir.join("results");
    let out = Command::new(BIN)
        .args(["train", "--quiet", "--no-plot", "--config"])
        .arg(&path)
        .arg("--out")
        .arg(&results)
        .output()
        .unwrap();
    ok(&out);
    results
}

/// `macdec ARGS`, waited for; success is not checked.
pub fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

/// The command's stdout, after asserting it succeeded (its stderr is the failure message).
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

/// The team returns a successful `macdec render` reported on stderr.
pub fn render_returns(out: &Output) -> String {
    ok(out);
    let err = String::from_utf8_lossy(&out.stderr);
    let at = err
        .find("team returns")
        .expect("render reports its returns");
    err[at..].trim().to_string()
}

/// The lines of a successful command's stdout.
pub fn stdout_lines(out: &Output) -> Vec<String> {
    ok(out).lines().map(str::to_string).collect()
}

/// The episodes a successful `deploy`, `eval` or `domain` printed, one JSON line each.
pub fn traces(out: &Output) -> Vec<EpisodeTrace> {
    stdout_lines(out)
        .iter()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Large pseudo-random weights (agent-specific), so greedy actions change along an episode
/// (freshly initialized nets mostly repeat one macro-action).
pub fn weight(agent: usize) -> impl Fn(&str, usize) -> f32 {
    move |name, k| {
        let mut h = (k as u64) ^ ((name.len() as u64) << 32) ^ ((agent as u64) << 48);
        for _ in 0..2 {
            h = (h ^ (h >> 31)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
        ((h >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 3.0
    }
}

/// One safetensors file of [`weight`]s per agent of `env`, under macdec's tensor names.
pub fn synthetic_agent_weights(env: &impl MacroEnv, arch: &Architecture) -> Vec<Vec<u8>> {
    (0..env.n_agents())
        .map(|i| synthetic_weights(arch, env.obs_sizes()[i], env.n_actions()[i], weight(i)))
        .collect()
}

/// The run a test policy claims to come from.
pub fn test_run(seed: u64) -> RunInfo {
    RunInfo {
        experiment: "test".into(),
        method: "our1".into(),
        variant: String::new(),
        seed,
        episodes_trained: 0,
        config: serde_json::Value::Null,
    }
}

/// A policy directory of [`synthetic_agent_weights`] for `env` (DDRQN M = 16, H = 8), as `export`
/// writes one, claiming run seed `seed`.
pub fn write_synthetic_policy(dir: &Path, env: EnvSpec, discount: f64, seed: u64) -> Manifest {
    let arch = Architecture::ddrqn(16, 8);
    let built = env.build().unwrap();
    let weights = synthetic_agent_weights(&built, &arch);
    Manifest::write_policy(dir, env, discount, arch, test_run(seed), &weights).unwrap()
}

/// One reference-named state_dict per agent of `env` in `dir` (`a<i>.safetensors`), agent i
/// named as `namings[i % len]`, with [`weight`]s.
pub fn write_agents(
    dir: &Path,
    env: EnvSpec,
    arch: &Architecture,
    namings: &[Naming],
) -> Vec<PathBuf> {
    let built = env.build().unwrap();
    (0..built.n_agents())
        .map(|i| {
            let bytes = reference_state_dict(
                arch,
                built.obs_sizes()[i],
                built.n_actions()[i],
                namings[i % namings.len()],
                weight(i),
            );
            let path = dir.join(format!("a{i}.safetensors"));
            std::fs::write(&path, bytes).unwrap();
            path
        })
        .collect()
}

/// The paths as `import --agents` takes them: comma-separated.
pub fn agents_arg(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(",")
}

/// A `macdec robot --listen` process and the address it announced; killed on drop.
pub struct RobotProcess {
    child: Child,
    pub addr: String,
}

impl Drop for RobotProcess {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Start agent `agent`'s robot for `policy` on a free loopback port (with the stand-in policy
/// when `mock`) and wait for its announcement.
pub fn robot_process(policy: &Path, agent: usize, mock: bool) -> RobotProcess {
    let mut cmd = Command::new(BIN);
    cmd.args(["robot", "--policy", policy.to_str().unwrap()])
        .args(["--agent", &agent.to_string(), "--listen", "127.0.0.1:0"]);
    if mock {
        cmd.arg("--mock");
    }
    let mut child = cmd.stdout(Stdio::piped()).spawn().unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = macdec::deploy::drive::processes::parse_announcement(&line)
        .unwrap_or_else(|| panic!("robot announcement: {line}"))
        .to_string();
    RobotProcess { child, addr }
}

/// A robot server thread serving agent `agent` of `manifest` with a mock policy salted `salt`
/// (the agent's own salt is its index).
pub fn mock_robot_server(manifest: &Manifest, agent: usize, salt: u64) -> RobotServer {
    let a = &manifest.agents[agent];
    let (obs, n) = (a.obs_size, a.n_actions);
    let factory: PolicyFactory =
        Arc::new(move || Box::new(MockPolicy::new(obs, n, salt)) as Box<dyn AgentPolicy>);
    let spec = Arc::new(RobotSpec::new(manifest, agent).unwrap());
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    spawn_server(listener, factory, spec, Limits::default()).unwrap()
}
