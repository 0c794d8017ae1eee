//! `macdec slurm`: the generated job-array script's task command, run locally with
//! SLURM_ARRAY_TASK_ID set, trains exactly the run of that index, and the union plots.

use std::path::Path;
use std::process::Command;

mod common;

use common::BIN;

const TINY: &str = r#"
name = "tiny_slurm"
methods = ["dec-hddrqn", "our1"]
seeds = "0..2"

[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 20
batch_size = 8
replay_buffer_size = 500
eval_freq = 5
"#;

fn run_task(script: &Path, index: usize) {
    let status = Command::new("bash")
        .arg(script)
        .env("SLURM_ARRAY_TASK_ID", index.to_string())
        .status()
        .unwrap();
    assert!(status.success(), "task {index} failed");
}

#[test]
fn array_tasks_train_their_own_runs_and_plot_together() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, TINY).unwrap();
    let out = dir.path().join("results");
    let o = Command::new(BIN)
        .args(["slurm", "--config"])
        .arg(&config)
        .arg("--out")
        .arg(&out)
        .args(["--time", "00:10:00", "--sbatch=--partition=test"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let script_text = String::from_utf8(o.stdout).unwrap();
    assert!(
        script_text.contains("#SBATCH --array=0-3\n"),
        "{script_text}"
    );
    assert!(script_text.contains("#SBATCH --partition=test\n"));
    assert!(
        script_text.contains("#   2: our1/seed-0\n"),
        "{script_text}"
    );
    let script = dir.path().join("job.sh");
    std::fs::write(&script, &script_text).unwrap();

    // Tasks 2 and 1 only: exactly those runs exist.
    run_task(&script, 2);
    run_task(&script, 1);
    let finished = |curve: &str, seed: u64| {
        out.join(format!("tiny_slurm/{curve}/seed-{seed}/finished"))
            .exists()
    };
    assert!(finished("our1", 0) && finished("dec-hddrqn", 1));
    assert!(!finished("dec-hddrqn", 0) && !finished("our1", 1));
    // A requeued task finds its run finished and does nothing.
    run_task(&script, 2);

    let plots = dir.path().join("plots");
    let o = Command::new(BIN)
        .args(["plot", "--results"])
        .arg(&out)
        .arg("--out")
        .arg(&plots)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(plots.join("tiny_slurm.png").exists());
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.contains("Our-1") && table.contains("Dec-HDDRQN"),
        "{table}"
    );

    // An index past the end is a clear error.
    let status = Command::new("bash")
        .arg(&script)
        .env("SLURM_ARRAY_TASK_ID", "9")
        .output()
        .unwrap();
    assert!(!status.status.success());
    assert!(String::from_utf8_lossy(&status.stderr).contains("--run-index 9"));
}
