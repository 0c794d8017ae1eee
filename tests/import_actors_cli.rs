//! `macdec import --reference macromarl` as a process (issue 27): MacroMARL actor state_dicts
//! (written here with the actor's tensor names, no torch needed) import into a policy directory
//! whose nets are actors; `eval` runs them exactly as `deploy` does on robot processes, greedy
//! with each GRU state carried; bad files are refused naming the file and tensor, and nothing is
//! written. (The authors' own trained actors are checked by `scripts/macromarl_actors_check.sh`
//! against the reference's greedy episodes; their weights are not part of this repository.)

mod common;

use common::{run, stdout_lines, weight};
use macdec::deploy::drive::driver::EpisodeTrace;
use macdec::envs::{EnvSpec, MacroEnv};
use macdec::policy_files::architecture::{synthetic_weights, Architecture};
use macdec::policy_files::load_all;
use macdec::policy_files::NetKind;
use std::path::{Path, PathBuf};

/// One actor file per agent of `env` with widths `mlp` and hidden size `hidden`.
fn write_actors(dir: &Path, env: &EnvSpec, mlp: [usize; 2], hidden: usize) -> Vec<PathBuf> {
    let built = env.build().unwrap();
    let arch = Architecture::gru_actor(mlp, hidden);
    (0..built.n_agents())
        .map(|i| {
            let bytes =
                synthetic_weights(&arch, built.obs_sizes()[i], built.n_actions()[i], weight(i));
            let path = dir.join(format!("actor{i}.safetensors"));
            std::fs::write(&path, bytes).unwrap();
            path
        })
        .collect()
}

fn list(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(",")
}

#[test]
fn imported_actors_evaluate_exactly_as_deployed_on_robot_processes() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("params.json");
    let env = macdec::envs::bp_ma_v0::spec(6, 100);
    let agents = write_actors(dir.path(), &env, [16, 12], 8);
    let policy = dir.path().join("policy");
    // A kwarg MacroMARL's script passes to every env but Box Pushing does not read is refused by
    // name, as `train` refuses it, and so is --tb-m-noisy, which BP-MA-v0 has no key for.
    std::fs::write(&params, r#"{"grid_dim": [6, 6], "TB_move_speed": 0.8}"#).unwrap();
    let agent_list = list(&agents);
    let import = |extra: &[&str]| {
        let args = [
            &[
                "import",
                "--reference",
                "macromarl",
                "--env",
                "BP-MA-v0",
                "--params",
                params.to_str().unwrap(),
                "--agents",
                &agent_list,
                "--out",
                policy.to_str().unwrap(),
            ][..],
            extra,
        ]
        .concat();
        run(&args)
    };
    let refused = import(&[]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && stderr.contains("`TB_move_speed`"),
        "{stderr}"
    );
    std::fs::write(&params, r#"{"grid_dim": [6, 6]}"#).unwrap();
    let refused = import(&["--tb-m-noisy", "0.3"]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && stderr.contains("`tb_m_noisy`"),
        "{stderr}"
    );
    assert!(!policy.exists(), "a refused import writes nothing");
    let out = run(&[
        "import",
        "--reference",
        "macromarl",
        "--env",
        "BP-MA-v0",
        "--params",
        params.to_str().unwrap(),
        "--agents",
        &list(&agents),
        "--out",
        policy.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (manifest, _) = load_all(&policy).unwrap();
    assert_eq!(manifest.env, env);
    assert_eq!(manifest.discount, 0.98);
    assert!(manifest.nets.iter().all(
        |n| n.kind == NetKind::Actor && n.architecture == Architecture::gru_actor([16, 12], 8)
    ));

    let p = policy.to_str().unwrap();
    let common = ["--policy", p, "--episodes", "2", "--trajectories"];
    let eval = stdout_lines(&run(&[&["eval"][..], &common].concat()));
    let deploy = stdout_lines(&run(&[&["deploy"][..], &common].concat()));
    assert_eq!(eval.len(), 2);
    assert_eq!(eval, deploy);
    // Greedy and deterministic: both episodes are the same; the actors act (not one action).
    assert_eq!(
        eval[0].replace("\"episode\":0", ""),
        eval[1].replace("\"episode\":1", "")
    );
    let trace: EpisodeTrace = serde_json::from_str(&eval[0]).unwrap();
    let mut actions: Vec<Vec<usize>> = trace
        .trajectory
        .iter()
        .map(|s| s.executed.clone())
        .collect();
    actions.dedup();
    assert!(actions.len() > 1, "{actions:?}");
}

#[test]
fn bad_actor_files_and_arguments_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let env = macdec::envs::bp_ma_v0::spec(10, 100);
    let agents = write_actors(dir.path(), &env, [8, 8], 4);
    // A Warehouse-sized actor for Box Pushing: the observation size is wrong.
    let wtd = macdec::envs::warehouse::spec(150, 0.0);
    let wtd_dir = dir.path().join("wtd");
    std::fs::create_dir(&wtd_dir).unwrap();
    let wrong = write_actors(&wtd_dir, &wtd, [8, 8], 4);
    let ddrqn = dir.path().join("ddrqn.safetensors");
    std::fs::write(
        &ddrqn,
        synthetic_weights(&Architecture::ddrqn(8, 4), 5, 8, weight(0)),
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let o = out_dir.to_str().unwrap();
    let import = |extra: &[&str]| {
        let mut args = vec!["import", "--reference", "macromarl", "--out", o];
        args.extend(extra);
        let out = run(&args);
        assert!(!out.status.success(), "accepted {extra:?}");
        assert!(!out_dir.exists(), "wrote something for {extra:?}");
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let a0 = agents[0].to_str().unwrap();
    let a1 = agents[1].to_str().unwrap();
    let e = import(&["--env", "BP-MA-v0", "--agents", a0]);
    assert!(e.contains("has 2 agents, 1 state_dict files"), "{e}");
    let e = import(&[
        "--env",
        "BP-MA-v0",
        "--agents",
        &format!("{a0},{}", ddrqn.display()),
    ]);
    assert!(
        e.contains("ddrqn.safetensors") && e.contains("gru.weight_hh_l0"),
        "{e}"
    );
    let w0 = wrong[0].to_str().unwrap();
    let e = import(&["--env", "BP-MA-v0", "--agents", &format!("{w0},{a1}")]);
    assert!(
        e.contains("fc1.weight") && e.contains("5 observation values"),
        "{e}"
    );
    // Agents whose actors have different widths: named as such, not as an unreadable file.
    let narrow_dir = dir.path().join("narrow");
    std::fs::create_dir(&narrow_dir).unwrap();
    let narrow = write_actors(&narrow_dir, &env, [6, 8], 4);
    let n1 = narrow[1].to_str().unwrap();
    let e = import(&["--env", "BP-MA-v0", "--agents", &format!("{a0},{n1}")]);
    assert!(
        e.contains("widths [6, 8]")
            && e.contains("[8, 8]")
            && e.contains("share one architecture")
            && !e.contains("not a safetensors file"),
        "{e}"
    );
    let e = import(&["--env", "Pong-v0", "--agents", a0]);
    assert!(e.contains("unknown domain `Pong-v0`"), "{e}");
    let e = import(&["--env", "BP-MA-v0", "--grid", "10", "--agents", a0]);
    assert!(e.contains("--grid is for --reference icra"), "{e}");
    let params = dir.path().join("p.json");
    std::fs::write(&params, r#"{"grid_dim": [6, 8]}"#).unwrap();
    let e = import(&[
        "--env",
        "BP-MA-v0",
        "--params",
        params.to_str().unwrap(),
        "--agents",
        &format!("{a0},{a1}"),
    ]);
    assert!(e.contains("grid_dim") && e.contains("square"), "{e}");
}
