//! A real Slurm cluster on loopback (scripts/slurm-local.sh): the job array `macdec slurm` writes
//! runs under slurmctld + slurmd, a requeued task resumes, the union plots, and the script leaves
//! no daemon or state behind. Needs root and Debian's slurm-wlm and munge (the script installs
//! them with apt-get), so it is ignored by default:
//!
//! ```sh
//! cargo test --release --test slurm_local -- --ignored
//! ```

use std::path::Path;
use std::process::Command;

mod common;

use common::BIN;

/// The values of the script's `slurm-local: <prefix><value>` lines.
fn values<'a>(out: &'a str, prefix: &str) -> Vec<&'a str> {
    out.lines()
        .filter_map(|l| l.strip_prefix("slurm-local: ")?.strip_prefix(prefix))
        .collect()
}

/// Whether `pid` is a live process (a zombie waiting for its reaper is not).
fn alive(pid: &str) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Ok(stat) => !stat
            .rsplit_once(')')
            .is_some_and(|(_, rest)| rest.trim_start().starts_with('Z')),
        Err(_) => false,
    }
}

#[test]
#[ignore = "needs root, apt-get and about a minute: cargo test --release --test slurm_local -- --ignored"]
fn a_real_slurm_cluster_runs_the_job_array_and_cleans_up() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/slurm-local.sh");
    let o = Command::new("bash")
        .arg(&script)
        .env("MACDEC", BIN)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    let last = stdout.lines().last().unwrap_or_default();
    assert!(
        o.status.success() && last.starts_with("slurm-local: OK: 4 of 4 array tasks COMPLETED"),
        "status {:?}\n--- stdout\n{stdout}\n--- stderr\n{stderr}",
        o.status
    );
    assert!(stdout.contains("| Our-1 | 2 (2) | 40 |"), "{stdout}");

    let state = values(&stdout, "cluster state in ");
    assert_eq!(state.len(), 1, "{stdout}");
    let state = state[0].trim_end_matches(" (removed on exit)");
    assert!(!Path::new(state).exists(), "{state} was left behind");

    let daemons: Vec<&str> = values(&stdout, "started ")
        .into_iter()
        .filter_map(|v| v.split_once(" (pid ")?.1.strip_suffix(')'))
        .collect();
    assert_eq!(daemons.len(), 3, "munged, slurmctld, slurmd: {stdout}");
    for pid in daemons {
        assert!(!alive(pid), "daemon pid {pid} still running");
    }
}
