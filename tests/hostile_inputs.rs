//! Issue 29: hostile inputs through the command line. Outputs onto things that are not regular
//! files, inputs that are not regular files or never end, a gzip bomb, crafted metadata checked
//! against train's limits by every reader, sizes from flags bounded like a config's, memory that
//! does not grow with the work, and messages that name the real problem.

mod common;

use common::{train_tiny_run, BIN};
use std::os::unix::fs::FileTypeExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::Duration;

/// One trained tiny run shared by the tests of this file (read-only: tests copy it to tamper).
fn tiny_run() -> &'static Path {
    static RUN: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, run) = RUN.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let run = train_tiny_run(dir.path());
        (dir, run)
    });
    run
}

/// A copy of the tiny run in `dir` (its results tree `dir/results/tiny/our1/seed-1`).
fn copy_of_tiny_run(dir: &Path) -> PathBuf {
    let run = dir.join("results/tiny/our1/seed-1");
    copy_dir(tiny_run(), &run);
    run
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// `macdec args`, killed (and the test failed) if it has not ended within `limit`; with
/// `max_memory` bytes of address space at most, so a command that would allocate more fails.
fn macdec_within(args: &[&str], limit: Duration, max_memory: Option<u64>) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(bytes) = max_memory {
        // SAFETY: setrlimit is async-signal-safe; nothing else runs between fork and exec.
        unsafe {
            cmd.pre_exec(move || {
                let limit = libc::rlimit {
                    rlim_cur: bytes,
                    rlim_max: bytes,
                };
                if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
    }
    let child = cmd.spawn().unwrap();
    // A watchdog kills the child at the limit, while this thread drains its output (a child
    // writing more than a pipe holds would otherwise never end).
    let pid = child.id() as libc::pid_t;
    let (done, done_rx) = std::sync::mpsc::channel::<()>();
    let watchdog = std::thread::spawn(move || {
        let killed = done_rx.recv_timeout(limit).is_err();
        if killed {
            // SAFETY: plain kill(2) of our own child, not yet reaped (the main thread is
            // still waiting for it when the timeout fires).
            unsafe { libc::kill(pid, libc::SIGKILL) };
        }
        killed
    });
    let out = child.wait_with_output().unwrap();
    let _ = done.send(());
    let killed = watchdog.join().unwrap();
    assert!(
        !killed,
        "`macdec {}` still running after {limit:?}",
        args.join(" ")
    );
    out
}

/// `macdec args` within 60 s.
fn macdec(args: &[&str]) -> Output {
    macdec_within(args, Duration::from_secs(60), None)
}

/// The failure message of a command that must fail cleanly (exit 1 or clap's 2, no panic, no
/// abort).
fn refused(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "expected a clean refusal, got {:?}: {err}",
        out.status
    );
    assert!(
        !err.contains("panicked") && !err.contains("memory allocation"),
        "{err}"
    );
    err
}

/// `macdec train ARGS --out RESULTS`, which must be refused before any run starts; its error.
fn train_refused(results: &Path, args: &[&str]) -> String {
    let mut all = vec!["train"];
    all.extend_from_slice(args);
    all.extend(["--out", s(results)]);
    let err = refused(&macdec(&all));
    assert!(!results.exists(), "{args:?}: no run may start");
    err
}

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The tiny run's two agent weight files as `import --agents` takes them.
fn tiny_agents() -> String {
    let policy = tiny_run().join("policy");
    format!(
        "{},{}",
        s(&policy.join("dec_agent_0.safetensors")),
        s(&policy.join("dec_agent_1.safetensors"))
    )
}

#[test]
fn outputs_onto_fifos_devices_and_foreign_directories_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = tiny_run();
    let fifo = dir.path().join("out.gif");
    mkfifo(&fifo);
    let err = refused(&macdec(&["render", "--run", s(run), "--out", s(&fifo)]));
    assert!(err.contains("out.gif"), "{err}");
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());

    // As root, renaming a GIF over /dev/null would have replaced the device.
    let err = refused(&macdec(&["render", "--run", s(run), "--out", "/dev/null"]));
    assert!(err.contains("/dev/null"), "{err}");
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());

    // plot writes <out>/<experiment>.png: a FIFO there is refused, not opened.
    let plots = dir.path().join("plots");
    std::fs::create_dir(&plots).unwrap();
    mkfifo(&plots.join("tiny.png"));
    let results = run.parent().unwrap().parent().unwrap().parent().unwrap();
    let err = refused(&macdec(&[
        "plot",
        "--results",
        s(results),
        "--out",
        s(&plots),
    ]));
    assert!(err.contains("tiny.png"), "{err}");

    // export and import --out: a FIFO, or a directory holding anything but policy files.
    let err = refused(&macdec(&["export", "--run", s(run), "--out", s(&fifo)]));
    assert!(err.contains("out.gif"), "{err}");
    let foreign = dir.path().join("foreign");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "mine").unwrap();
    refused(&macdec(&["export", "--run", s(run), "--out", s(&foreign)]));
    let agents = tiny_agents();
    let err = refused(&macdec(&[
        "import",
        "--env",
        "box-pushing",
        "--grid",
        "8",
        "--horizon",
        "20",
        "--agents",
        &agents,
        "--out",
        s(&foreign),
    ]));
    assert!(
        err.contains("notes.txt") || err.contains("foreign"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(foreign.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn inputs_that_are_not_regular_files_are_refused_without_waiting() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("input");
    mkfifo(&fifo);
    let quick = Duration::from_secs(20);
    // Nothing ever writes to the FIFO: opening it for reading would block for ever.
    for args in [
        vec!["train", "--config", s(&fifo), "--out", s(dir.path())],
        vec!["replay", "--actions", s(&fifo)],
        vec!["replay", "--actions", "/dev/zero"],
        vec!["train", "--config", "/dev/zero", "--out", s(dir.path())],
        vec!["replay", "--actions", s(dir.path())],
    ] {
        let err = refused(&macdec_within(&args, quick, None));
        assert!(err.contains("not a regular file"), "{args:?}: {err}");
    }
    // A policy whose description is a FIFO.
    let policy = dir.path().join("policy");
    copy_dir(&tiny_run().join("policy"), &policy);
    std::fs::remove_file(policy.join("policy.json")).unwrap();
    mkfifo(&policy.join("policy.json"));
    let err = refused(&macdec_within(
        &["eval", "--policy", s(&policy)],
        quick,
        None,
    ));
    assert!(err.contains("not a regular file"), "{err}");
}

#[test]
fn a_gzip_bomb_in_a_results_tree_stops_at_the_bound() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let run = copy_of_tiny_run(dir.path());
    std::fs::remove_file(run.join("metrics.csv")).unwrap();
    // 600 MiB of zeros, about 600 KB compressed: beyond the 512 MiB bound on metrics.
    let file = std::fs::File::create(run.join("metrics.csv.gz")).unwrap();
    let mut gz = flate2::write::GzEncoder::new(file, flate2::Compression::fast());
    let zeros = vec![b'0'; 1 << 20];
    for _ in 0..600 {
        gz.write_all(&zeros).unwrap();
    }
    gz.finish().unwrap();
    let plots = dir.path().join("plots");
    // Unbounded, the bomb took more than 4 GB; the bound keeps plot under 2 GiB of address space.
    let out = macdec_within(
        &[
            "plot",
            "--results",
            s(&dir.path().join("results")),
            "--out",
            s(&plots),
        ],
        Duration::from_secs(120),
        Some(2 << 30),
    );
    let err = refused(&out);
    assert!(
        err.contains("metrics.csv.gz") && err.contains("536870912"),
        "{err}"
    );
}

/// `policy.json` of a copy of the tiny run, edited by `edit`.
fn tamper_policy(run: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let path = run.join("policy/policy.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(&path, v.to_string()).unwrap();
}

#[test]
fn a_crafted_policy_is_refused_by_every_reader_before_it_sizes_anything() {
    let dir = tempfile::tempdir().unwrap();
    let run = copy_of_tiny_run(dir.path());
    // Within the file's byte bound, far beyond train's horizon limit: a mock robot team would
    // play it for ever and render would allocate 64 PB of frames.
    tamper_policy(&run, |v| {
        v["env"]["horizon"] = 1_000_000_000_000_000u64.into()
    });
    let policy = run.join("policy");
    let out_dir = dir.path().join("export");
    let gif = dir.path().join("x.gif");
    for args in [
        vec!["export", "--run", s(&run), "--out", s(&out_dir)],
        vec!["render", "--run", s(&run), "--out", s(&gif)],
        vec!["eval", "--policy", s(&policy)],
        vec!["deploy", "--policy", s(&policy), "--mock"],
        vec!["robot", "--policy", s(&policy), "--agent", "0"],
    ] {
        let out = macdec_within(&args, Duration::from_secs(30), Some(4 << 30));
        let err = refused(&out);
        assert!(
            err.contains("env_terminate_step") && err.contains("at most 100000"),
            "{args:?}: {err}"
        );
    }
    assert!(!gif.exists() && !out_dir.exists());

    // A custom domain's horizon is held to the same limit.
    let run = copy_of_tiny_run(&dir.path().join("custom"));
    tamper_policy(
        &run,
        |v| v["env"] = serde_json::json!({"env": "custom", "name": "corridor", "horizon": 100_001}),
    );
    let err = refused(&macdec(&[
        "robot",
        "--policy",
        s(&run.join("policy")),
        "--agent",
        "0",
    ]));
    assert!(err.contains("env.horizon"), "{err}");
}

#[test]
fn audit_refuses_a_committed_config_that_train_would_refuse() {
    let dir = tempfile::tempdir().unwrap();
    let run = copy_of_tiny_run(dir.path());
    let config = run.join("config.toml");
    let text = std::fs::read_to_string(&config).unwrap();
    for (from, to, key) in [
        ("batch_size = 8", "batch_size = 0", "`batch_size`"),
        ("l_rate = 0.001", "l_rate = nan", "`l_rate`"),
        ("total_epi = 20", "total_epi = 200000000", "`total_epi`"),
    ] {
        assert!(text.contains(from), "{text}");
        std::fs::write(&config, text.replace(from, to)).unwrap();
        let out = macdec(&["audit", "--run", s(&run)]);
        let all = format!("{}{}", String::from_utf8_lossy(&out.stdout), refused(&out));
        assert!(
            all.contains(key) && all.contains("train refuses") && !all.contains("identical"),
            "{to}: {all}"
        );
    }
}

#[test]
fn sizes_from_flags_obey_the_config_limits() {
    let run = tiny_run();
    let policy = run.join("policy");
    let agents = tiny_agents();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("imported");
    for (args, flag) in [
        (
            vec!["render", "--run", s(run), "--episodes", "100001"],
            "--episodes",
        ),
        (
            vec!["eval", "--policy", s(&policy), "--episodes", "100001"],
            "--episodes",
        ),
        (
            vec![
                "import",
                "--env",
                "box-pushing",
                "--grid",
                "8",
                "--horizon",
                "100001",
                "--agents",
                &agents,
                "--out",
                s(&out),
            ],
            "--horizon",
        ),
        (
            vec![
                "import",
                "--env",
                "box-pushing",
                "--grid",
                "1001",
                "--horizon",
                "20",
                "--agents",
                &agents,
                "--out",
                s(&out),
            ],
            "--grid",
        ),
        (
            vec![
                "robot",
                "--policy",
                s(&policy),
                "--agent",
                "0",
                "--max-line-bytes",
                "99999999999",
            ],
            "--max-line-bytes",
        ),
    ] {
        let err = refused(&macdec(&args));
        assert!(
            err.contains(flag) && err.contains("at most"),
            "{args:?}: {err}"
        );
    }
    assert!(!out.exists());
}

#[test]
fn render_keeps_two_frames_not_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let gif = dir.path().join("many.gif");
    // 300 episodes of 21 frames of about 260 x 300 pixels: 500 MB kept, a few MB streamed.
    let out = macdec_within(
        &[
            "render",
            "--run",
            s(tiny_run()),
            "--episodes",
            "300",
            "--out",
            s(&gif),
        ],
        Duration::from_secs(120),
        Some(256 << 20),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("300 episode(s)") && err.contains("mean"),
        "{err}"
    );
    let bytes = std::fs::read(&gif).unwrap();
    assert!(bytes.starts_with(b"GIF89a") && bytes.ends_with(b";"));
}

#[test]
fn replay_verbose_on_the_largest_grid_stays_small() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("big.json");
    let steps = vec![[7, 7]; 30];
    std::fs::write(
        &file,
        serde_json::json!({"env": "box-pushing", "grid": 1000, "horizon": 100000, "steps": steps})
            .to_string(),
    )
    .unwrap();
    let out = macdec_within(
        &["replay", "--actions", s(&file), "--verbose"],
        Duration::from_secs(60),
        Some(512 << 20),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 31);
}

#[test]
fn a_nan_rate_and_a_seed_beyond_the_largest_are_named_before_any_run() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("results");
    let err = train_refused(&results, &["--set", "l_rate=nan"]);
    assert!(
        err.contains("`l_rate`")
            && err.contains("positive number")
            && !err.contains("does not use"),
        "{err}"
    );
    let err = train_refused(&results, &["--seeds", "9223372036854775808"]);
    assert!(
        err.contains("9223372036854775808") && err.contains("largest"),
        "{err}"
    );
}

#[test]
fn no_key_is_dropped_a_set_with_a_line_break_nor_a_key_the_domain_does_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("results");
    let err = train_refused(&results, &["--set", "total_epi=30\neval_freq=5"]);
    assert!(err.contains("line break"), "{err}");
    for (set, key) in [
        ("tb_m_noisy=0.5", "`tb_m_noisy`"),
        ("env_name=\"BP-MA-v0\"", ""),
    ] {
        let mut args = vec!["--set", set];
        if key.is_empty() {
            // MacroMARL's Box Pushing with a kwarg only its Warehouses read.
            args.extend(["--methods", "mac-iac", "--set", "TB_move_speed=0.6"]);
        }
        let err = train_refused(&results, &args);
        let key = if key.is_empty() {
            "`TB_move_speed`"
        } else {
            key
        };
        assert!(err.contains(key) && err.contains("leave it out"), "{err}");
    }
}

#[test]
fn a_replay_file_naming_a_key_its_domain_does_not_read_is_refused_never_dropped() {
    let dir = tempfile::tempdir().unwrap();
    // macdec's own form and the reference's form, each with a key its domain does not read:
    // replayed noiseless (or with the other layout) it would not be the episode the file means.
    for (file, key) in [
        (
            r#"{"env": "box-pushing", "grid": 8, "horizon": 30, "tb_m_noisy": 0.5, "steps": [[0, 0]]}"#,
            "`tb_m_noisy`",
        ),
        (
            r#"{"env": "BP_MA", "params": {"grid_dim": 8, "tb_m_noisy": 0.5}, "steps": [[0, 0]]}"#,
            "`tb_m_noisy`",
        ),
        (
            r#"{"env": "OSD_S_4", "params": {"grid_dim": 7}, "steps": [[0, 0, 0]]}"#,
            "`grid_dim`",
        ),
        (
            r#"{"env": "BP-MA-v0", "grid_dim": [6, 6], "TB_move_speed": 0.5, "steps": [[0, 0]]}"#,
            "`TB_move_speed`",
        ),
    ] {
        let path = dir.path().join("actions.json");
        std::fs::write(&path, file).unwrap();
        let out = macdec(&["replay", "--actions", s(&path)]);
        let err = refused(&out);
        assert!(err.contains(key), "{file}: {err}");
        assert!(out.stdout.is_empty(), "{file}: nothing may be replayed");
    }
}

#[test]
fn an_unknown_key_is_hinted_from_the_methods_own_family() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("results");
    // An ICRA key given to an actor-critic method, and the other way round: the hint names the
    // family the key belongs to and the method's own keys, never the other family's.
    let err = train_refused(&results, &["--methods", "mac-iac", "--set", "l_rate=0.01"]);
    assert!(
        err.contains("unknown key `l_rate` for mac-iac")
            && err.contains("is a key of the ICRA 2020")
            && err.contains("a_lr, c_lr")
            && !err.contains("replay_buffer_size"),
        "{err}"
    );
    let err = train_refused(&results, &["--methods", "our1", "--set", "a_lr=0.01"]);
    assert!(
        err.contains("`a_lr` is a key of MacroMARL's")
            && err.contains("our1 takes the keys of the ICRA 2020")
            && !err.contains("n_env"),
        "{err}"
    );
    // A typo of the family's own key.
    let err = train_refused(&results, &["--methods", "mac-iac", "--set", "a_lrr=0.01"]);
    assert!(
        err.contains("did you mean `a_lr`?") && !err.contains("is a key of"),
        "{err}"
    );
}

#[test]
fn a_run_that_could_not_update_is_refused_never_called_finished() {
    let dir = tempfile::tempdir().unwrap();
    let results = dir.path().join("results");
    // Certain from the config: refused by name before any run starts, in every family.
    for (method, sets, key) in [
        // Actor-critic: one update per train_freq episodes.
        (
            "mac-iac",
            &["train_freq=32", "total_epi=16", "eval_freq=8"][..],
            "`train_freq`: must be at most total_epi (16)",
        ),
        // Value families: one update per train_freq main-loop steps, at most total_epi x horizon.
        (
            "our1",
            &["train_freq=100000", "total_epi=20", "eval_freq=10"][..],
            "`train_freq`: must be at most total_epi x env_terminate_step",
        ),
        (
            "mac-dec-q",
            &[
                "train_freq=100000",
                "total_epi=40",
                "start_train=2",
                "eval_freq=10",
            ][..],
            "`train_freq`: must be at most total_epi x env_terminate_step",
        ),
        (
            "our1",
            &["start_train=100", "total_epi=20", "eval_freq=10"][..],
            "`start_train`: must be at most total_epi (20)",
        ),
        (
            "mac-dec-q",
            &["start_train=40", "total_epi=40", "eval_freq=10"][..],
            "`start_train`: must be below total_epi (40)",
        ),
    ] {
        let mut args = vec!["--methods", method, "--seeds", "0"];
        for set in sets {
            args.extend(["--set", set]);
        }
        let err = train_refused(&results, &args);
        assert!(err.contains(key), "{method} {sets:?}: {err}");
    }
    // Not certain from the config (episodes ended early): the run trains its budget, then
    // fails naming why instead of "finishing" with its initial nets and exit status 0.
    let out = macdec(&[
        "train",
        "--methods",
        "our1",
        "--seeds",
        "0",
        "--set",
        "grid_dim=8",
        "--set",
        "env_terminate_step=30",
        "--set",
        "total_epi=2",
        "--set",
        "start_train=2",
        "--set",
        "eval_freq=1",
        "--set",
        "train_freq=7",
        "--out",
        s(&results),
        "--no-plot",
    ]);
    let err = refused(&out);
    assert!(err.contains("without a single update"), "{err}");
    let run = results.join("quickstart_bp10/our1/seed-0");
    assert!(
        run.join("metrics.csv").is_file(),
        "the evaluations are kept"
    );
    assert!(
        !run.join("finished").exists(),
        "a run without an update is not finished"
    );
}

#[test]
fn a_robot_reads_its_weight_file_before_building_a_net_the_manifest_sizes() {
    use sha2::Digest;
    let dir = tempfile::tempdir().unwrap();
    let run = copy_of_tiny_run(dir.path());
    let policy = run.join("policy");
    // A custom domain with 90 000 observation values (within the 1 MiB description) and the
    // widest layers: a net of 2.4 GB if built from the manifest, for a 10-byte weight file whose
    // checksum the manifest states correctly.
    let tiny_file = b"0123456789";
    let sha: String = sha2::Sha256::digest(tiny_file)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    std::fs::write(policy.join("dec_agent_0.safetensors"), tiny_file).unwrap();
    tamper_policy(&run, |v| {
        let n = 90_000;
        v["env"] = serde_json::json!({"env": "custom", "name": "wide", "horizon": 20});
        for a in v["agents"].as_array_mut().unwrap() {
            a["obs_size"] = n.into();
            a["obs_names"] = vec!["o"; n].into();
        }
        let nets: Vec<serde_json::Value> = v["nets"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|net| net["role"] == "dec")
            .cloned()
            .map(|mut net| {
                net["input"] = n.into();
                net["architecture"]["mlp_layer_size"] = 2048.into();
                if net["agent"] == 0 {
                    net["sha256"] = sha.clone().into();
                }
                net
            })
            .collect();
        v["nets"] = nets.into();
        v["evaluated"] = "dec".into();
    });
    let out = macdec_within(
        &["robot", "--policy", s(&policy), "--agent", "0"],
        Duration::from_secs(30),
        Some(512 << 20),
    );
    let err = refused(&out);
    assert!(err.contains("dec_agent_0.safetensors"), "{err}");
}

#[test]
fn a_joint_action_net_beyond_the_memory_bound_is_refused_before_any_run_starts() {
    // Mac-CAC on Overcooked B scores 15^3 = 3375 joint macro-actions: 200 episodes per update
    // would need more than 5 GB. Within 2 GB of address space the batch is refused by name
    // before any of its runs starts, so no run (Mac-IAICC's included) is lost half-way.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results");
    let config = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/experiments/macromarl/overcooked_b.toml"
    );
    let err = refused(&macdec_within(
        &[
            "train",
            "--config",
            config,
            "--methods",
            "mac-iaicc,mac-cac",
            "--seeds",
            "0",
            "--set",
            "n_env=200",
            "--set",
            "train_freq=200",
            "--out",
            s(&out),
            "--quiet",
            "--no-plot",
        ],
        Duration::from_secs(60),
        Some(2 << 30),
    ));
    assert!(
        err.contains("train_freq") && err.contains("widest output 3375"),
        "{err}"
    );
    let runs = walkdir_count(&out);
    assert_eq!(runs, 0, "{err}");
}

#[test]
fn the_largest_joint_action_batches_the_bound_allows_train_within_its_memory() {
    // The other side of the bound: at the largest batch it lets through, a joint-action net
    // (15^3 = 3375 outputs on three-cook Overcooked B) updates within 2.5 GB of address space
    // (measured: about 1 GB resident each), for the actor-critic family's Mac-CAC (24 episodes
    // per update; 25 are refused) and MacroMARL's value-based MacCen-Q (24 sequences of the
    // horizon; 25 are refused).
    let dir = tempfile::tempdir().unwrap();
    let root = env!("CARGO_MANIFEST_DIR");
    let cac = format!("{root}/experiments/macromarl/overcooked_b.toml");
    let cen_q = format!("{root}/experiments/macromarl_value/overcooked_b.toml");
    let runs: [(&str, &str, &[&str]); 2] = [
        (
            &cac,
            "mac-cac",
            &[
                "train_freq=24",
                "n_env=24",
                "total_epi=48",
                "eval_freq=24",
                "eval_num_epi=1",
            ],
        ),
        (
            &cen_q,
            "mac-cen-q",
            &[
                "n_agent=3",
                "batch_size=24",
                "start_train=30",
                "total_epi=40",
                "eval_freq=10",
            ],
        ),
    ];
    for (config, method, sets) in runs {
        let out = dir.path().join(method);
        let mut args = vec![
            "train",
            "--config",
            config,
            "--methods",
            method,
            "--seeds",
            "0",
        ];
        for set in sets {
            args.extend(["--set", set]);
        }
        args.extend(["--out", s(&out), "--quiet", "--no-plot", "--jobs", "1"]);
        let result = macdec_within(&args, Duration::from_secs(600), Some(5 << 29));
        let err = String::from_utf8_lossy(&result.stderr);
        assert!(result.status.success(), "{method}: {err}");
        // One more episode per update is refused before any run starts.
        let over: Vec<String> = sets.iter().map(|set| set.replace("=24", "=25")).collect();
        let mut args = vec![
            "train",
            "--config",
            config,
            "--methods",
            method,
            "--seeds",
            "0",
        ];
        for set in &over {
            args.extend(["--set", set.as_str()]);
        }
        let refused_out = dir.path().join(format!("{method}-over"));
        args.extend(["--out", s(&refused_out)]);
        let err = refused(&macdec(&args));
        assert!(err.contains("widest output 3375"), "{method}: {err}");
    }
}

/// Files under `dir` (0 when it does not exist).
fn walkdir_count(dir: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .map(|e| {
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                walkdir_count(&e.path())
            } else {
                1
            }
        })
        .sum()
}
