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
//! The files were recorded on the AVX-512 kernel path; every kernel path has its arithmetic
//! (`autograd::kernels::gemm`), so they are compared on every CPU.

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

/// The CSV text with only the columns named in `keep`'s header, in its order: a recorded
/// file's columns (which lack `wall_seconds`, the one column that is not reproducible, and the
/// `eval_return_undiscounted` column added after they were recorded) picked from a new run's.
fn columns_of(text: &str, keep: &str) -> String {
    let header: Vec<&str> = text.lines().next().expect("a header").split(',').collect();
    let at: Vec<usize> = keep
        .lines()
        .next()
        .expect("a header")
        .split(',')
        .map(|name| {
            header
                .iter()
                .position(|&h| h == name)
                .unwrap_or_else(|| panic!("no `{name}` column in {header:?}"))
        })
        .collect();
    text.lines()
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            at.iter().map(|&k| cells[k]).collect::<Vec<_>>().join(",")
        })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

#[test]
fn every_method_and_domain_trains_to_the_recorded_metrics() {
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
            assert!(!want.contains("wall_seconds"), "{group} {method}");
            assert_eq!(
                columns_of(&got, &want),
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
    let want = "episode,eval_return\n0,1.0\n";
    let text = "episode,wall_seconds,eval_return,eval_return_undiscounted\n0,0.5,1.0,2.0\n";
    assert_eq!(columns_of(text, want), want);
    let moved = "episode,wall_seconds,eval_return,eval_return_undiscounted\n0,0.5,1.5,2.0\n";
    assert_ne!(columns_of(moved, want), want);
}
