//! Training numbers are frozen (issue 11): every method on Box Pushing and Warehouse, plus the
//! `dynamic_h = false`, `cen_explore = false` and noisy-Warehouse paths, trains to exactly the
//! metrics recorded by the binary built before the issue-11 refactor (commit 2e0e1ef).
//!
//! `tests/frozen_metrics/<group>_<method>.csv` are that binary's seed-0 `metrics.csv` files with
//! the `wall_seconds` column removed, from `macdec train --config <group's toml> --set
//! total_epi=60 --set eval_freq=5 --seeds 0..3` and the group's extra `--set` keys (below); the
//! two experiment files are copied beside them so later edits to `experiments/` cannot move them.
//! They match the build that trained the committed `reproduction/` runs (a4f2208) too.
//!
//! The files were recorded on the AVX-512 kernel path; other paths round differently, so on a CPU
//! without AVX-512 the comparison is skipped with a message.

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_macdec");

/// (group, experiment file, methods, extra overrides).
const GROUPS: [(&str, &str, &str, &[&str]); 4] = [
    (
        "bp",
        "fig4a_bp10.toml",
        "dec-hddrqn,cen-ddrqn,our1,our1-r",
        &[],
    ),
    (
        "wtd",
        "fig5_wtd.toml",
        "dec-hddrqn,cen-ddrqn,our1,our1-r,our2",
        &[],
    ),
    (
        "bpvar",
        "fig4a_bp10.toml",
        "dec-hddrqn,our1",
        &["dynamic_h=false", "our1.cen_explore=false"],
    ),
    (
        "wtdnoisy",
        "fig5_wtd.toml",
        "dec-hddrqn,our2",
        &["tb_m_noisy=0.1", "eval_num_epi=3"],
    ),
];

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/frozen_metrics")
}

/// The CSV text without its `wall_seconds` column (the one column that is not reproducible).
fn without_wall_seconds(text: &str) -> String {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let drop = header
        .iter()
        .position(|&h| h == "wall_seconds")
        .expect("a wall_seconds column");
    std::iter::once(text.lines().next().unwrap())
        .chain(lines)
        .map(|l| {
            l.split(',')
                .enumerate()
                .filter(|&(i, _)| i != drop)
                .map(|(_, v)| v)
                .collect::<Vec<_>>()
                .join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[test]
fn every_method_and_domain_trains_to_the_recorded_metrics() {
    let here = macdec::autograd::kernels::kernel_path();
    if here != "avx512" {
        eprintln!(
            "skipped: the recorded metrics are for the avx512 kernel path, this CPU takes {here}"
        );
        return;
    }
    let out = std::env::temp_dir().join(format!("macdec-frozen-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let mut compared = 0;
    for (group, file, methods, extra) in GROUPS {
        let mut cmd = Command::new(BIN);
        cmd.arg("train")
            .arg("--config")
            .arg(fixtures().join(file))
            .args(["--methods", methods, "--seeds", "0"])
            .args(["--set", "total_epi=60", "--set", "eval_freq=5"])
            .args(["--no-plot", "--quiet", "--out"])
            .arg(out.join(group));
        for kv in extra {
            cmd.args(["--set", kv]);
        }
        let run = cmd.output().expect("macdec runs");
        assert!(
            run.status.success(),
            "{group}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let experiment = file.trim_end_matches(".toml");
        for method in methods.split(',') {
            let got = std::fs::read_to_string(
                out.join(group)
                    .join(experiment)
                    .join(method)
                    .join("seed-0/metrics.csv"),
            )
            .unwrap();
            let want =
                std::fs::read_to_string(fixtures().join(format!("{group}_{method}.csv"))).unwrap();
            assert!(
                want.lines().count() == 14,
                "{group} {method}: 13 evaluations"
            );
            assert_eq!(
                without_wall_seconds(&got),
                want,
                "{group} {method}: metrics moved"
            );
            compared += 1;
        }
    }
    assert_eq!(compared, 13);
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn the_comparison_sees_a_changed_number() {
    let text = "episode,wall_seconds,eval_return\n0,0.5,1.0\n";
    assert_eq!(without_wall_seconds(text), "episode,eval_return\n0,1.0\n");
    assert_ne!(
        without_wall_seconds(text),
        without_wall_seconds("episode,wall_seconds,eval_return\n0,0.5,1.5\n")
    );
}
