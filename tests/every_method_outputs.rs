//! `eval`, `export` and the robot commands on a trained run of every method (issue 40 item 3;
//! ACAC's three, issue 41): each policy evaluates with the nets its training evaluated (the agents'
//! own, or one centralized net for the team), actors sample as MacroMARL evaluates, and where a
//! centralized net makes no sense (an export for robots, a robot serving one agent) the refusal
//! names the centralized Q-net or actor. The centralized Q-net acts as Cen-DDRQN's evaluation
//! does, step by step. `Policy.load`/`act` on the same methods is
//! `python/tests/test_every_method.py`; `render` is `tests/render_every_method.rs`.

mod common;

use common::{ok, render_returns, run, traces, train_config};
use macdec::algos::value::acting::{select_cen, ActScratch};
use macdec::deploy::drive::driver::EpisodeTrace;
use macdec::deploy::drive::local_eval::Choice;
use macdec::deploy::drive::team::CentralPolicy;
use macdec::envs::{EnvRng, MacroEnv};
use macdec::experiment::run::metrics;
use macdec::nn::{ActingNet, Params, QNet, QNetConfig};
use rand::SeedableRng;
use std::path::{Path, PathBuf};

/// The five ICRA methods on Box Pushing 8x8 (deterministic: a greedy episode's return is the
/// same from any seed), three evaluations, a second of training each; with this seed every
/// method's final policy returns something else than standing still (-2.27).
const TINY_VALUE: &str = r#"
name = "tiny"
methods = ["dec-hddrqn", "cen-ddrqn", "our1", "our1-r", "our2"]
seeds = "1..2"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 40
eps_l_d_steps = 10
batch_size = 8
replay_buffer_size = 500
eval_freq = 20
checkpoint_freq = 20
sample_epi = true
"#;

/// The six actor-critic methods on Box Pushing 6x6, a few updates each.
const TINY_AC: &str = r#"
name = "tiny"
methods = ["mac-iac", "mac-cac", "naive-mac-iacc", "naive-mac-iasc", "mac-iaicc", "mac-iaisc"]
seeds = "0..1"

[params]
env_name = "BP-MA-v0"
grid_dim = [6, 6]
env_terminate_step = 30
total_epi = 16
n_env = 4
train_freq = 4
c_target_update_freq = 8
eval_freq = 8
eval_num_epi = 2
"#;

const VALUE: [&str; 5] = ["dec-hddrqn", "cen-ddrqn", "our1", "our1-r", "our2"];
const AC: [&str; 6] = [
    "mac-iac",
    "mac-cac",
    "naive-mac-iacc",
    "naive-mac-iasc",
    "mac-iaicc",
    "mac-iaisc",
];

/// The methods whose policy is one centralized net, and what that net is.
fn centralized(method: &str) -> Option<&'static str> {
    match method {
        "cen-ddrqn" => Some("centralized Q-net"),
        "mac-cac" => Some("centralized actor"),
        _ => None,
    }
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `eval` of the policy directory `policy`, `episodes` episodes, with extra flags.
fn eval(policy: &Path, episodes: usize, flags: &[&str]) -> std::process::Output {
    let n = episodes.to_string();
    let args = [&["eval", "--policy", s(policy), "--episodes", &n], flags].concat();
    run(&args)
}

/// The command failed, and its message holds every one of `needles`.
fn refused(out: &std::process::Output, needles: &[&str]) -> String {
    assert!(!out.status.success(), "expected a refusal");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    for n in needles {
        assert!(err.contains(n), "expected `{n}` in: {err}");
    }
    err
}

/// Every value of `key` in a command's JSON lines, parsed from the text with Rust's correctly
/// rounded parser (serde_json's default one may be one unit in the last place off).
fn json_numbers(out: &std::process::Output, key: &str) -> Vec<f64> {
    let needle = format!("\"{key}\":");
    ok(out)
        .lines()
        .map(|line| {
            let at = line.find(&needle).expect("the key is in every line") + needle.len();
            let text = &line[at..];
            let end = text.find([',', '}']).unwrap_or(text.len());
            text[..end].parse().unwrap()
        })
        .collect()
}

/// The returns `render` printed (`team returns [a, b]`), as numbers.
fn rendered(out: &std::process::Output) -> Vec<f64> {
    let text = render_returns(out);
    let list = text.trim_start_matches("team returns ");
    let list = list.trim_end_matches(')').trim_matches(['[', ']']);
    list.split(", ").map(|x| x.parse().unwrap()).collect()
}

/// Export `run_dir` to `out`, or the refusal of a centralized policy naming its net.
fn check_export(method: &str, run_dir: &Path, out: &Path) -> Option<PathBuf> {
    let exported = run(&["export", "--run", s(run_dir), "--out", s(out)]);
    match centralized(method) {
        Some(net) => {
            refused(
                &exported,
                &["no decentralized nets", &format!("its policy is its {net}")],
            );
            assert!(!out.exists(), "{method}: nothing written");
            None
        }
        None => {
            ok(&exported);
            Some(out.to_path_buf())
        }
    }
}

/// The robot commands refuse a centralized policy by naming its net; they serve every other.
fn check_robots(method: &str, policy: &Path, greedy: &[EpisodeTrace]) {
    let n = greedy.len().to_string();
    let deployed = run(&["deploy", "--policy", s(policy), "--episodes", &n]);
    match centralized(method) {
        Some(net) => {
            let why = format!("it acts only through its {net}");
            refused(&deployed, &[&why, "macdec eval"]);
            let robot = run(&["robot", "--policy", s(policy), "--agent", "0"]);
            refused(&robot, &["agent 0 has no decentralized net", &why]);
        }
        // Robot processes give exactly the in-process episodes.
        None => assert_eq!(traces(&deployed), greedy, "{method}"),
    }
}

#[test]
fn every_value_method_evaluates_exports_and_serves_or_refuses_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let results = train_config(dir.path(), TINY_VALUE);
    for method in VALUE {
        let run_dir = results.join("tiny").join(method).join("seed-1");
        let policy = run_dir.join("policy");
        let greedy_out = eval(&policy, 2, &[]);
        let greedy = traces(&greedy_out);
        // The domain is deterministic and the last evaluation ran the final nets: `eval` gives
        // the return training recorded, whichever nets (the agents', or Cen-DDRQN's centralized
        // one) the method evaluates.
        let table = metrics::read(&run_dir.join("metrics.csv")).unwrap();
        let last = table.rows.last().unwrap();
        assert_eq!(last.episode, 40, "{method}");
        let returns = json_numbers(&greedy_out, "return");
        assert_eq!(returns, [last.eval_return; 2], "{method}");
        assert_ne!(
            format!("{:.2}", last.eval_return),
            "-2.27",
            "{method}: stood still"
        );
        // A Q-net does not sample.
        let sampled = eval(&policy, 1, &["--sample"]);
        refused(&sampled, &["is a Q-net", "needs an actor policy"]);
        let exported = check_export(method, &run_dir, &dir.path().join(format!("{method}-x")));
        if let Some(x) = exported {
            assert_eq!(traces(&eval(&x, 2, &[])), greedy, "{method}");
        }
        check_robots(method, &policy, &greedy);
    }
}

/// What every actor policy of a trained run does (`method`'s run in `run_dir`, scratch files in
/// `dir`): greedy and sampled `eval` (sampling seeded by the run's seed: the same draws again),
/// `render` playing the same episodes from the same streams, an export acting the same, and
/// robots giving the greedy episodes (or refusing a centralized policy by name). Returns eval's
/// greedy output.
fn check_actor_policy(method: &str, run_dir: &Path, dir: &Path) -> std::process::Output {
    let policy = run_dir.join("policy");
    let greedy_out = eval(&policy, 3, &[]);
    let greedy = traces(&greedy_out);
    let sampled_out = eval(&policy, 3, &["--sample"]);
    let sampled = traces(&sampled_out);
    assert_eq!(
        traces(&eval(&policy, 3, &["--sample"])),
        sampled,
        "{method}"
    );
    let gif = dir.join(format!("{method}.gif"));
    let render = |flags: &[&str]| {
        let args = [
            &["render", "--run", s(run_dir), "--out", s(&gif)][..],
            &["--episodes", "3"],
            flags,
        ]
        .concat();
        rendered(&run(&args))
    };
    let undiscounted = |out| json_numbers(out, "undiscounted_return");
    assert_eq!(render(&[]), undiscounted(&greedy_out), "{method}");
    assert_eq!(
        render(&["--sample"]),
        undiscounted(&sampled_out),
        "{method}"
    );
    let exported = check_export(method, run_dir, &dir.join(format!("{method}-x")));
    if let Some(x) = exported {
        assert_eq!(traces(&eval(&x, 3, &[])), greedy, "{method}");
        let x_sampled = traces(&eval(&x, 3, &["--sample"]));
        assert_eq!(x_sampled, sampled, "{method}");
    }
    check_robots(method, &policy, &greedy);
    greedy_out
}

#[test]
fn every_actor_critic_method_evaluates_greedy_or_sampled_and_mac_cac_acts_centrally() {
    let dir = tempfile::tempdir().unwrap();
    let results = train_config(dir.path(), TINY_AC);
    for method in AC {
        let run_dir = results.join("tiny").join(method).join("seed-0");
        let greedy_out = check_actor_policy(method, &run_dir, dir.path());
        // `eval` says when the team acts through one centralized net.
        let summary = String::from_utf8_lossy(&greedy_out.stderr);
        let central = summary.contains("acting centrally with its centralized actor");
        assert_eq!(central, method == "mac-cac", "{method}: {summary}");
    }
}

/// ACAC's three methods on its bp6 (Box Pushing 6x6, ACAC's keys), a few updates each.
const TINY_ACAC: &str = r#"
name = "tiny"
methods = ["acac", "acac-vanilla", "acac-micro-gae"]
seeds = "0..1"

[params]
env_name = "BP-MA-v0"
grid_dim = [6, 6]
env_terminate_step = 30
total_epi = 12
n_env = 4
train_freq = 4
c_target_update_freq = 8
eval_freq = 8
eval_num_epi = 2
"#;

/// An ACAC run's policy files hold every agent's actor with the time table it read in training,
/// exactly the checkpoint's; `eval` (greedy and sampled), `render`, `export` and robots run them
/// as every actor policy ([`check_actor_policy`]), each passing the episode's primitive step
/// (robots get it in `"step"`).
#[test]
fn every_acac_method_writes_its_actors_and_evaluates_exports_and_serves_them() {
    use macdec::experiment::run::results_tree::CHECKPOINT;
    use macdec::experiment::run::train_run::load_checkpoint;
    use macdec::policy_files::read_policy_files;
    let dir = tempfile::tempdir().unwrap();
    let results = train_config(dir.path(), TINY_ACAC);
    for method in ["acac", "acac-vanilla", "acac-micro-gae"] {
        let run_dir = results.join("tiny").join(method).join("seed-0");
        let saved = read_policy_files(&run_dir).unwrap();
        let trainer = load_checkpoint(&run_dir.join(CHECKPOINT)).unwrap();
        let trained: Vec<ActingNet> = trainer
            .saved_nets()
            .iter()
            .map(|n| n.net.to_net())
            .collect();
        assert_eq!(saved.agents, trained, "{method}");
        assert!(saved.team.is_none());
        assert!(
            saved.agents.iter().all(ActingNet::reads_step),
            "{method}: ACAC's actors read the time"
        );
        check_actor_policy(method, &run_dir, dir.path());
    }
}

/// A ROS robot node serves a policy that reads the time by counting the observations since the
/// reset (a ROS message carries no step): `ros/test_robot_session_e2e.py` runs `macdec domain`
/// against bridges that drop macdec's step and ask `macdec robot` through the node's
/// `RobotSession`; every counted step must be macdec's and the episodes `deploy`'s. Skipped,
/// saying so, where there is no python3.
#[test]
fn ros_robot_nodes_count_the_step_an_acac_policy_reads() {
    let dir = tempfile::tempdir().unwrap();
    let config = TINY_ACAC.replace(
        r#"methods = ["acac", "acac-vanilla", "acac-micro-gae"]"#,
        r#"methods = ["acac"]"#,
    );
    let results = train_config(dir.path(), &config);
    let policy = results.join("tiny/acac/seed-0/policy");
    let ros = Path::new(env!("CARGO_MANIFEST_DIR")).join("ros");
    let out = match std::process::Command::new("python3")
        .args(["-m", "unittest", "-v", "test_robot_session_e2e"])
        .current_dir(&ros)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env("MACDEC", common::BIN)
        .env("MACDEC_TIMED_POLICY", &policy)
        .output()
    {
        Ok(out) => out,
        Err(e) => {
            eprintln!("skipped: no python3 to run ros/test_robot_session_e2e.py ({e})");
            return;
        }
    };
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("Ran 1 test") && !err.contains("skipped"),
        "{err}"
    );
}

/// A centralized Q-net for `env` with large weights, so its greedy joint action changes over an
/// episode.
fn cen_qnet(env: &impl MacroEnv) -> QNet {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let cfg = QNetConfig {
        input: env.joint_obs_size(),
        mlp: 16,
        hidden: 8,
        output: env.n_joint_actions(),
    };
    let mut net = QNet::new(cfg, &mut rng);
    for w in net.params.slices_mut() {
        w.iter_mut().for_each(|v| *v *= 4.0);
    }
    net
}

/// A greedy centralized Q-net acts exactly as the value family's conditional argmax does
/// (`select_cen`, what Cen-DDRQN's evaluations run), step by step, busy agents included.
#[test]
fn a_central_q_net_acts_as_the_conditional_argmax_of_cen_ddrqn() {
    let mut env = macdec::envs::box_pushing::spec(8, 30).build().unwrap();
    let net = cen_qnet(&env);
    let rng = EnvRng::seed_from_u64(0);
    let mut team = CentralPolicy::new(
        ActingNet::Q(net.clone()),
        env.n_actions().to_vec(),
        Choice::Greedy,
        &rng,
    )
    .unwrap();
    let mut state = net.zero_state();
    let mut scratch = ActScratch::new(&env);
    let mut env_rng = EnvRng::seed_from_u64(3);
    let mut choices = std::collections::BTreeSet::new();
    let mut busy_steps = 0;
    for _ in 0..2 {
        env.reset(&mut env_rng);
        team.reset();
        state.reset();
        let (mut ours, mut theirs) = (vec![0; 2], vec![0; 2]);
        loop {
            busy_steps += usize::from((0..2).any(|i| !env.is_free(i)));
            team.decide(&env, &mut ours).unwrap();
            select_cen(&env, &net, &mut state, None, &mut scratch, &mut theirs);
            assert_eq!(ours, theirs, "t = {}", env.t());
            choices.insert(ours.clone());
            if env.step(&ours, &mut env_rng).unwrap().done {
                break;
            }
        }
    }
    assert!(
        choices.len() > 2 && busy_steps > 0,
        "{choices:?} {busy_steps}"
    );
}
