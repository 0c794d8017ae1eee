//! Only `macdec render` draws (issue 11: "a domain without a renderer still trains, evaluates,
//! plots and exports"): a run whose domain `render` cannot draw is refused with the domain named,
//! never a panic, and no other command reaches the renderer.

mod common;

use common::{ok, run, train_tiny_run};
use std::path::Path;

#[test]
fn a_run_of_a_domain_render_cannot_draw_is_refused_naming_the_domain() {
    let dir = tempfile::tempdir().unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let trained = train_tiny_run(dir.path());
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
/// the command line's `macdec render` (`cli/render.rs`): training, evaluation, plots, export and
/// deployment never name it, so a domain without a picture loses only `render`.
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
    assert_eq!(users, ["cli/render.rs"]);
}
