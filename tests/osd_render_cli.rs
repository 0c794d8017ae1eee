//! `macdec render` draws runs of MacroMARL's Warehouse domains: a tiny run of each of OSD-D-v7
//! (3 agents) and OSD-F-v0 (4 agents, a wider floor) trains from a config naming the gym id and
//! renders to a GIF.

mod common;

use common::{ok, run};
use std::path::Path;

fn tiny(env_name: &str) -> String {
    format!(
        r#"
name = "tiny"
methods = ["dec-hddrqn"]
seeds = "0..1"

[params]
env_name = "{env_name}"
env_terminate_step = 30
total_epi = 10
batch_size = 4
replay_buffer_size = 100
eval_freq = 5
eval_num_epi = 1
"#
    )
}

#[test]
fn warehouse_runs_render_to_a_gif() {
    for env_name in ["OSD-D-v7", "OSD-F-v0"] {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("tiny.toml");
        std::fs::write(&config, tiny(env_name)).unwrap();
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
        let recorded =
            std::fs::read_to_string(results.join("tiny/dec-hddrqn/seed-0/config.toml")).unwrap();
        assert!(recorded.contains("human_speed_per_step"), "{recorded}");
        let gif = dir.path().join("osd.gif");
        let trained = results.join("tiny/dec-hddrqn/seed-0");
        ok(&run(&["render", "--run", &s(&trained), "--out", &s(&gif)]));
        let bytes = std::fs::read(&gif).unwrap();
        assert!(
            bytes.starts_with(b"GIF89a") && bytes.len() > 1000,
            "{env_name}"
        );
    }
}
