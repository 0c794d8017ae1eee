//! `macdec train` end to end: determinism across --jobs, resume after a kill, clear errors.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use common::BIN;

/// A tiny Box Pushing experiment: a few hundred episodes, frequent checkpoints.
const TINY: &str = r#"
name = "tiny"
methods = ["dec-hddrqn", "our1"]
seeds = "0..2"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 40
total_epi = 60
eps_l_d_steps = 40
batch_size = 16
replay_buffer_size = 2000
eval_freq = 5
checkpoint_freq = 10
"#;

fn train(config: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(BIN)
        .arg("train")
        .arg("--config")
        .arg(config)
        .arg("--out")
        .arg(out)
        .arg("--plots")
        .arg(out.join("plots"))
        .arg("--quiet")
        .args(extra)
        .output()
        .expect("macdec runs")
}

/// `macdec train --quiet` in the background, output discarded (to be killed mid-run).
fn spawn_train(config: &Path, out: &Path, extra: &[&str]) -> std::process::Child {
    Command::new(BIN)
        .args(["train", "--quiet", "--config"])
        .arg(config)
        .arg("--out")
        .arg(out)
        .args(extra)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("macdec starts")
}

/// The metrics file without its wall-clock column (the one column that is not reproducible).
fn metrics_without_time(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .map(|l| l.rsplit_once(',').map_or(l, |(head, _)| head).to_string())
        .collect()
}

#[test]
fn runs_are_bit_identical_whatever_the_job_count() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    assert!(train(&config, &a, &["--jobs", "1"]).status.success());
    assert!(train(&config, &b, &["--jobs", "2"]).status.success());
    for method in ["dec-hddrqn", "our1"] {
        for seed in 0..2 {
            let rel = format!("tiny/{method}/seed-{seed}/metrics.csv");
            let ma = metrics_without_time(&a.join(&rel));
            assert!(ma.len() > 5, "{rel}: too few rows");
            assert_eq!(ma, metrics_without_time(&b.join(&rel)), "{rel}");
        }
    }
    // Different seeds give different curves (the test can fail).
    assert_ne!(
        metrics_without_time(&a.join("tiny/our1/seed-0/metrics.csv")),
        metrics_without_time(&a.join("tiny/our1/seed-1/metrics.csv"))
    );
}

#[test]
fn a_killed_run_resumes_to_the_uninterrupted_metrics() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY.replace("total_epi = 60", "total_epi = 200")).unwrap();
    let whole = dir.path().join("whole");
    let args = ["--methods", "our1", "--seeds", "0"];
    assert!(train(&config, &whole, &args).status.success());

    let killed = dir.path().join("killed");
    let checkpoint = killed.join("tiny/our1/seed-0/checkpoint.bin");
    let mut child = spawn_train(&config, &killed, &[&args[..], &["--no-plot"]].concat());
    // Kill it once at least one checkpoint exists, mid-run.
    let start = Instant::now();
    while !checkpoint.exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(checkpoint.exists(), "no checkpoint was written");
    assert!(
        !killed.join("tiny/our1/seed-0/finished").exists(),
        "the run finished before it could be killed; make it longer"
    );
    let resumed = train(&config, &killed, &args);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    let rel = "tiny/our1/seed-0/metrics.csv";
    assert_eq!(
        metrics_without_time(&whole.join(rel)),
        metrics_without_time(&killed.join(rel))
    );
}

#[test]
fn a_run_being_trained_by_another_process_is_left_to_it_and_force_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(
        &config,
        TINY.replace("total_epi = 60", "total_epi = 1000000"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let run = out.join("tiny/our1/seed-0");
    let args = ["--methods", "our1", "--seeds", "0", "--no-plot"];
    let mut first = spawn_train(&config, &out, &args);
    let start = Instant::now();
    while !run.join("metrics.csv").exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    let metrics_before = std::fs::read(run.join("metrics.csv")).unwrap();
    // A second process on the same tree leaves the run to the first and says so.
    let second = train(&config, &out, &args);
    let err = String::from_utf8_lossy(&second.stderr);
    assert!(second.status.success(), "{err}");
    assert!(
        err.contains("left tiny/our1/seed-0 to the other process training it"),
        "{err}"
    );
    assert!(err.contains("1 run(s) left to other processes"), "{err}");
    let forced = train(&config, &out, &[&args[..], &["--force"]].concat());
    let err = String::from_utf8_lossy(&forced.stderr);
    assert!(!forced.status.success(), "{err}");
    assert!(
        err.contains("another macdec process is training this run"),
        "{err}"
    );
    // The second process touched nothing: the first one's files are still there.
    assert!(run.join("config.toml").exists());
    assert!(std::fs::read(run.join("metrics.csv")).unwrap().len() >= metrics_before.len());
    first.kill().unwrap();
    first.wait().unwrap();
    // A killed process holds no lock: the run can be taken over (here replaced with --force).
    std::fs::write(&config, TINY).unwrap();
    let after = train(&config, &out, &[&args[..], &["--force"]].concat());
    assert!(
        after.status.success(),
        "{}",
        String::from_utf8_lossy(&after.stderr)
    );
    assert!(run.join("finished").exists());
}

#[test]
fn a_second_process_with_a_different_config_fails_naming_the_difference() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(
        &config,
        TINY.replace("total_epi = 60", "total_epi = 1000000"),
    )
    .unwrap();
    let other = dir.path().join("other").join("tiny.toml");
    std::fs::create_dir_all(other.parent().unwrap()).unwrap();
    std::fs::write(
        &other,
        TINY.replace("total_epi = 60", "total_epi = 1000000")
            .replace("batch_size = 16", "batch_size = 8"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let run = out.join("tiny/our1/seed-0");
    let args = ["--methods", "our1", "--seeds", "0", "--no-plot"];
    let mut first = spawn_train(&config, &out, &args);
    let start = Instant::now();
    while !run.join(".lock").exists() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(2));
    }
    // Started while the first holds the lock, perhaps before its config.toml is written.
    let second = train(&other, &out, &args);
    first.kill().unwrap();
    first.wait().unwrap();
    let err = String::from_utf8_lossy(&second.stderr);
    assert!(!second.status.success(), "{err}");
    assert!(err.contains("batch_size"), "{err}");
    assert!(!err.contains("left tiny/our1/seed-0"), "{err}");
}

#[test]
fn links_in_the_results_tree_are_never_followed() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let outside = dir.path().join("outside");
    std::fs::create_dir_all(outside.join("our1/seed-0")).unwrap();
    std::fs::write(outside.join("precious"), "keep").unwrap();
    std::fs::write(outside.join("our1/seed-0/precious"), "keep").unwrap();
    let args = ["--methods", "our1", "--seeds", "0", "--no-plot"];
    // A linked experiment directory, with and without --force.
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::os::unix::fs::symlink(&outside, out.join("tiny")).unwrap();
    for extra in [&[][..], &["--force"][..]] {
        let o = train(&config, &out, &[&args[..], extra].concat());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{extra:?}: {err}");
        assert!(err.contains("is a symbolic link"), "{err}");
    }
    // A linked lock file or config.toml inside a real run directory.
    for planted in [".lock", "config.toml"] {
        let out = dir.path().join(format!("out-{planted}"));
        let run = out.join("tiny/our1/seed-0");
        std::fs::create_dir_all(&run).unwrap();
        let target = outside.join("precious");
        std::os::unix::fs::symlink(&target, run.join(planted)).unwrap();
        for extra in [&[][..], &["--force"][..]] {
            let o = train(&config, &out, &[&args[..], extra].concat());
            let err = String::from_utf8_lossy(&o.stderr);
            if extra.is_empty() || planted == ".lock" {
                assert!(!o.status.success(), "{planted} {extra:?}: {err}");
                assert!(err.contains("symbolic link"), "{planted} {extra:?}: {err}");
            } else {
                // --force empties the run's own directory: the link goes, not its target.
                assert!(o.status.success(), "{planted} {extra:?}: {err}");
            }
        }
    }
    let mut left: Vec<String> = walk(&outside);
    left.sort();
    assert_eq!(left, ["our1/seed-0/precious", "precious"]);
    assert_eq!(
        std::fs::read_to_string(outside.join("precious")).unwrap(),
        "keep"
    );
}

/// Every file below `root`, as paths relative to it.
fn walk(root: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(root).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            for sub in walk(&p) {
                out.push(format!(
                    "{}/{sub}",
                    p.file_name().unwrap().to_string_lossy()
                ));
            }
        } else {
            out.push(p.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    out
}

#[test]
fn a_symlinked_run_directory_is_refused_and_its_target_is_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let out = dir.path().join("out");
    let outside = dir.path().join("outside");
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(outside.join("precious"), "keep").unwrap();
    std::fs::create_dir_all(out.join("tiny/our1")).unwrap();
    std::os::unix::fs::symlink(&outside, out.join("tiny/our1/seed-0")).unwrap();
    for extra in [&[][..], &["--force"][..]] {
        let o = train(
            &config,
            &out,
            &[
                &["--methods", "our1", "--seeds", "0", "--no-plot"][..],
                extra,
            ]
            .concat(),
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{extra:?}: {err}");
        assert!(err.contains("is a symbolic link"), "{err}");
    }
    let left: Vec<_> = std::fs::read_dir(&outside)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["precious"]);
}

#[test]
fn finished_runs_are_not_recomputed() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let out = dir.path().join("out");
    let args = ["--methods", "our1", "--seeds", "0"];
    assert!(train(&config, &out, &args).status.success());
    let metrics = out.join("tiny/our1/seed-0/metrics.csv");
    let before = std::fs::metadata(&metrics).unwrap().modified().unwrap();
    let again = train(&config, &out, &args);
    assert!(again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("already finished"));
    assert_eq!(
        before,
        std::fs::metadata(&metrics).unwrap().modified().unwrap()
    );
}

#[test]
fn bad_config_keys_and_values_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let out = dir.path().join("out");
    for (set, needle) in [
        ("total_episodes=3", "total_episodes"),
        ("batch_size=0", "batch_size"),
        ("l_rate=abc", "l_rate"),
    ] {
        let o = train(&config, &out, &["--set", set]);
        assert!(!o.status.success(), "{set} was accepted");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{set}: {err}");
        assert!(!err.contains("panicked"), "{set}: {err}");
    }
    let o = train(&config, &out, &["--seeds", "3..1"]);
    assert!(!o.status.success());
    let o = train(&config, &out, &["--methods", "our9"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("our9"));
}

#[test]
fn a_diverging_run_fails_clearly_and_the_others_finish() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let out = dir.path().join("out");
    // An absurd learning rate makes Our-1's Q-values overflow within a few updates.
    let o = train(&config, &out, &["--set", "our1.l_rate=1e30"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("our1 seed 0: non-finite") && err.contains("at episode"),
        "{err}"
    );
    assert!(err.contains("2 of 4 run(s) failed"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for seed in 0..2 {
        assert!(out
            .join(format!("tiny/dec-hddrqn/seed-{seed}/finished"))
            .exists());
        assert!(!out.join(format!("tiny/our1/seed-{seed}/finished")).exists());
    }
}

#[test]
fn names_that_climb_out_of_out_are_refused_before_anything_is_touched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a/b/out");
    let victim = dir.path().join("a/escape");
    std::fs::create_dir_all(victim.join("our1/seed-0")).unwrap();
    std::fs::write(victim.join("our1/seed-0/precious"), b"keep").unwrap();
    for name in ["../escape", "/tmp/abs", "", "x\ny"] {
        let config = dir.path().join("bad.toml");
        let text = TINY.replace("name = \"tiny\"", &format!("name = {}", toml_string(name)));
        std::fs::write(&config, text).unwrap();
        let o = train(&config, &out, &["--force", "--no-plot"]);
        assert!(!o.status.success(), "{name:?} accepted");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("experiment name"), "{name:?}: {err}");
        assert!(!out.exists(), "{name:?}: something was written");
    }
    assert!(victim.join("our1/seed-0/precious").exists());
}

fn toml_string(s: &str) -> String {
    format!(
        "\"{}\"",
        s.replace('\\', "\\\\")
            .replace('"', "\\\"")
            .replace('\n', "\\n")
    )
}

#[test]
fn a_finished_run_whose_config_differs_is_refused_naming_the_key_and_the_figure_stays_in_out() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY.replace("total_epi = 60", "total_epi = 10")).unwrap();
    let out = dir.path().join("out");
    let args = ["--methods", "our1", "--seeds", "0"];
    // No --plots: the figure goes into the results root, not ./plots of the working directory.
    let o = Command::new(BIN)
        .args(["train", "--quiet", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .args(args)
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("tiny.png").exists());
    assert!(!dir.path().join("plots").exists());

    let run_config = out.join("tiny/our1/seed-0/config.toml");
    let text = std::fs::read_to_string(&run_config).unwrap();
    std::fs::write(
        &run_config,
        text.replace("batch_size = 16", "batch_size = 8"),
    )
    .unwrap();
    let o = train(&config, &out, &args);
    assert!(!o.status.success(), "a stale run was reused");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("batch_size (on disk 8, requested 16)") && err.contains("--force"),
        "{err}"
    );
    assert!(train(&config, &out, &[&args[..], &["--force"]].concat())
        .status
        .success());
}

#[test]
fn slurm_refuses_values_that_would_break_the_script() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    for extra in [
        vec!["--time", "01:00:00\necho pwned"],
        vec!["--sbatch=--partition=cpu\necho pwned"],
        vec!["--set", "total_epi=60\necho pwned"],
    ] {
        let o = Command::new(BIN)
            .args(["slurm", "--config"])
            .arg(&config)
            .args(&extra)
            .output()
            .unwrap();
        assert!(!o.status.success(), "{extra:?} accepted");
        assert!(o.stdout.is_empty(), "{extra:?}: a script was printed");
    }
}

#[test]
fn another_runs_or_a_damaged_checkpoint_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY.replace("total_epi = 60", "total_epi = 20")).unwrap();
    let out = dir.path().join("out");
    let args = ["--methods", "our1", "--no-plot"];
    assert!(train(&config, &out, &args).status.success());
    let seed = |k: u32| out.join(format!("tiny/our1/seed-{k}"));
    std::fs::remove_file(seed(0).join("finished")).unwrap();
    std::fs::copy(
        seed(1).join("checkpoint.bin"),
        seed(0).join("checkpoint.bin"),
    )
    .unwrap();
    let o = train(&config, &out, &args);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("belongs to another run: seed \"1\""), "{err}");

    let mut bytes = std::fs::read(seed(1).join("checkpoint.bin")).unwrap();
    bytes.extend_from_slice(b"garbage");
    std::fs::write(seed(0).join("checkpoint.bin"), &bytes).unwrap();
    let err = String::from_utf8_lossy(&train(&config, &out, &args).stderr).into_owned();
    assert!(err.contains("trailing bytes"), "{err}");
    // A dead writer's temp file is cleaned up when the run resumes (no --force: nothing else
    // would remove it).
    std::fs::remove_file(seed(0).join("checkpoint.bin")).unwrap();
    let stale = seed(0).join(".checkpoint.bin.4294967.tmp");
    std::fs::write(&stale, b"half").unwrap();
    assert!(train(&config, &out, &args).status.success());
    assert!(!stale.exists());
    assert!(seed(0).join("finished").exists());
}
