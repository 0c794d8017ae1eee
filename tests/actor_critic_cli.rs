//! Actor-critic runs through the command line: `macdec train` writes a run with its actors as
//! policy files, `eval` runs them greedily or sampled (`--sample`, MacroMARL's protocol), `export`
//! puts them in a policy directory for robots, a killed run resumes to the same numbers, and a
//! Q-net policy refuses `--sample` by name.

mod common;

use common::{ok, run, traces};

const EXPERIMENT: &str = r#"
name = "ac"
methods = ["mac-iaisc", "mac-cac"]
seeds = [0]
[params]
env_name = "BP-MA-v0"
grid_dim = [4, 4]
env_terminate_step = 20
total_epi = 64
n_env = 4
train_freq = 4
c_target_update_freq = 8
eval_freq = 16
checkpoint_freq = 16
"#;

#[test]
fn actor_critic_runs_train_evaluate_and_export() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("ac.toml");
    std::fs::write(&config, EXPERIMENT).unwrap();
    let out = dir.path().join("results");
    let (c, o) = (config.to_str().unwrap(), out.to_str().unwrap());
    ok(&run(&[
        "train",
        "--config",
        c,
        "--out",
        o,
        "--quiet",
        "--no-plot",
    ]));
    let iaisc = out.join("ac/mac-iaisc/seed-0");
    let metrics = std::fs::read_to_string(iaisc.join("metrics.csv")).unwrap();
    assert!(
        metrics.starts_with("episode,env_steps,updates,eval_return,eval_return_undiscounted,eps,critic_loss,actor_loss,train_return,acac_timesteps,wall_seconds\n"),
        "{metrics}"
    );
    assert_eq!(
        metrics.lines().count(),
        1 + 4,
        "evaluations at 0, 16, 32, 48"
    );

    // Greedy and sampled evaluation of the run's actors.
    let policy = iaisc.join("policy");
    let p = policy.to_str().unwrap();
    let greedy = traces(&run(&["eval", "--policy", p, "--episodes", "3"]));
    assert_eq!(greedy.len(), 3);
    let sampled = run(&["eval", "--policy", p, "--episodes", "3", "--sample"]);
    assert_eq!(traces(&sampled).len(), 3);
    assert_eq!(
        sampled.stdout,
        run(&["eval", "--policy", p, "--episodes", "3", "--sample"]).stdout,
        "sampling is seeded"
    );

    // Export for robots, and the export evaluates as the run does.
    let exported = dir.path().join("export");
    let e = exported.to_str().unwrap();
    ok(&run(&[
        "export",
        "--run",
        iaisc.to_str().unwrap(),
        "--out",
        e,
    ]));
    assert_eq!(
        greedy,
        traces(&run(&["eval", "--policy", e, "--episodes", "3"]))
    );

    // Mac-CAC's centralized actor cannot be exported for decentralized robots.
    let cac = out.join("ac/mac-cac/seed-0");
    let refused = run(&["export", "--run", cac.to_str().unwrap(), "--out", e]);
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("no decentralized nets"), "{err}");
}

/// A run killed after its first checkpoint resumes to exactly the numbers of an uninterrupted run.
#[test]
fn a_killed_actor_critic_run_resumes_to_the_same_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("ac.toml");
    std::fs::write(&config, EXPERIMENT).unwrap();
    let c = config.to_str().unwrap();
    let long = [
        "--methods",
        "mac-iaicc",
        "--set",
        "total_epi=3200",
        "--quiet",
        "--no-plot",
    ];
    let whole = dir.path().join("whole");
    ok(&run(&[
        &["train", "--config", c, "--out", whole.to_str().unwrap()],
        &long[..],
    ]
    .concat()));
    let killed = dir.path().join("killed");
    let k = killed.to_str().unwrap();
    let mut child = std::process::Command::new(common::BIN)
        .args(["train", "--config", c, "--out", k])
        .args(long)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let run_dir = killed.join("ac/mac-iaicc/seed-0");
    let start = std::time::Instant::now();
    while !run_dir.join("checkpoint.bin").is_file()
        && start.elapsed() < std::time::Duration::from_secs(60)
    {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !run_dir.join("finished").exists(),
        "the run finished before it was killed; the test did not test resuming"
    );
    ok(&run(
        &[&["train", "--config", c, "--out", k], &long[..]].concat()
    ));
    let metrics = |root: &std::path::Path| {
        let text = std::fs::read_to_string(root.join("ac/mac-iaicc/seed-0/metrics.csv")).unwrap();
        text.lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect::<Vec<_>>()
    };
    assert_eq!(metrics(&whole), metrics(&killed));
}

#[test]
fn sampling_a_q_net_policy_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let spec = macdec::envs::box_pushing::spec(10, 100);
    macdec::deploy::policy::mock::write_mock_policy(dir.path(), spec).unwrap();
    let out = run(&["eval", "--policy", dir.path().to_str().unwrap(), "--sample"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("needs an actor policy"), "{err}");
}
