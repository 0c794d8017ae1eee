//! Training numbers never change by accident: short runs of every method on both domains must
//! reproduce, byte for byte (wall clock aside), the metrics recorded in `tests/fixtures/metrics/`.
//! The committed 40-seed reproduction depends on this; a change that alters numerics must say so,
//! re-record these files (`MACDEC_RECORD_FIXTURES=1 cargo test --release --test
//! metrics_unchanged`) and recompute the affected results.
//!
//! The fixtures were recorded on the AVX-512 kernel path; other paths round differently, so on a
//! CPU without AVX-512 the comparison is skipped with a message (the fixtures name their path).

use macdec::experiment::config::{Experiment, Overrides};
use macdec::experiment::metrics::{read_text, METRICS_FILE};
use macdec::experiment::runner::Progress;
use macdec::experiment::train_run::train_run;
use std::path::Path;

/// (fixture name, experiment TOML) of every method on both domains, a few dozen episodes each
/// with evaluation every 5, so hundreds of updates (and, on Warehouse, target syncs) happen.
const CASES: [(&str, &str); 9] = [
    (
        "bp10_dec-hddrqn",
        "methods = [\"dec-hddrqn\"]\n[params]\nenv_name = \"BP_MA\"\n",
    ),
    (
        "bp10_cen-ddrqn",
        "methods = [\"cen-ddrqn\"]\n[params]\nenv_name = \"BP_MA\"\n",
    ),
    (
        "bp10_our1",
        "methods = [\"our1\"]\n[params]\nenv_name = \"BP_MA\"\n",
    ),
    (
        "bp10_our1-r",
        "methods = [\"our1-r\"]\n[params]\nenv_name = \"BP_MA\"\n",
    ),
    (
        "wtd_dec-hddrqn",
        "methods = [\"dec-hddrqn\"]\n[params]\nenv_name = \"OSD_S_4\"\n",
    ),
    (
        "wtd_cen-ddrqn",
        "methods = [\"cen-ddrqn\"]\n[params]\nenv_name = \"OSD_S_4\"\n",
    ),
    (
        "wtd_our1",
        "methods = [\"our1\"]\n[params]\nenv_name = \"OSD_S_4\"\n",
    ),
    (
        "wtd_our1-r",
        "methods = [\"our1-r\"]\n[params]\nenv_name = \"OSD_S_4\"\n",
    ),
    (
        "wtd_our2",
        "methods = [\"our2\"]\n[params]\nenv_name = \"OSD_S_4\"\n",
    ),
];

const KERNEL_PATH: &str = "avx512";

fn without_wall_seconds(text: &str) -> String {
    text.lines()
        .map(|l| l.rsplit_once(',').map_or(l, |(rest, _)| rest))
        .collect::<Vec<_>>()
        .join("\n")
}

fn train(name: &str, toml_text: &str, root: &Path) -> String {
    let overrides = Overrides {
        seeds: Some(vec![3]),
        set: vec![
            "total_epi=60".into(),
            "eval_freq=5".into(),
            "target_update_freq=200".into(),
            "eps_l_d_steps=40".into(),
        ],
        ..Default::default()
    };
    let exp = Experiment::parse(toml_text, Path::new("case.toml"), name, &overrides).unwrap();
    let runs = exp.runs().unwrap();
    assert_eq!(runs.len(), 1);
    let dir = runs[0].dir(root);
    train_run(&runs[0], &dir, &Progress::hidden(), false).unwrap();
    let text = read_text(&dir.join(METRICS_FILE)).unwrap();
    without_wall_seconds(&String::from_utf8(text).unwrap())
}

#[test]
fn every_method_and_domain_trains_to_the_recorded_metrics() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/metrics");
    let record = std::env::var_os("MACDEC_RECORD_FIXTURES").is_some();
    let here = macdec::autograd::kernels::kernel_path();
    if here != KERNEL_PATH && !record {
        eprintln!("skipped: fixtures are for the {KERNEL_PATH} kernel path, this CPU takes {here}");
        return;
    }
    let t = tempfile::tempdir().unwrap();
    let mut differing = Vec::new();
    for (name, text) in CASES {
        let got = train(name, text, t.path());
        let path = fixtures.join(format!("{name}.csv"));
        if record {
            std::fs::create_dir_all(&fixtures).unwrap();
            std::fs::write(&path, &got).unwrap();
            continue;
        }
        let want = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e} (record with MACDEC_RECORD_FIXTURES=1)",
                path.display()
            )
        });
        assert!(
            got.lines().count() == 14,
            "{name}: expected a header and 13 rows"
        );
        if let Some((i, (g, w))) = got
            .lines()
            .zip(want.lines())
            .enumerate()
            .find(|(_, (g, w))| g != w)
        {
            differing.push(format!("{name} line {}: got {g}\n  recorded {w}", i + 1));
        } else if got.lines().count() != want.lines().count() {
            differing.push(format!("{name}: row counts differ"));
        }
    }
    assert!(
        differing.is_empty(),
        "training numbers changed:\n{}",
        differing.join("\n")
    );
}
