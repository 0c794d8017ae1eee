//! A run's policy files (issue 11): training writes `<run>/policy/` with one safetensors file per
//! net and `policy.json`; `export` and `render` work from those alone (no `checkpoint.bin`), and
//! keep working on run directories whose `policy.json` or `config.toml` lacks keys a later
//! version adds or carries keys this version does not know.

use macdec::experiment::run::results_tree::CHECKPOINT;
use macdec::experiment::run::train_run::load_checkpoint;
use macdec::nn::ActingNet;
use macdec::policy_files::{read_policy_files, NetRole, POLICY_DIR, POLICY_FILE};
use std::path::Path;
use std::process::Command;

mod common;

use common::{ok, render_returns as returns, BIN};

/// A tiny Box Pushing experiment with one decentralized and one centralized method.
const TINY: &str = r#"
name = "tiny"
methods = ["our1", "cen-ddrqn"]
seeds = "2..3"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 40
eps_l_d_steps = 20
batch_size = 8
replay_buffer_size = 1000
eval_freq = 20
checkpoint_freq = 20
"#;

fn macdec(args: &[&str], paths: &[&Path]) -> std::process::Output {
    let mut cmd = Command::new(BIN);
    cmd.args(args);
    for p in paths {
        cmd.arg(p);
    }
    cmd.output().unwrap()
}

fn export(run: &Path, out: &Path) -> std::process::Output {
    let mut cmd = Command::new(BIN);
    cmd.args(["export", "--run"]).arg(run).arg("--out").arg(out);
    cmd.output().unwrap()
}

fn render(run: &Path, out: &Path) -> std::process::Output {
    render_net(run, out, &[])
}

/// `render` with extra flags (`--net cen`, ...).
fn render_net(run: &Path, out: &Path, flags: &[&str]) -> std::process::Output {
    let mut cmd = Command::new(BIN);
    cmd.args(["render", "--run"]).arg(run).arg("--out").arg(out);
    cmd.args(flags);
    cmd.output().unwrap()
}

#[test]
fn policy_files_outlive_the_checkpoint_and_tolerate_added_and_missing_keys() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let results = dir.path().join("results");
    ok(&macdec(
        &["train", "--quiet", "--no-plot", "--config"],
        &[&config, Path::new("--out"), &results],
    ));

    // The files, named by net, holding exactly the checkpoint's nets.
    let our1 = results.join("tiny/our1/seed-2");
    let cen = results.join("tiny/cen-ddrqn/seed-2");
    for f in [
        "dec_agent_0.safetensors",
        "dec_agent_1.safetensors",
        "cen.safetensors",
        POLICY_FILE,
    ] {
        assert!(our1.join(POLICY_DIR).join(f).is_file(), "{f}");
    }
    assert!(!cen
        .join(POLICY_DIR)
        .join("dec_agent_0.safetensors")
        .exists());
    let trainer = load_checkpoint(&our1.join(CHECKPOINT)).unwrap();
    let policy = read_policy_files(&our1).unwrap();
    let saved: Vec<ActingNet> = trainer
        .saved_nets()
        .iter()
        .map(|n| n.net.to_net())
        .collect();
    let read: Vec<ActingNet> = policy.agents.iter().chain(&policy.team).cloned().collect();
    assert_eq!(read, saved);
    assert_eq!(read.len(), 3);
    assert_eq!(
        (
            policy.manifest.run.method.as_str(),
            policy.manifest.run.seed,
            policy.manifest.run.episodes_trained
        ),
        ("our1", 2, 40)
    );
    assert_eq!(policy.manifest.evaluated, NetRole::Dec);
    assert_eq!(
        read_policy_files(&cen).unwrap().manifest.evaluated,
        NetRole::Cen
    );

    // Export and render need no checkpoint.
    let gif_before = dir.path().join("before.gif");
    let returns_before = returns(&render(&our1, &gif_before));
    let cen_returns = returns(&render(&cen, &dir.path().join("cen.gif")));

    // --net picks the nets: Our-1's centralized net acts as Cen-DDRQN's does; `dec` is Our-1's
    // default; a Cen-DDRQN run has no decentralized nets to pick, and says so.
    let our1_cen_gif = dir.path().join("our1-cen.gif");
    let our1_cen = returns(&render_net(&our1, &our1_cen_gif, &["--net", "cen"]));
    let our1_dec_gif = dir.path().join("our1-dec.gif");
    assert_eq!(
        returns(&render_net(&our1, &our1_dec_gif, &["--net", "dec"])),
        returns_before
    );
    assert_eq!(
        std::fs::read(&our1_dec_gif).unwrap(),
        std::fs::read(&gif_before).unwrap()
    );
    assert_ne!(
        std::fs::read(&our1_cen_gif).unwrap(),
        std::fs::read(&gif_before).unwrap(),
        "the centralized net acts differently ({our1_cen} vs {returns_before})"
    );
    assert_eq!(
        returns(&render_net(
            &cen,
            &dir.path().join("c.gif"),
            &["--net", "cen"]
        )),
        cen_returns
    );
    let out = render_net(&cen, &dir.path().join("d.gif"), &["--net", "dec"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("has no decentralized net (method cen-ddrqn)"),
        "{err}"
    );
    let out = render_net(&our1, &dir.path().join("x.gif"), &["--net", "joint"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("expected `cen` or `dec`"));
    for run in [&our1, &cen] {
        std::fs::remove_file(run.join(CHECKPOINT)).unwrap();
    }
    let exported = dir.path().join("export");
    ok(&export(&our1, &exported));
    let gif = dir.path().join("after.gif");
    assert_eq!(returns(&render(&our1, &gif)), returns_before);
    assert_eq!(
        std::fs::read(&gif).unwrap(),
        std::fs::read(&gif_before).unwrap()
    );

    // An older run directory: its policy.json lacks keys a later version adds (here the
    // optional `agent` of no net) and its config.toml lacks a config key; a newer one carries
    // keys this version does not know. Plotting, export and render still read them.
    let json = our1.join(POLICY_DIR).join(POLICY_FILE);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    v["added_by_a_later_version"] = serde_json::json!({"x": 1});
    v["config"]
        .as_object_mut()
        .unwrap()
        .remove("replay_buffer_size");
    v["config"]["a_new_hyperparameter"] = serde_json::json!(0.5);
    v["nets"][0]["new_net_key"] = serde_json::json!("y");
    std::fs::write(&json, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let toml_path = our1.join("config.toml");
    let text = std::fs::read_to_string(&toml_path).unwrap();
    let older: String = text
        .lines()
        .filter(|l| !l.starts_with("replay_buffer_size") && !l.starts_with("sub_trace_len"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(older, text);
    std::fs::write(&toml_path, older).unwrap();

    ok(&export(&our1, &dir.path().join("export-again")));
    assert_eq!(
        returns(&render(&our1, &dir.path().join("again.gif"))),
        returns_before
    );
    let plots = dir.path().join("plots");
    ok(&macdec(
        &["plot", "--results"],
        &[&results, Path::new("--out"), &plots],
    ));
    assert!(std::fs::read_dir(&plots).unwrap().next().is_some());

    // A run from before policy files: a clear error saying what is missing.
    std::fs::remove_dir_all(cen.join(POLICY_DIR)).unwrap();
    let out = render(&cen, &dir.path().join("none.gif"));
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("has no policy/policy.json"), "{err}");
}
