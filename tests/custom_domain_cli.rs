//! A domain defined outside macdec gets the whole command line (issue 26 item 3): the shipped
//! example (`examples/custom_domain.rs`, Rendezvous, registered through `macdec::cli::main_with`)
//! trains `examples/custom_domain.toml` with seeds and `--jobs`, resumes a killed run to the same
//! numbers, writes `finished`, plots the domain's optimum, and exports, evaluates, deploys,
//! audits and writes Slurm scripts for it; `render` says the domain draws no picture, and the
//! plain `macdec` binary, which lacks the domain, names it instead of guessing.

mod common;

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The example binary `cargo test` builds next to the test binaries.
fn example() -> PathBuf {
    let deps = std::env::current_exe().unwrap();
    let exe = deps
        .parent()
        .and_then(Path::parent)
        .unwrap()
        .join("examples")
        .join(format!("custom_domain{}", std::env::consts::EXE_SUFFIX));
    assert!(exe.is_file(), "{} not built", exe.display());
    exe
}

fn config() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/custom_domain.toml")
}

fn ok(out: Output) -> String {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{text}");
    text
}

fn run_example(args: &[&str]) -> Output {
    Command::new(example()).args(args).output().unwrap()
}

/// Short runs: 300 episodes, an evaluation every 50 and a checkpoint every 50.
const SHORT: [&str; 6] = [
    "--set",
    "total_epi=300",
    "--set",
    "eval_freq=50",
    "--set",
    "checkpoint_freq=50",
];

fn train(out: &Path, seeds: &str, extra: &[&str]) -> Output {
    let cfg = config();
    let mut args = vec![
        "train",
        "--config",
        cfg.to_str().unwrap(),
        "--seeds",
        seeds,
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--no-plot",
    ];
    args.extend_from_slice(extra);
    run_example(&args)
}

#[test]
fn the_custom_domain_trains_plots_exports_evaluates_and_audits() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("results");
    let mut extra = SHORT.to_vec();
    extra.extend(["--jobs", "2"]);
    ok(train(&out, "0..2", &extra));
    let run = out.join("custom_domain/our1/seed-0");
    for method in ["our1", "dec-hddrqn"] {
        for seed in 0..2 {
            let dir = out.join(format!("custom_domain/{method}/seed-{seed}"));
            assert!(dir.join("finished").is_file(), "{}", dir.display());
        }
    }
    let config_toml = std::fs::read_to_string(run.join("config.toml")).unwrap();
    assert!(
        config_toml.contains("env_name = \"rendezvous\"\nenv_terminate_step = 20\n"),
        "{config_toml}"
    );

    // The example's plot knows the optimum; plain macdec, without the domain, draws no line.
    let figs = t.path().join("figs");
    ok(run_example(&[
        "plot",
        "--results",
        out.to_str().unwrap(),
        "--out",
        figs.to_str().unwrap(),
    ]));
    let svg = std::fs::read_to_string(figs.join("custom_domain.svg")).unwrap();
    let plain = t.path().join("plain");
    ok(common::run(&[
        "plot",
        "--results",
        out.to_str().unwrap(),
        "--out",
        plain.to_str().unwrap(),
    ]));
    let plain_svg = std::fs::read_to_string(plain.join("custom_domain.svg")).unwrap();
    assert!(svg.contains("ptimal"), "the optimum line is drawn");
    assert!(
        !plain_svg.contains("ptimal"),
        "no optimum without the domain"
    );

    // Export, then run episodes in-process and with robot processes of the example binary.
    let policy = t.path().join("policy");
    ok(run_example(&[
        "export",
        "--run",
        run.to_str().unwrap(),
        "--out",
        policy.to_str().unwrap(),
    ]));
    let p = policy.to_str().unwrap();
    let eval = ok(run_example(&["eval", "--policy", p, "--episodes", "2"]));
    assert!(eval.contains("2 episode(s) of rendezvous"), "{eval}");
    let deploy = ok(run_example(&["deploy", "--policy", p, "--episodes", "1"]));
    assert!(deploy.contains("robot process(es)"), "{deploy}");
    // Plain macdec, which lacks the domain, still serves its agents to robots ...
    let robot = common::robot_process(&policy, 1, false);
    let mut stream = std::io::BufReader::new(std::net::TcpStream::connect(&robot.addr).unwrap());
    stream
        .get_mut()
        .write_all(b"{\"type\": \"info\"}\n")
        .unwrap();
    let mut info = String::new();
    stream.read_line(&mut info).unwrap();
    assert!(
        info.contains("\"agent\":1") && info.contains("rendezvous"),
        "{info}"
    );
    // ... but runs no episodes of it, and says which domain is missing.
    let err = common::run(&["eval", "--policy", p]);
    assert!(!err.status.success());
    let text = String::from_utf8_lossy(&err.stderr);
    assert!(
        text.contains("rendezvous") && text.contains("main_with") && !text.contains("panicked"),
        "{text}"
    );

    // Audit retrains a finished run to the same numbers.
    let audit = ok(run_example(&[
        "audit",
        "--results",
        out.to_str().unwrap(),
        "--run",
        run.to_str().unwrap(),
    ]));
    assert!(audit.contains("identical"), "{audit}");

    // Slurm scripts call this binary; render explains that the domain draws no picture.
    let cfg = config();
    let script = ok(run_example(&[
        "slurm",
        "--config",
        cfg.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(
        script.contains(example().to_str().unwrap()) && script.contains("--run-index"),
        "{script}"
    );
    let gif = t.path().join("r.gif");
    let render = run_example(&[
        "render",
        "--run",
        run.to_str().unwrap(),
        "--out",
        gif.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&render.stderr);
    assert!(
        !render.status.success() && text.contains("draws no picture") && !text.contains("panicked"),
        "{text}"
    );
    assert!(!gif.exists());
}

/// A run killed after its first checkpoint resumes to exactly the numbers of an uninterrupted run.
#[test]
fn a_killed_custom_domain_run_resumes_to_the_same_numbers() {
    let t = tempfile::tempdir().unwrap();
    let whole = t.path().join("whole");
    let long = ["--set", "total_epi=1600", "--set", "checkpoint_freq=50"];
    ok(train(&whole, "0", &long));

    let killed = t.path().join("killed");
    let cfg = config();
    let mut child = Command::new(example())
        .args([
            "train",
            "--config",
            cfg.to_str().unwrap(),
            "--seeds",
            "0",
            "--methods",
            "our1,dec-hddrqn",
            "--out",
            killed.to_str().unwrap(),
            "--quiet",
            "--no-plot",
        ])
        .args(long)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let checkpoint = killed.join("custom_domain/our1/seed-0/checkpoint.bin");
    let start = Instant::now();
    while !checkpoint.is_file() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(checkpoint.is_file(), "no checkpoint within a minute");
    assert!(
        !killed.join("custom_domain/our1/seed-0/finished").exists(),
        "the run finished before it was killed; the test did not test resuming"
    );

    // A run directory holding a checkpoint either resumes from it or fails naming it (it never
    // starts over silently), so success here means the custom environment saved in the
    // checkpoint was read back through the domain registry.
    ok(train(&killed, "0", &long));
    for method in ["our1", "dec-hddrqn"] {
        let metrics = |root: &Path| {
            let text = std::fs::read_to_string(
                root.join(format!("custom_domain/{method}/seed-0/metrics.csv")),
            )
            .unwrap();
            // wall_seconds (the last column) differs between runs; every other column must not.
            text.lines()
                .map(|l| l.rsplit_once(',').unwrap().0.to_string())
                .collect::<Vec<_>>()
        };
        assert_eq!(metrics(&whole), metrics(&killed), "{method}");
    }
}
