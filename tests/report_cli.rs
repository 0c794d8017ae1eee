//! `macdec report` end to end on a handmade results tree whose final returns are known, on the
//! committed MacroMARL tree (against its summary tables), and on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;

use common::BIN;

/// A committed MacroMARL run's config: Box Pushing (BP-MA-v0) 6x6, whose optimum is known.
fn bp6_config() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("reproduction/macromarl/bp6/mac-iac/seed-0/config.toml");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

const HEADER: &str =
    "episode,env_steps,updates,eval_return,eps,critic_loss,actor_loss,train_return,wall_seconds";

/// A run of ten evaluations every 100 episodes whose last return is `last` (its final return:
/// the mean of the last ceil(10 / 10) = 1 evaluation), `steps_per_episode` env steps each.
fn write_run(root: &Path, method: &str, seed: u64, last: f64, steps_per_episode: u64, gz: bool) {
    let dir = root.join("bp").join(method).join(format!("seed-{seed}"));
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = format!("{HEADER}\n");
    for i in 0..10u64 {
        let episode = i * 100;
        let value = if i == 9 { last } else { i as f64 };
        text.push_str(&format!(
            "{episode},{},{i},{value},1.0,,,,{}.5\n",
            episode * steps_per_episode,
            i
        ));
    }
    if gz {
        use std::io::Write;
        let file = std::fs::File::create(dir.join("metrics.csv.gz")).unwrap();
        let mut enc = flate2::write::GzEncoder::new(file, flate2::Compression::default());
        enc.write_all(text.as_bytes()).unwrap();
        enc.finish().unwrap();
    } else {
        std::fs::write(dir.join("metrics.csv"), text).unwrap();
    }
    std::fs::write(dir.join("config.toml"), bp6_config()).unwrap();
    std::fs::write(dir.join("finished"), "").unwrap();
}

/// Mac-IAC's final returns 10, 20, 30, 40 (one stored gzipped); Mac-CAC's 100, 110, 120, 130,
/// at twice the steps per episode.
fn handmade_tree(root: &Path) {
    for (seed, last) in [10.0, 20.0, 30.0, 40.0].into_iter().enumerate() {
        write_run(root, "mac-iac", seed as u64, last, 10, seed == 2);
    }
    for (seed, last) in [100.0, 110.0, 120.0, 130.0].into_iter().enumerate() {
        write_run(root, "mac-cac", seed as u64, last, 20, false);
    }
}

fn report(results: &Path, out: &Path, extra: &[&str]) -> Output {
    Command::new(BIN)
        .arg("report")
        .arg("--results")
        .arg(results)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("macdec runs")
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn refused(o: Output, message: &str) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "accepted; stderr: {stderr}");
    assert!(stderr.contains(message), "`{message}` is not in: {stderr}");
}

/// (block, method, metric) -> (value, ci_low, ci_high, n_runs) from an aggregate CSV.
fn aggregate(path: &Path) -> Vec<(String, String, String, [f64; 3], usize)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("block,method,metric,value,ci_low,ci_high,n_runs")
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 7, "{l}");
            let num = |i: usize| f[i].parse::<f64>().unwrap();
            (
                f[0].to_string(),
                f[1].to_string(),
                f[2].to_string(),
                [num(3), num(4), num(5)],
                f[6].parse().unwrap(),
            )
        })
        .collect()
}

fn find<'a>(
    rows: &'a [(String, String, String, [f64; 3], usize)],
    method: &str,
    metric: &str,
) -> &'a (String, String, String, [f64; 3], usize) {
    rows.iter()
        .find(|r| r.1 == method && r.2 == metric)
        .unwrap_or_else(|| panic!("no {method} {metric}"))
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The BP-MA-v0 6x6 optimum (`plots/macromarl/bp6_summary.csv`'s `optimal`).
const BP6_OPTIMAL: f64 = 270.60545094431995;

#[test]
fn report_writes_hand_checked_aggregates_improvements_figures_and_marl_eval_json() {
    let t = tempfile::tempdir().unwrap();
    let results = t.path().join("results");
    handmade_tree(&results);
    let out = t.path().join("out");
    let o = ok(report(&results, &out, &["--resamples", "500"]));
    assert_eq!(
        files_in(&out),
        [
            "bp_aggregate.csv",
            "bp_improvement.csv",
            "bp_marl_eval.json",
            "bp_profile.png",
            "bp_profile.svg",
            "bp_sample_efficiency.png",
            "bp_sample_efficiency.svg",
        ]
    );

    let rows = aggregate(&out.join("bp_aggregate.csv"));
    // Paper order: Mac-IAC, then Mac-CAC; four metrics each (the optimum is known).
    assert_eq!(rows.len(), 8);
    assert_eq!(
        rows.iter()
            .map(|r| r.2.as_str())
            .take(4)
            .collect::<Vec<_>>(),
        ["iqm", "mean", "median", "optimality_gap"]
    );
    // Mac-IAC: 10, 20, 30, 40. IQM cuts int(0.25 x 4) = 1 each end: (20 + 30) / 2.
    let iqm = find(&rows, "mac-iac", "iqm");
    assert_eq!((iqm.0.as_str(), iqm.3[0], iqm.4), ("bp", 25.0, 4));
    assert!(iqm.3[1] < 25.0 && 25.0 < iqm.3[2], "{iqm:?}");
    assert_eq!(find(&rows, "mac-iac", "mean").3[0], 25.0);
    assert_eq!(find(&rows, "mac-iac", "median").3[0], 25.0);
    // Every run is below the optimum: the gap is 1 - mean / optimum.
    let gap = find(&rows, "mac-iac", "optimality_gap").3;
    assert!(
        (gap[0] - (1.0 - 25.0 / BP6_OPTIMAL)).abs() < 1e-12,
        "{gap:?}"
    );
    assert!(gap[1] <= gap[0] && gap[0] <= gap[2], "{gap:?}");
    assert_eq!(find(&rows, "mac-cac", "iqm").3[0], 115.0);

    // Every Mac-CAC run above every Mac-IAC run: certain, in every resample.
    let improvement = std::fs::read_to_string(out.join("bp_improvement.csv")).unwrap();
    assert_eq!(
        improvement,
        "method_x,method_y,probability,ci_low,ci_high\n\
         mac-iac,mac-cac,0.0,0.0,0.0\n\
         mac-cac,mac-iac,1.0,1.0,1.0\n"
    );

    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("bp_marl_eval.json")).unwrap()).unwrap();
    let envs = json.as_object().unwrap();
    assert_eq!(envs.len(), 1);
    let (env, tasks) = envs.iter().next().unwrap();
    let algos = tasks["bp"].as_object().unwrap();
    assert_eq!(algos.len(), 2);
    let run = &algos["mac-cac"]["seed_3"];
    assert_eq!(
        run.as_object().unwrap().len(),
        11,
        "ten steps and absolute_metrics"
    );
    assert_eq!(run["step_9"]["step_count"], 900 * 20);
    assert_eq!(run["step_9"]["return"], serde_json::json!([130.0]));
    assert_eq!(
        run["absolute_metrics"]["return"],
        serde_json::json!([130.0])
    );
    assert_eq!(
        algos["mac-iac"]["seed_2"]["absolute_metrics"]["return"],
        serde_json::json!([30.0])
    );
    assert!(!env.is_empty());

    let profile = std::fs::read_to_string(out.join("bp_profile.svg")).unwrap();
    for needle in [
        "Mac-IAC (n = 4 runs)",
        "Mac-CAC (n = 4 runs)",
        "normalised final return τ",
        "performance profile",
    ] {
        assert!(profile.contains(needle), "profile SVG lacks {needle:?}");
    }
    let curves = std::fs::read_to_string(out.join("bp_sample_efficiency.svg")).unwrap();
    for needle in [
        "training episodes",
        "IQM of discounted return",
        "optimal return 270.61",
    ] {
        assert!(curves.contains(needle), "curves SVG lacks {needle:?}");
    }
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("| mac-iac | 4 | 25.00 ["), "{table}");
}

#[test]
fn the_same_seed_writes_the_same_bytes_and_another_seed_other_intervals() {
    let t = tempfile::tempdir().unwrap();
    let results = t.path().join("results");
    handmade_tree(&results);
    let run = |name: &str, seed: &str| {
        let out = t.path().join(name);
        ok(report(
            &results,
            &out,
            &["--resamples", "300", "--seed", seed],
        ));
        out
    };
    let (a, b, c) = (run("a", "0"), run("b", "0"), run("c", "1"));
    for file in files_in(&a) {
        let (x, y) = (std::fs::read(a.join(&file)), std::fs::read(b.join(&file)));
        assert_eq!(
            x.unwrap(),
            y.unwrap(),
            "{file} differs between two runs of seed 0"
        );
    }
    let (ra, rc) = (
        aggregate(&a.join("bp_aggregate.csv")),
        aggregate(&c.join("bp_aggregate.csv")),
    );
    let values = |r: &[(String, String, String, [f64; 3], usize)]| -> Vec<f64> {
        r.iter().map(|x| x.3[0]).collect()
    };
    assert_eq!(
        values(&ra),
        values(&rc),
        "the seed moves intervals, not values"
    );
    assert_ne!(ra, rc, "seed 1 draws other resamples");
}

#[test]
fn env_steps_curves_interpolate_methods_of_different_speeds() {
    let t = tempfile::tempdir().unwrap();
    let results = t.path().join("results");
    handmade_tree(&results);
    // Make one Mac-IAC run slower than the others: its steps no longer line up.
    write_run(&results, "mac-iac", 1, 20.0, 11, false);
    let out = t.path().join("out");
    ok(report(
        &results,
        &out,
        &["--resamples", "50", "--x", "env_steps"],
    ));
    let svg = std::fs::read_to_string(out.join("bp_sample_efficiency.svg")).unwrap();
    assert!(svg.contains("environment steps"));
    assert!(
        svg.contains("linearly"),
        "the caption says runs were interpolated"
    );
}

#[test]
fn report_means_are_the_committed_summary_tables_final_means() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    let results = root.join("reproduction/macromarl");
    ok(report(
        &results,
        &out,
        &["--resamples", "20", "--block", "bp6"],
    ));
    assert_eq!(files_in(&out).len(), 7, "only bp6: {:?}", files_in(&out));
    let rows = aggregate(&out.join("bp6_aggregate.csv"));
    let summary = std::fs::read_to_string(root.join("plots/macromarl/bp6_summary.csv")).unwrap();
    let mut lines = summary.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let mut compared = 0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let mean = find(&rows, f[col("curve")], "mean");
        let final_mean: f64 = f[col("final_mean")].parse().unwrap();
        let final_n: usize = f[col("final_n")].parse().unwrap();
        assert!(
            (mean.3[0] - final_mean).abs() <= 1e-9 * final_mean.abs().max(1.0),
            "{}: report mean {} against summary {final_mean}",
            f[col("curve")],
            mean.3[0]
        );
        assert_eq!(mean.4, final_n);
        compared += 1;
    }
    assert_eq!(compared, 4);
}

#[test]
fn bad_input_is_refused_with_the_problem_named() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    refused(
        report(&t.path().join("nowhere"), &out, &[]),
        "cannot read the results directory",
    );
    let empty = t.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    refused(report(&empty, &out, &[]), "no runs found");
    let results = t.path().join("results");
    handmade_tree(&results);
    refused(
        report(&results, &out, &["--block", "nope"]),
        "no block `nope` with runs in the results tree (it has bp)",
    );
    refused(
        report(&results, &out, &["--resamples", "0"]),
        "must be at least 1",
    );
    refused(
        report(&results, &out, &["--resamples", "1000000"]),
        "must be at most 100000",
    );
    // The only run's metrics are not a metrics file.
    let bad = t.path().join("bad");
    let dir: PathBuf = bad.join("blk").join("mac-iac").join("seed-0");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("metrics.csv"), "episode,nonsense\n1,2\n").unwrap();
    refused(report(&bad, &out, &[]), "malformed metrics file");
    assert!(!out.exists(), "nothing written on refusal");
}
