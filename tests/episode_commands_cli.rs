//! `macdec eval`, `deploy` and `domain` share their flags and their printer (issue 11): on one
//! policy they print the same episode lines, and each ends with its own summary line, pinned
//! here word for word (scripts and the ROS bridge read these lines).

mod common;

use common::{robot_process, run, traces, write_synthetic_policy};
use macdec::deploy::drive::driver::EpisodeTrace;
use macdec::envs::EnvSpec;
use std::process::Output;

/// Noisy Warehouse: the seed changes the episodes, so a wrong seed shows.
fn noisy_warehouse() -> EnvSpec {
    macdec::envs::warehouse::spec(150, 0.3)
}

/// The seed the policy's run claims; the default of `--seed`.
const RUN_SEED: u64 = 7;

/// The last line of a command's stderr (the summary, after any robot notes).
fn summary(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr);
    err.lines().last().unwrap_or_default().to_string()
}

fn mean(traces: &[EpisodeTrace], f: impl Fn(&EpisodeTrace) -> f64) -> f64 {
    traces.iter().map(f).sum::<f64>() / traces.len() as f64
}

#[test]
fn eval_deploy_and_domain_print_the_same_episodes_and_their_own_summaries() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = write_synthetic_policy(dir.path(), noisy_warehouse(), 0.95, RUN_SEED);
    let p = dir.path().to_str().unwrap();
    let robots: Vec<_> = (0..manifest.agents.len())
        .map(|i| robot_process(dir.path(), i, false))
        .collect();
    let list = robots
        .iter()
        .map(|r| r.addr.as_str())
        .collect::<Vec<_>>()
        .join(",");
    let episode_runs: [(Vec<&str>, usize, u64); 2] = [
        (
            vec!["--episodes", "3", "--seed", "5", "--trajectories"],
            3,
            5,
        ),
        // The defaults: one episode, the run's seed.
        (vec![], 1, RUN_SEED),
    ];
    for (flags, episodes, seed) in episode_runs {
        let eval = run(&[&["eval", "--policy", p][..], &flags].concat());
        let deploy = run(&[&["deploy", "--policy", p][..], &flags].concat());
        let domain = run(&[&["domain", "--policy", p, "--robots", &list][..], &flags].concat());
        let episodes_of = traces(&eval);
        assert_eq!(episodes_of.len(), episodes);
        assert_eq!(traces(&deploy), episodes_of);
        assert_eq!(traces(&domain), episodes_of);
        assert_eq!(eval.stdout, deploy.stdout);
        assert_eq!(eval.stdout, domain.stdout);
        let with_steps = !flags.is_empty();
        assert_eq!(
            episodes_of.iter().all(|t| !t.trajectory.is_empty()),
            with_steps
        );

        let discounted = mean(&episodes_of, |t| t.discounted_return);
        let undiscounted = mean(&episodes_of, |t| t.undiscounted_return);
        assert_eq!(
            summary(&eval),
            format!(
                "{episodes} episode(s) of warehouse in-process, seed {seed}: \
                 mean discounted return {discounted:.4}, mean undiscounted {undiscounted:.4}"
            )
        );
        assert_eq!(
            summary(&deploy),
            format!(
                "{episodes} episode(s) of warehouse with 3 robot process(es), seed {seed}: \
                 mean discounted return {discounted:.4}"
            )
        );
        assert_eq!(
            summary(&domain),
            format!(
                "{episodes} episode(s) of warehouse with 3 remote robot(s), seed {seed}: \
                 mean discounted return {discounted:.4}"
            )
        );
    }
    // The run's seed is the default: the same first episode as --seed 7, another than --seed 5.
    let eval = |extra: &[&str]| {
        traces(&run(
            &[&["eval", "--policy", p, "--trajectories"], extra].concat()
        ))
    };
    let default_seed = eval(&[]);
    let seed_7 = eval(&["--seed", "7"]);
    let seed_5 = eval(&["--seed", "5"]);
    assert_eq!(default_seed, seed_7);
    assert_ne!(default_seed, seed_5);
}

#[test]
fn the_shared_flags_are_refused_alike_by_all_three_commands() {
    for command in ["eval", "deploy", "domain"] {
        let mut args = vec![command, "--policy", "/nonexistent/policy"];
        if command == "domain" {
            args.extend(["--robots", "127.0.0.1:9"]);
        }
        let out = run(&[&args[..], &["--episodes", "0"]].concat());
        assert_eq!(out.status.code(), Some(2), "{command}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("invalid value '0' for '--episodes <EPISODES>': must be at least 1"),
            "{command}: {err}"
        );
        let out = run(&args);
        assert_eq!(out.status.code(), Some(1), "{command}");
        assert_eq!(
            String::from_utf8_lossy(&out.stderr).lines().next(),
            Some("Error: loading policy /nonexistent/policy"),
            "{command}"
        );
    }
}

#[test]
fn domain_usage_names_the_policy_before_the_robots() {
    // Flattening the shared flags must not reorder the usage line scripts and docs show.
    let help = common::ok(&run(&["domain", "--help"]));
    assert!(
        help.contains("Usage: macdec domain [OPTIONS] --policy <POLICY> --robots <ROBOTS>"),
        "{help}"
    );
    let policy = help.find("--policy <POLICY>  ").unwrap();
    let robots = help.find("--robots <ROBOTS>  ").unwrap();
    let episodes = help.find("--episodes <EPISODES>").unwrap();
    assert!(policy < robots && robots < episodes, "{help}");
    assert!(help.contains("Policy directory the robots run"), "{help}");
}
