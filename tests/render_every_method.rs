//! `macdec render` animates a trained run of every method (issue 40 item 3): the six
//! actor-critic methods' actors (Mac-CAC's centralized actor as one team policy) beside the
//! value methods' Q-nets (`tests/policy_files.rs`), greedy or sampled from the run seed's own
//! streams, and refuses a net the run does not have by naming it.

mod common;

use common::{render_returns, run, train_config};
use std::path::Path;

const AC_METHODS: [&str; 6] = [
    "mac-iac",
    "mac-cac",
    "naive-mac-iacc",
    "naive-mac-iasc",
    "mac-iaicc",
    "mac-iaisc",
];

/// Every actor-critic method on Box Pushing 6x6, a few updates each.
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

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_actor_critic_run_renders_and_a_missing_net_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let results = train_config(dir.path(), TINY_AC);
    for method in AC_METHODS {
        let run_dir = results.join("tiny").join(method).join("seed-0");
        let gif = dir.path().join(format!("{method}.gif"));
        let args = [
            "render",
            "--run",
            s(&run_dir),
            "--out",
            s(&gif),
            "--episodes",
            "2",
        ];
        let first = render_returns(&run(&args));
        let bytes = std::fs::read(&gif).unwrap();
        assert!(
            bytes.starts_with(b"GIF89a") && bytes.len() > 1000,
            "{method}"
        );
        // Greedy acting from the run's seed: the same episodes again.
        assert_eq!(render_returns(&run(&args)), first, "{method}");
        // Sampled as MacroMARL evaluates: reproducible from the run's seed too.
        let mut sampled = args.to_vec();
        sampled.push("--sample");
        let drawn = render_returns(&run(&sampled));
        assert_eq!(render_returns(&run(&sampled)), drawn, "{method} --sample");
        // The nets the method does not have are refused by name.
        let other = if method == "mac-cac" { "dec" } else { "cen" };
        let refused = run(&[
            "render",
            "--run",
            s(&run_dir),
            "--out",
            s(&gif),
            "--net",
            other,
        ]);
        assert!(!refused.status.success(), "{method} --net {other}");
        let err = String::from_utf8_lossy(&refused.stderr);
        let kind = if other == "dec" {
            "decentralized"
        } else {
            "centralized"
        };
        assert!(
            err.contains(&format!("no {kind} net (method {method})")),
            "{method}: {err}"
        );
    }
}

#[test]
fn a_q_net_run_refuses_to_sample() {
    let dir = tempfile::tempdir().unwrap();
    let run_dir = common::train_tiny_run(dir.path());
    let gif = dir.path().join("q.gif");
    let out = run(&["render", "--run", s(&run_dir), "--out", s(&gif), "--sample"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("sampling (--sample) needs an actor policy"),
        "{err}"
    );
}
