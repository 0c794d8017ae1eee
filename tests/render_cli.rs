//! Only `macdec render` draws (issue 11: "a domain without a renderer still trains, evaluates,
//! plots and exports"): a run whose domain `render` cannot draw is refused with the domain named,
//! never a panic, and no other command reaches the renderer.

mod common;

use common::{ok, run};
use std::path::Path;

/// A tiny Box Pushing run: a second of training.
const TINY: &str = r#"
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

#[test]
fn a_run_of_a_domain_render_cannot_draw_is_refused_naming_the_domain() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let results = dir.path().join("results");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    ok(&run(&[
        "train",
        "--quiet",
        "--no-plot",
        "--config",
        &s(&config),
        "--out",
        &s(&results),
    ]));
    let trained = results.join("tiny/our1/seed-1");
    let gif = dir.path().join("ok.gif");
    ok(&run(&["render", "--run", &s(&trained), "--out", &s(&gif)]));
    assert!(gif.is_file());

    // The same run as a build with one more domain (and no picture of it) would write it.
    let policy_json = trained.join("policy/policy.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&policy_json).unwrap()).unwrap();
    v["env"] = serde_json::json!({"env": "rendezvous", "horizon": 20});
    std::fs::write(&policy_json, v.to_string()).unwrap();
    let gif = dir.path().join("refused.gif");
    let out = run(&["render", "--run", &s(&trained), "--out", &s(&gif)]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("rendezvous") && !err.contains("panicked"),
        "{err}"
    );
    assert!(!gif.exists());
}

/// The renderer (`src/render`, with its run rollouts in `render/rollout.rs`) is reached only by
/// the command line's `macdec render` (`cli/`): training, evaluation, plots, export and deployment never name
/// it, so a domain without a picture loses only `render`.
#[test]
fn only_the_render_command_reaches_the_renderer() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut users = Vec::new();
    let mut stack = vec![src.clone()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs")
                && !path.starts_with(src.join("render"))
            {
                let text = std::fs::read_to_string(&path).unwrap();
                if text.contains("crate::render") || text.contains("macdec::render") {
                    users.push(path.strip_prefix(&src).unwrap().display().to_string());
                }
            }
        }
    }
    users.sort();
    assert_eq!(users, ["cli/mod.rs"]);
}
