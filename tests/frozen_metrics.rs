//! Training numbers are frozen (issues 11 and 40): every method trains to exactly the metrics
//! recorded before a refactor could move them.
//!
//! `tests/frozen_metrics/<group>_<method>.csv` are seed-0 `metrics.csv` files with the
//! `wall_seconds` column removed, from `macdec train --config <group's toml> --seeds 0` with the
//! group's `--set` keys (below); the experiment files are copied beside them so later edits to
//! `experiments/` cannot move them.
//!
//! - `bp`, `wtd`, `bpvar`, `wtdnoisy`: the five ICRA methods on Box Pushing and Warehouse, plus
//!   the `dynamic_h = false`, `cen_explore = false` and noisy-Warehouse paths, recorded by the
//!   binary built before the issue-11 refactor (commit 2e0e1ef), which matches the build that
//!   trained the committed `reproduction/` runs (a4f2208). They predate
//!   `eval_return_undiscounted`, so that column is not compared for them.
//! - `acbp`, `acwh`, `acoc`: the six actor-critic methods on MacroMARL's Box Pushing 6x6, the
//!   four published ones on Warehouse A and Mac-CAC and Mac-IAICC on Overcooked A (3 agents),
//!   recorded at 5060c3c before the family seam of issue 40, which trained the committed
//!   `reproduction/macromarl` runs' numbers (audited identical). Four lanes, an update every 4
//!   episodes, a target sync every 8, epsilon decaying over the run: every part of the loop.
//! - `vbp`, `vwh`: MacroMARL's value-based MacDec-Q and MacCen-Q on Box Pushing 8x8 (windows
//!   memory) and Warehouse A (episodes memory, 3 agents), recorded at 305770f before the speed-ups
//!   of issue 44 (`experiments/macromarl_value/{bp8,wh_a}.toml` copied as `value_*.toml`). Updates
//!   from episode 10 on, a target sync every 50 steps, epsilon and hysteresis moving over the run.
//!
//! The files were recorded on the AVX-512 kernel path; every kernel path has its arithmetic
//! (`autograd::kernels::gemm`), so they are compared on every CPU.

use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_macdec");

/// The ICRA groups' length: 13 evaluations.
const ICRA: [&str; 2] = ["total_epi=60", "eval_freq=5"];
/// The actor-critic groups' schedule: 12 evaluations.
const AC: [&str; 6] = [
    "n_env=4",
    "train_freq=4",
    "c_target_update_freq=8",
    "eps_stable_at=48",
    "total_epi=96",
    "eval_freq=8",
];

/// The value-based groups' schedule: 13 evaluations.
const VALUE: [&str; 7] = [
    "total_epi=60",
    "start_train=10",
    "train_freq=5",
    "target_update_freq=50",
    "eps_l_d_steps=40",
    "h_stable_at=40",
    "eval_freq=5",
];

/// One group of recorded runs.
struct Group {
    name: &'static str,
    experiment: &'static str,
    methods: &'static str,
    /// The group's schedule ([`ICRA`], [`AC`] or [`VALUE`]).
    schedule: &'static [&'static str],
    /// Overrides beyond the schedule (later ones win).
    extra: &'static [&'static str],
    /// Evaluations in each run's curve.
    evaluations: usize,
}

const GROUPS: [Group; 9] = [
    Group {
        name: "bp",
        experiment: "fig4a_bp10.toml",
        methods: "dec-hddrqn,cen-ddrqn,our1,our1-r",
        schedule: &ICRA,
        extra: &[],
        evaluations: 13,
    },
    Group {
        name: "wtd",
        experiment: "fig5_wtd.toml",
        methods: "dec-hddrqn,cen-ddrqn,our1,our1-r,our2",
        schedule: &ICRA,
        extra: &[],
        evaluations: 13,
    },
    Group {
        name: "bpvar",
        experiment: "fig4a_bp10.toml",
        methods: "dec-hddrqn,our1",
        schedule: &ICRA,
        extra: &["dynamic_h=false", "our1.cen_explore=false"],
        evaluations: 13,
    },
    Group {
        name: "wtdnoisy",
        experiment: "fig5_wtd.toml",
        methods: "dec-hddrqn,our2",
        schedule: &ICRA,
        extra: &["tb_m_noisy=0.1", "eval_num_epi=3"],
        evaluations: 13,
    },
    Group {
        name: "acbp",
        experiment: "bp6.toml",
        methods: "mac-iac,mac-cac,naive-mac-iacc,naive-mac-iasc,mac-iaicc,mac-iaisc",
        schedule: &AC,
        extra: &[],
        evaluations: 12,
    },
    Group {
        name: "acwh",
        experiment: "wh_a.toml",
        methods: "mac-iac,mac-cac,naive-mac-iacc,mac-iaicc",
        schedule: &AC,
        extra: &[],
        evaluations: 12,
    },
    Group {
        name: "acoc",
        experiment: "overcooked_a.toml",
        methods: "mac-cac,mac-iaicc",
        schedule: &AC,
        extra: &["total_epi=48"],
        evaluations: 6,
    },
    Group {
        name: "vbp",
        experiment: "value_bp8.toml",
        methods: "mac-dec-q,mac-cen-q",
        schedule: &VALUE,
        extra: &[],
        evaluations: 13,
    },
    Group {
        name: "vwh",
        experiment: "value_wh_a.toml",
        methods: "mac-dec-q,mac-cen-q",
        schedule: &VALUE,
        extra: &["batch_size=8", "train_freq=50"],
        evaluations: 13,
    },
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
    for g in &GROUPS {
        let group = g.name;
        let mut cmd = Command::new(BIN);
        cmd.arg("train")
            .arg("--config")
            .arg(fixtures().join(g.experiment))
            .args(["--methods", g.methods, "--seeds", "0"])
            .args(["--no-plot", "--quiet", "--out"])
            .arg(out.join(group));
        for kv in g.schedule.iter().chain(g.extra) {
            cmd.args(["--set", kv]);
        }
        let run = cmd.output().expect("macdec runs");
        assert!(
            run.status.success(),
            "{group}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let experiment = g.experiment.trim_end_matches(".toml");
        for method in g.methods.split(',') {
            let got = std::fs::read_to_string(
                out.join(group)
                    .join(experiment)
                    .join(method)
                    .join("seed-0/metrics.csv"),
            )
            .unwrap();
            let want =
                std::fs::read_to_string(fixtures().join(format!("{group}_{method}.csv"))).unwrap();
            assert_eq!(
                want.lines().count(),
                1 + g.evaluations,
                "{group} {method}: {} evaluations",
                g.evaluations
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
    assert_eq!(compared, 13 + 12 + 4);
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
