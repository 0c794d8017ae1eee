//! `macdec import` and `macdec eval` as processes (issue 12): state_dicts written here with the
//! reference's names (both schemes, no torch needed) import into a policy directory that `eval`
//! runs exactly as `deploy` does on robot processes; bad files are refused with the file and
//! tensor named, and nothing is written.

mod common;

use common::{agents_arg, run, stdout_lines, weight, write_agents};
use macdec::algos::value::method::ValueMethod;
use macdec::deploy::drive::driver::EpisodeTrace;
use macdec::deploy::policy::import::{reference_state_dict, Naming};
use macdec::envs::EnvSpec;
use macdec::policy_files::architecture::Architecture;
use macdec::policy_files::{load_all, POLICY_FILE};

#[test]
fn imported_policies_evaluate_exactly_as_deployed_on_robot_processes() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(EnvSpec, Vec<&str>, Vec<Naming>); 2] = [
        (
            macdec::envs::box_pushing::spec(10, 100),
            vec!["--env", "box-pushing", "--grid", "10", "--horizon", "100"],
            vec![Naming::Rnn, Naming::Lstm],
        ),
        (
            macdec::envs::warehouse::spec(150, 0.3),
            vec![
                "--env",
                "warehouse",
                "--horizon",
                "150",
                "--tb-m-noisy",
                "0.3",
            ],
            vec![Naming::Lstm],
        ),
    ];
    for (k, (env, env_args, namings)) in cases.into_iter().enumerate() {
        let sub = dir.path().join(format!("case-{k}"));
        std::fs::create_dir(&sub).unwrap();
        let arch = Architecture::ddrqn(16, 8);
        let agents = write_agents(&sub, env.clone(), &arch, &namings);
        let policy = sub.join("policy");
        let agents_list = agents_arg(&agents);
        let mut args = vec!["import"];
        args.extend(&env_args);
        args.extend(["--agents", &agents_list, "--out", policy.to_str().unwrap()]);
        let out = run(&args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (manifest, _) = load_all(&policy).unwrap();
        assert_eq!(manifest.env, env);
        assert!(manifest.nets.iter().all(|n| n.architecture == arch));
        assert_eq!(manifest.run.method, "imported");
        assert_eq!(
            manifest.run.config["files"][0]["file"],
            agents[0].display().to_string()
        );

        let p = policy.to_str().unwrap();
        let common = [
            "--policy",
            p,
            "--episodes",
            "3",
            "--seed",
            "5",
            "--trajectories",
        ];
        let eval = stdout_lines(&run(&[&["eval"][..], &common].concat()));
        let deploy = stdout_lines(&run(&[&["deploy"][..], &common].concat()));
        assert_eq!(eval.len(), 3);
        assert_eq!(eval, deploy, "eval and deploy differ on {}", env.name());

        let traces: Vec<EpisodeTrace> = eval
            .iter()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        let mut actions: Vec<Vec<usize>> = traces[0]
            .trajectory
            .iter()
            .map(|s| s.executed.clone())
            .collect();
        actions.sort();
        actions.dedup();
        assert!(actions.len() > 1, "{actions:?}");

        // Without --trajectories: the same lines less the steps; another seed, other episodes
        // when the domain is noisy.
        let short = stdout_lines(&run(&[
            "eval",
            "--policy",
            p,
            "--episodes",
            "3",
            "--seed",
            "5",
        ]));
        for (line, trace) in short.iter().zip(&traces) {
            assert_eq!(*line, trace.json_line(false));
            assert!(!line.contains("trajectory"), "{line}");
        }
        if env.env_name() == "OSD_S_4" {
            let other = stdout_lines(&run(&[
                "eval",
                "--policy",
                p,
                "--episodes",
                "1",
                "--seed",
                "6",
                "--trajectories",
            ]));
            assert_ne!(other[0], eval[0]);
        }
    }
}

#[test]
fn the_same_weights_under_either_naming_import_to_identical_policies() {
    let dir = tempfile::tempdir().unwrap();
    let env = macdec::envs::box_pushing::spec(10, 100);
    let arch = Architecture::ddrqn(8, 4);
    let mut weights = Vec::new();
    for naming in [Naming::Lstm, Naming::Rnn] {
        let sub = dir.path().join(format!("{naming:?}"));
        std::fs::create_dir(&sub).unwrap();
        let agents = write_agents(&sub, env.clone(), &arch, &[naming]);
        let out = sub.join("policy");
        let status = run(&[
            "import",
            "--env",
            "box-pushing",
            "--grid",
            "10",
            "--horizon",
            "100",
            "--agents",
            &agents_arg(&agents),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(status.status.success());
        weights.push(std::fs::read(out.join("agent-1.safetensors")).unwrap());
    }
    assert_eq!(weights[0], weights[1]);
}

#[test]
fn bad_state_dicts_and_arguments_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let env = macdec::envs::box_pushing::spec(10, 100);
    let arch = Architecture::ddrqn(8, 4);
    let agents = write_agents(dir.path(), env, &arch, &[Naming::Rnn]);
    // Agent 1's file written for the wrong observation size.
    let wrong = dir.path().join("wrong.safetensors");
    std::fs::write(
        &wrong,
        reference_state_dict(&arch, 6, 8, Naming::Rnn, weight(1)),
    )
    .unwrap();
    let out = dir.path().join("policy");
    let o = out.to_str().unwrap();
    let bp = [
        "import",
        "--env",
        "box-pushing",
        "--grid",
        "10",
        "--horizon",
        "100",
    ];
    let a0 = agents[0].display().to_string();
    let cases: Vec<(Vec<String>, String)> = vec![
        (
            vec![format!("{a0},{}", wrong.display())],
            format!(
                "{}: tensor `fc1.weight` has shape [8, 6], expected [8, 5]",
                wrong.display()
            ),
        ),
        (vec![a0.clone()], "2 agents, 1 state_dict".into()),
        (
            vec![format!("{a0},{}", dir.path().display())],
            "not a regular file".into(),
        ),
        (
            vec![format!("{a0},{}", dir.path().join("none").display())],
            "none".into(),
        ),
    ];
    for (agents, needle) in cases {
        let mut args: Vec<&str> = bp.to_vec();
        args.extend(["--agents", &agents[0], "--out", o]);
        let res = run(&args);
        let err = String::from_utf8_lossy(&res.stderr);
        assert!(!res.status.success());
        assert!(err.contains(&needle), "expected `{needle}` in: {err}");
        assert!(!out.join(POLICY_FILE).exists());
    }
    let res = run(&[
        "import",
        "--env",
        "box-pushing",
        "--horizon",
        "100",
        "--agents",
        &a0,
        "--out",
        o,
    ]);
    assert!(String::from_utf8_lossy(&res.stderr).contains("needs --grid"));
    let res = run(&["eval", "--policy", dir.path().to_str().unwrap()]);
    assert!(!res.status.success());
    assert!(String::from_utf8_lossy(&res.stderr).contains(POLICY_FILE));
}

/// The discount `macdec import` writes by default ([`EnvSpec::paper_discount`]) is the one the
/// learner's paper defaults train with: the paper's, Box Pushing 0.98 and Warehouse 1.0 (`docs/ALGORITHMS.md` §10).
#[test]
fn deploys_paper_discounts_are_the_learners() {
    use macdec::algos::families::Method;
    for (spec, paper) in [
        (macdec::envs::box_pushing::paper_spec(10), 0.98),
        (macdec::envs::box_pushing::paper_spec(30), 0.98),
        (macdec::envs::warehouse::paper_spec(), 1.0),
    ] {
        assert_eq!(spec.paper_discount(), Some(paper), "{spec:?}");
        for method in [
            Method::Value(ValueMethod::Our1),
            Method::Value(ValueMethod::CenDdrqn),
            Method::Value(ValueMethod::DecHddrqn),
        ] {
            assert_eq!(
                method.defaults(&spec).discount(),
                paper,
                "{spec:?} {method:?}"
            );
        }
    }
}
