//! `macdec plot` and `macdec results` on a results tree: where figures go by default, the
//! smoothing option, and the tidy table against the committed figures' own numbers.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

mod common;

use common::BIN;

/// Two short runs of one method (a few seconds).
const TINY: &str = r#"
name = "tiny_plot"
methods = ["our1"]
seeds = "0..2"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 40
eps_l_d_steps = 20
batch_size = 8
replay_buffer_size = 500
eval_freq = 5
"#;

fn macdec(cwd: &Path, args: &[&str]) -> std::process::Output {
    Command::new(BIN)
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("macdec runs")
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn plot_by_default_writes_beside_the_results_never_into_plots() {
    let t = tempfile::tempdir().unwrap();
    std::fs::write(t.path().join("tiny.toml"), TINY).unwrap();
    // A checkout's committed figures.
    let plots = t.path().join("plots");
    std::fs::create_dir(&plots).unwrap();
    std::fs::write(plots.join("tiny_plot.png"), "committed").unwrap();
    let o = macdec(
        t.path(),
        &["train", "--config", "tiny.toml", "--quiet", "--no-plot"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = macdec(t.path(), &["plot"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(files_in(&plots), ["tiny_plot.png"]);
    assert_eq!(
        std::fs::read_to_string(plots.join("tiny_plot.png")).unwrap(),
        "committed"
    );
    let results = t.path().join("results");
    for f in ["tiny_plot.png", "tiny_plot.svg", "tiny_plot_summary.csv"] {
        assert!(results.join(f).is_file(), "{f}");
    }
    // 9 evaluations: too few to smooth by default, and the table says which curve it read.
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.contains("95% of optimal first at (unsmoothed mean)"),
        "{table}"
    );
    // An explicit --out plots is the one way to redraw them.
    let o = macdec(t.path(), &["plot", "--out", "plots", "--smooth", "3"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("(mean smoothed over 3 evaluations)"));
    assert_ne!(
        std::fs::read(plots.join("tiny_plot.png")).unwrap(),
        b"committed"
    );
    // A window that cannot be centred is refused by name.
    let o = macdec(t.path(), &["plot", "--smooth", "20"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("odd") && err.contains("19 or 21"), "{err}");

    // The tidy table: one row per evaluation of each run, to a file or to stdout.
    let o = macdec(t.path(), &["results", "--out", "all.csv"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(t.path().join("all.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "experiment,method,variant,seed,episode,env_steps,updates,eval_return,eval_return_undiscounted,epsilon,hysteresis,loss,wall_seconds"
    );
    assert_eq!(lines.len(), 1 + 2 * 9);
    assert!(lines[1].starts_with("tiny_plot,our1,,0,0,"), "{}", lines[1]);
    let o = macdec(t.path(), &["results"]);
    assert_eq!(String::from_utf8_lossy(&o.stdout), text);
    let o = macdec(t.path(), &["results", "--results", "nowhere"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("nowhere"));
}

/// The committed tree's tidy table gives the committed figures' final returns: one definition
/// of a run's "last 10%" (ceil(n / 10) evaluations) for the plot, the table and the scripts.
#[test]
fn the_tidy_table_of_the_reproduction_gives_the_committed_final_returns() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("fig4a.csv");
    let o = Command::new(BIN)
        .arg("results")
        .arg("--results")
        .arg(root.join("reproduction"))
        .arg("--out")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut reader = csv::Reader::from_path(&csv).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (exp, method, seed, ret) = (
        col("experiment"),
        col("method"),
        col("seed"),
        col("eval_return"),
    );
    // (experiment, method) -> seed -> returns in episode order.
    let mut runs: BTreeMap<(String, String), BTreeMap<u64, Vec<f64>>> = BTreeMap::new();
    for r in reader.records() {
        let r = r.unwrap();
        runs.entry((r[exp].to_string(), r[method].to_string()))
            .or_default()
            .entry(r[seed].parse().unwrap())
            .or_default()
            .push(r[ret].parse().unwrap());
    }
    let mut checked = 0;
    for summary in ["fig4a_bp10", "fig5_wtd", "macromarl/bp6", "macromarl/wh_a"] {
        let path = root.join("plots").join(format!("{summary}_summary.csv"));
        let mut s = csv::Reader::from_path(&path).unwrap();
        let h = s.headers().unwrap().clone();
        let at = |name: &str| h.iter().position(|x| x == name).unwrap();
        for row in s.records() {
            let row = row.unwrap();
            let curve = row[at("curve")].to_string();
            let seeds = &runs[&(summary.to_string(), curve.clone())];
            let finals: Vec<f64> = seeds
                .values()
                .map(|r| {
                    let k = r.len().div_ceil(10).max(1);
                    r[r.len() - k..].iter().sum::<f64>() / k as f64
                })
                .collect();
            let mean = finals.iter().sum::<f64>() / finals.len() as f64;
            let committed: f64 = row[at("final_mean")].parse().unwrap();
            assert_eq!(finals.len(), row[at("final_n")].parse::<usize>().unwrap());
            assert!(
                (mean - committed).abs() < 1e-9,
                "{summary} {curve}: {mean} vs {committed}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 14);
}
