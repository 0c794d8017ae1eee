//! `macdec robot` and `macdec deploy` as real processes, with the hidden `--mock` policy:
//! stdin/stdout and TCP robots, refusal of a corrupt export, and a multi-process deployment equal
//! to in-process greedy execution.

use macdec::deploy::drive::driver::{run_episodes, EpisodeTrace};
use macdec::deploy::drive::link::LocalLink;
use macdec::deploy::policy::mock::{mock_policies, write_mock_policy, MockPolicy};
use macdec::deploy::serve::protocol::{Ack, Reply, Request};
use macdec::deploy::{greedy_action, AgentPolicy};
use macdec::envs::EnvSpec;
use macdec::experiment::definition::seeds::{stream, Role};
use macdec::policy_files::POLICY_FILE;
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};

mod common;

use common::{ok, traces, BIN};

fn bp10() -> EnvSpec {
    macdec::envs::box_pushing::spec(10, 100)
}

fn observe(obs: &[f32], done: bool) -> String {
    Request::Observe {
        obs: obs.to_vec(),
        macro_action_done: done,
        step: None,
    }
    .to_line()
}

#[test]
fn stdio_robot_keeps_its_hidden_state_and_survives_bad_lines() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = write_mock_policy(dir.path(), bp10()).unwrap();
    let (a, b) = ([1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 1.0, 0.0]);
    let input = [
        r#"{"type":"info"}"#.to_string(),
        observe(&a, true),
        observe(&b, false),
        "{\"type\":\"observe\",\"obs\":[1,NaN,0,0,0],\"macro_action_done\":true}".into(),
        observe(&b, true),
        r#"{"type":"reset"}"#.into(),
        observe(&b, true),
    ]
    .join("\n")
        + "\n";
    let mut child = Command::new(BIN)
        .args(["robot", "--mock", "--agent", "1", "--policy"])
        .arg(dir.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let replies: Vec<Reply> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(replies.len(), 7);
    assert_eq!(
        replies[0],
        Reply::Info {
            agent: 1,
            manifest: Box::new(manifest)
        }
    );
    let mut reference = MockPolicy::new(5, 8, 1);
    let mut q = vec![0.0; 8];
    let mut decision = |obs: &[f32], reference: &mut MockPolicy| {
        reference.q_values(obs, 0, &mut q);
        let action = greedy_action(&q);
        (action, q.clone())
    };
    let check = |reply: &Reply, (action, q): (usize, Vec<f32>)| match reply {
        Reply::Decision {
            action: got,
            q: got_q,
            ..
        } => assert_eq!((*got, got_q), (action, &q)),
        other => panic!("expected a decision, got {other:?}"),
    };
    check(&replies[1], decision(&a, &mut reference));
    assert_eq!(replies[2], Reply::Ack { ok: Ack::Continue });
    assert!(matches!(&replies[3], Reply::Error { error } if error.contains("NaN")));
    check(&replies[4], decision(&b, &mut reference));
    assert_eq!(replies[5], Reply::Ack { ok: Ack::Reset });
    reference.reset();
    check(&replies[6], decision(&b, &mut reference));
}

#[test]
fn robot_refuses_a_corrupt_export_with_the_file_named() {
    let dir = tempfile::tempdir().unwrap();
    write_mock_policy(dir.path(), bp10()).unwrap();
    let path = dir.path().join("agent-1.safetensors");
    let mut bytes = std::fs::read(&path).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&path, bytes).unwrap();
    let out = Command::new(BIN)
        .args(["robot", "--mock", "--agent", "1", "--policy"])
        .arg(dir.path())
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("agent-1.safetensors") && err.contains("SHA-256"),
        "{err}"
    );
    // Agent 0's file is intact, so its robot starts (and ends at once on empty stdin).
    let ok = Command::new(BIN)
        .args(["robot", "--mock", "--agent", "0", "--policy"])
        .arg(dir.path())
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    std::fs::remove_file(dir.path().join(POLICY_FILE)).unwrap();
    let out = Command::new(BIN)
        .args(["robot", "--mock", "--agent", "0", "--policy"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("manifest.json"));
}

#[test]
fn tcp_robot_announces_its_port_and_serves_connections() {
    let dir = tempfile::tempdir().unwrap();
    write_mock_policy(dir.path(), bp10()).unwrap();
    let mut child = Command::new(BIN)
        .args([
            "robot",
            "--mock",
            "--agent",
            "0",
            "--listen",
            "127.0.0.1:0",
            "--exit-on-stdin-close",
            "--policy",
        ])
        .arg(dir.path())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    let addr = macdec::deploy::drive::processes::parse_announcement(&first).expect(&first);
    let stream = std::net::TcpStream::connect(addr).unwrap();
    let mut reader = BufReader::new(stream.try_clone().unwrap());
    (&stream)
        .write_all((observe(&[0.0; 5], true) + "\n").as_bytes())
        .unwrap();
    let mut line = String::new();
    reader.read_line(&mut line).unwrap();
    let mut q = vec![0.0; 8];
    MockPolicy::new(5, 8, 0).q_values(&[0.0; 5], 0, &mut q);
    assert!(matches!(
        serde_json::from_str(&line).unwrap(),
        Reply::Decision { q: got, .. } if got == q
    ));
    // Closing its stdin ends the robot.
    drop(child.stdin.take());
    let status = child.wait().unwrap();
    assert!(status.success());
}

#[test]
fn deployed_robot_processes_equal_in_process_greedy_execution() {
    let dir = tempfile::tempdir().unwrap();
    let env = macdec::envs::warehouse::spec(150, 0.2);
    let manifest = write_mock_policy(dir.path(), env.clone()).unwrap();
    let out = Command::new(BIN)
        .args([
            "deploy",
            "--mock",
            "--episodes",
            "3",
            "--seed",
            "4",
            "--trajectories",
            "--policy",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    let deployed = traces(&out);
    let mut links: Vec<LocalLink<MockPolicy>> = mock_policies(&manifest)
        .into_iter()
        .map(LocalLink::new)
        .collect();
    let mut built = env.build().unwrap();
    let in_process = run_episodes(
        &mut built,
        &mut links,
        manifest.discount,
        3,
        &mut stream(4, Role::EvalEnv),
    )
    .unwrap();
    assert_eq!(deployed, in_process);
    assert!(deployed.iter().all(|t| !t.trajectory.is_empty()));
}

/// A tiny Box Pushing experiment: a few seconds of training.
const TINY: &str = r#"
name = "tiny"
methods = ["our1", "cen-ddrqn"]
seeds = "3..4"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 40
total_epi = 80
eps_l_d_steps = 40
batch_size = 16
replay_buffer_size = 2000
eval_freq = 20
checkpoint_freq = 40
"#;

#[test]
fn a_trained_run_exported_and_deployed_on_robot_processes_equals_greedy_evaluation() {
    use macdec::algos::value::evaluate::{greedy_episode, GreedyPolicy};
    use macdec::envs::MacroEnv;
    use macdec::experiment::run::results_tree::CHECKPOINT;
    use macdec::experiment::run::train_run::load_checkpoint;
    use macdec::nn::{ActingNetRef, QNet};

    let dir = tempfile::tempdir().unwrap();
    let results = common::train_config(dir.path(), TINY);

    // Cen-DDRQN has no decentralized nets: refused with the reason.
    let out = Command::new(BIN)
        .args(["export", "--run"])
        .arg(results.join("tiny/cen-ddrqn/seed-3"))
        .arg("--out")
        .arg(dir.path().join("cen-policy"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no decentralized nets"), "{err}");

    let run = results.join("tiny/our1/seed-3");
    let policy = dir.path().join("policy");
    let out = Command::new(BIN)
        .args(["export", "--run"])
        .arg(&run)
        .arg("--out")
        .arg(&policy)
        .output()
        .unwrap();
    ok(&out);
    let (manifest, _) = macdec::policy_files::load_all(&policy).unwrap();
    assert_eq!(
        (manifest.run.method.as_str(), manifest.run.seed),
        ("our1", 3)
    );
    assert_eq!(manifest.run.episodes_trained, 80);
    assert_eq!(manifest.agents.len(), 2);

    let episodes = 2;
    let out = Command::new(BIN)
        .args([
            "deploy",
            "--trajectories",
            "--episodes",
            &episodes.to_string(),
            "--policy",
        ])
        .arg(&policy)
        .output()
        .unwrap();
    let deployed = traces(&out);
    assert_eq!(deployed.len(), episodes);

    // In-process greedy evaluation of the checkpoint's nets, same seed (the run's), same stream.
    let trainer = load_checkpoint(&run.join(CHECKPOINT)).unwrap();
    let saved = trainer.saved_nets();
    let nets: Vec<&QNet> = saved
        .iter()
        .filter(|n| n.agent.is_some())
        .map(|n| match n.net {
            ActingNetRef::Q(q) => q,
            _ => unreachable!("an our1 run's agents have Q-nets"),
        })
        .collect();
    let mut env = manifest.env.build().unwrap();
    let mut rng = stream(3, Role::EvalEnv);
    for trace in &deployed {
        let mut steps = Vec::new();
        let ret = greedy_episode(
            &mut env,
            GreedyPolicy::Dec(&nets),
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
    }
}

#[test]
fn deploy_prints_each_episode_as_it_ends() {
    // A hundred thousand episodes (the most --episodes takes) would take hours: the first line
    // must still arrive within seconds, so results are streamed, not kept until the end.
    let dir = tempfile::tempdir().unwrap();
    write_mock_policy(dir.path(), bp10()).unwrap();
    let mut child = Command::new(BIN)
        .args(["deploy", "--mock", "--episodes", "100000", "--policy"])
        .arg(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = BufReader::new(stdout).read_line(&mut line);
        let _ = tx.send(line);
    });
    let line = rx.recv_timeout(std::time::Duration::from_secs(60));
    child.kill().unwrap();
    child.wait().unwrap();
    let line = line.expect("no episode line within 60 s");
    let trace: EpisodeTrace = serde_json::from_str(&line).unwrap();
    assert_eq!(trace.episode, 0);
}

/// `src/deploy` knows no learner (issue 11): no file there names `src/algos`, so a policy
/// directory, whatever its domain, is served without the trainer's types.
#[test]
fn deploy_imports_nothing_of_the_learner() {
    let mut stack = vec![std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/deploy")];
    let (mut users, mut files) = (Vec::new(), 0);
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            files += 1;
            let text = std::fs::read_to_string(&path).unwrap();
            if text.contains("crate::algos") || text.contains("macdec::algos") {
                users.push(path.display().to_string());
            }
        }
    }
    assert!(files > 15, "read only {files} files under src/deploy");
    assert!(users.is_empty(), "{users:?}");
}
