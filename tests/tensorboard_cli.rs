//! `macdec train --tensorboard DIR` end to end: one directory of event files per run, each
//! evaluation's metrics row as scalars at its episode, the same numbers as without the flag,
//! resumed runs adding a file whose session start replaces what the killed process logged after
//! its checkpoint, and a bad DIR refused before training. TensorBoard's own reader is checked
//! against the same files by `python/tests/test_tensorboard.py`.

use macdec::experiment::run::metrics::{self, MetricsTable};
use macdec::files::tensorboard::{event_files, read_events, Event, What};
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use common::BIN;

/// Box Pushing 8x8 with Our-1, two seeds: a couple of seconds per run, several checkpoints.
const VALUE: &str = r#"
name = "tiny"
methods = ["our1"]
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

/// Mac-IAC on Box Pushing 6x6 (the actor-critic family's columns).
const ACTOR_CRITIC: &str = r#"
name = "tiny_ac"
methods = ["mac-iac"]
seeds = "0"

[params]
env_name = "BP-MA-v0"
grid_dim = [6, 6]
env_terminate_step = 30
total_epi = 16
n_env = 4
train_freq = 4
c_target_update_freq = 8
eval_freq = 4
eval_num_epi = 2
"#;

fn train(config: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(BIN)
        .args(["train", "--quiet", "--no-plot", "--config"])
        .arg(config)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .expect("macdec runs")
}

fn ok(out: std::process::Output) -> std::process::Output {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// What TensorBoard shows of a run directory: its event files in name order, where a session
/// start at step s drops every point read before at step s or later (TensorBoard's
/// `EventAccumulator` with `file_version` 2). Returns each tag's (step, value) points.
fn shown(dir: &Path) -> BTreeMap<String, Vec<(i64, f32)>> {
    let mut tags: BTreeMap<String, Vec<(i64, f32)>> = BTreeMap::new();
    for file in event_files(dir).unwrap() {
        let events = read_events(&file).unwrap();
        assert_eq!(
            events[0].what,
            What::FileVersion("brain.Event:2".into()),
            "{}",
            file.display()
        );
        for Event { step, what, .. } in events {
            match what {
                What::FileVersion(_) => {}
                What::SessionStart => {
                    for points in tags.values_mut() {
                        points.retain(|&(s, _)| s < step);
                    }
                }
                What::Scalars(scalars) => {
                    for s in scalars {
                        tags.entry(s.tag).or_default().push((step, s.value));
                    }
                }
            }
        }
    }
    tags
}

/// The same curve from `metrics.csv`: every column but `episode` against the episode, as f32,
/// empty cells left out; `wall_seconds` too unless `with_time` is false.
fn expected(table: &MetricsTable, with_time: bool) -> BTreeMap<String, Vec<(i64, f32)>> {
    let mut columns: Vec<String> = ["env_steps", "updates", "eval_return"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    columns.push(metrics::EVAL_RETURN_UNDISCOUNTED.into());
    columns.extend(table.family_columns.iter().cloned());
    if with_time {
        columns.push(metrics::WALL_SECONDS.into());
    }
    let episodes = table.column("episode").unwrap();
    columns
        .into_iter()
        .map(|c| {
            let points = episodes
                .iter()
                .zip(table.column(&c).unwrap())
                .filter_map(|(e, v)| Some((e.unwrap() as i64, v? as f32)))
                .collect();
            (c, points)
        })
        .filter(|(_, points): &(String, Vec<_>)| !points.is_empty())
        .collect()
}

fn metrics_table(run: &Path) -> MetricsTable {
    metrics::read(&run.join(metrics::METRICS_FILE)).unwrap()
}

#[test]
fn each_run_logs_its_metrics_rows_at_their_episodes_and_no_number_changes() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, VALUE).unwrap();
    let tb = dir.path().join("tb");
    let with = dir.path().join("with");
    let without = dir.path().join("without");
    let shown_tb = tb.to_str().unwrap();
    let out = ok(train(
        &config,
        &with,
        &["--jobs", "2", "--tensorboard", shown_tb],
    ));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!("tensorboard --logdir {shown_tb}")),
        "{stderr}"
    );
    ok(train(&config, &without, &["--jobs", "1"]));
    for seed in 0..2 {
        let rel = format!("tiny/our1/seed-{seed}");
        let run_tb = tb.join(&rel);
        let files = event_files(&run_tb).unwrap();
        assert_eq!(files.len(), 1, "{rel}: one file per training process");
        let name = files[0].file_name().unwrap().to_str().unwrap().to_string();
        assert!(name.starts_with("events.out.tfevents."), "{name}");
        let events = read_events(&files[0]).unwrap();
        assert_eq!(events[1].what, What::SessionStart);
        let table = metrics_table(&with.join(&rel));
        assert_eq!(table.rows.len(), 1 + 60 / 5);
        // One event per row, at its episode, holding every column: f32 of the CSV's numbers.
        let steps: Vec<i64> = events[2..].iter().map(|e| e.step).collect();
        let episodes: Vec<i64> = table.rows.iter().map(|r| r.episode as i64).collect();
        assert_eq!(steps, episodes, "{rel}");
        let tags = shown(&run_tb);
        assert_eq!(tags, expected(&table, true), "{rel}");
        assert!(tags.contains_key("loss") && tags.contains_key("epsilon"));
        // Logging changes no number: the run trained without the flag has the same metrics.
        let plain = metrics_table(&without.join(&rel));
        assert_eq!(expected(&plain, false), expected(&table, false), "{rel}");
    }

    // Finished runs are skipped as before, whatever the flag, and log nothing more.
    let again = ok(train(&config, &with, &["--tensorboard", shown_tb]));
    assert!(String::from_utf8_lossy(&again.stderr).contains("2 run(s) already finished"));
    ok(train(&config, &without, &["--tensorboard", shown_tb]));
    for seed in 0..2 {
        assert_eq!(
            event_files(&tb.join(format!("tiny/our1/seed-{seed}")))
                .unwrap()
                .len(),
            1
        );
    }
}

#[test]
fn the_actor_critic_family_logs_its_own_columns() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny_ac.toml");
    std::fs::write(&config, ACTOR_CRITIC).unwrap();
    let out = dir.path().join("results");
    // The event files may sit beside metrics.csv: --tensorboard is --out.
    ok(train(
        &config,
        &out,
        &["--tensorboard", out.to_str().unwrap()],
    ));
    let run = out.join("tiny_ac/mac-iac/seed-0");
    let table = metrics_table(&run);
    assert!(
        table.family_columns.iter().any(|c| c.contains("loss")),
        "{:?}",
        table.family_columns
    );
    let tags = shown(&run);
    assert_eq!(tags, expected(&table, true));
    for c in &table.family_columns {
        assert!(tags.contains_key(c), "{c} not logged");
    }
    // The results readers still take the run directory.
    let results = Command::new(BIN)
        .arg("results")
        .arg("--results")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        results.status.success(),
        "{}",
        String::from_utf8_lossy(&results.stderr)
    );
}

#[test]
fn a_killed_run_resumes_into_a_new_file_and_tensorboard_shows_the_uninterrupted_curve() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, VALUE.replace("total_epi = 60", "total_epi = 200")).unwrap();
    let out = dir.path().join("results");
    let tb = dir.path().join("tb");
    let args = [
        "--methods",
        "our1",
        "--seeds",
        "0",
        "--tensorboard",
        tb.to_str().unwrap(),
    ];
    let run = out.join("tiny/our1/seed-0");
    let run_tb = tb.join("tiny/our1/seed-0");
    let mut child = Command::new(BIN)
        .args(["train", "--quiet", "--no-plot", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it once it has checkpointed and logged past that checkpoint.
    let start = Instant::now();
    let logged_past_checkpoint = || {
        run.join("checkpoint.bin").exists()
            && event_files(&run_tb).is_ok_and(|f| {
                f.first()
                    .and_then(|f| read_events(f).ok())
                    .is_some_and(|e| e.last().is_some_and(|e| e.step % 10 == 5))
            })
    };
    while !logged_past_checkpoint() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !run.join("finished").exists(),
        "the run finished before it could be killed; make it longer"
    );
    let killed_file = event_files(&run_tb).unwrap().remove(0);
    let killed_bytes = std::fs::read(&killed_file).unwrap();
    let last_killed = read_events(&killed_file).unwrap().last().unwrap().step;
    // metrics.csv is written with each checkpoint: it ends where the resumed run starts.
    let checkpointed = metrics_table(&run).rows.last().unwrap().episode as i64;
    assert!(
        last_killed > checkpointed,
        "the killed process logged a point after its last checkpoint ({last_killed} > {checkpointed})"
    );

    ok(train(&config, &out, &args));
    let files = event_files(&run_tb).unwrap();
    assert_eq!(files.len(), 2, "the resumed process adds a file");
    assert_eq!(files[0], killed_file);
    assert_eq!(
        std::fs::read(&killed_file).unwrap(),
        killed_bytes,
        "the killed process's file is left as it was"
    );
    // The new file alone holds the whole curve; read after the old one, the result is the
    // curve of metrics.csv, which equals an uninterrupted run's.
    let table = metrics_table(&run);
    let resumed = read_events(&files[1]).unwrap();
    assert_eq!(
        (resumed[1].step, &resumed[1].what),
        (0, &What::SessionStart)
    );
    assert_eq!(resumed.len() - 2, table.rows.len());
    let tags = shown(&run_tb);
    let mut want = expected(&table, true);
    // The wall clock of the points the killed process logged before its checkpoint is its own;
    // compare it by steps only.
    let time_steps = |m: &BTreeMap<String, Vec<(i64, f32)>>| -> Vec<i64> {
        m[metrics::WALL_SECONDS].iter().map(|p| p.0).collect()
    };
    assert_eq!(time_steps(&tags), time_steps(&want));
    let mut got = tags.clone();
    got.remove(metrics::WALL_SECONDS);
    want.remove(metrics::WALL_SECONDS);
    assert_eq!(got, want);
}

#[test]
fn a_tensorboard_dir_that_is_a_file_or_unwritable_is_refused_before_training() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, VALUE).unwrap();
    let out = dir.path().join("results");
    let file = dir.path().join("tb");
    std::fs::write(&file, "").unwrap();
    let refused = train(&config, &out, &["--tensorboard", file.to_str().unwrap()]);
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains(&format!("--tensorboard {}", file.display()))
            && stderr.contains("exists and is not a directory"),
        "{stderr}"
    );
    assert!(!out.exists(), "nothing trained or written");
    assert!(!stderr.contains("panicked"), "{stderr}");

    // A directory without write permission (root writes anyway: not checkable as root).
    if is_root() {
        return;
    }
    let locked = dir.path().join("locked");
    std::fs::create_dir(&locked).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).unwrap();
    let refused = train(&config, &out, &["--tensorboard", locked.to_str().unwrap()]);
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(stderr.contains("cannot create files in it"), "{stderr}");
    assert!(!out.exists());
}

/// Whether this process runs as root (owner of every file's permissions), from `/proc`.
fn is_root() -> bool {
    std::fs::read_to_string("/proc/self/status").is_ok_and(|s| {
        s.lines()
            .find(|l| l.starts_with("Uid:"))
            .and_then(|l| l.split_whitespace().nth(2))
            == Some("0")
    })
}
