//! Slurm job arrays: one array task per run of an experiment.
//!
//! Each task runs `macdec train` for exactly one run (`--run-index $SLURM_ARRAY_TASK_ID`) into the
//! shared results directory (no figures: tasks would race to draw them). Runs checkpoint and resume, so a preempted and requeued task
//! continues where it stopped; `macdec plot` then reads the union of the run directories.

use std::fmt::Write as _;
use std::path::Path;

/// What the generated script needs besides the experiment.
#[derive(Debug, Clone)]
pub struct SlurmOptions<'a> {
    /// The experiment file, as the cluster nodes will see it.
    pub config: &'a Path,
    /// The results root, as the cluster nodes will see it.
    pub out: &'a Path,
    /// The `macdec` binary, as the cluster nodes will see it.
    pub binary: &'a Path,
    /// Extra `macdec train` arguments (`--seeds`, `--methods`, `--set`), already quoted.
    pub train_args: Vec<String>,
    /// Wall-clock limit per task, e.g. `04:00:00`.
    pub time: &'a str,
    /// Memory per task, e.g. `2G`.
    pub mem: &'a str,
    /// Extra `#SBATCH` lines (partition, account), without the prefix.
    pub extra_sbatch: Vec<String>,
}

/// Quote a word for a POSIX shell.
pub fn shell_quote(word: &str) -> String {
    if !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,@+".contains(c))
    {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

/// The job-array script for `n_runs` runs named by `labels` (one comment line each, so a
/// reader can map task ids to runs).
pub fn job_script(experiment: &str, labels: &[String], o: &SlurmOptions<'_>) -> String {
    let mut s = String::new();
    let n = labels.len();
    let _ = writeln!(s, "#!/bin/bash");
    let _ = writeln!(s, "#SBATCH --job-name=macdec-{experiment}");
    let _ = writeln!(s, "#SBATCH --array=0-{}", n.saturating_sub(1));
    let _ = writeln!(s, "#SBATCH --cpus-per-task=1");
    let _ = writeln!(s, "#SBATCH --mem={}", o.mem);
    let _ = writeln!(s, "#SBATCH --time={}", o.time);
    let _ = writeln!(s, "#SBATCH --requeue");
    let _ = writeln!(s, "#SBATCH --output=slurm-%A_%a.out");
    for line in &o.extra_sbatch {
        let _ = writeln!(s, "#SBATCH {line}");
    }
    let _ = writeln!(s, "#");
    let _ = writeln!(
        s,
        "# {n} runs of experiment {experiment}; array task id -> run:"
    );
    for (i, label) in labels.iter().enumerate() {
        let _ = writeln!(s, "#   {i}: {label}");
    }
    let _ = writeln!(
        s,
        "# Each task trains one run, resuming from its checkpoint if requeued."
    );
    let _ = writeln!(s, "set -euo pipefail");
    let mut cmd = vec![
        shell_quote(&o.binary.display().to_string()),
        "train".into(),
        "--config".into(),
        shell_quote(&o.config.display().to_string()),
        "--out".into(),
        shell_quote(&o.out.display().to_string()),
    ];
    cmd.extend(o.train_args.iter().cloned());
    cmd.extend(
        [
            "--jobs",
            "1",
            "--quiet",
            "--no-plot",
            "--run-index",
            "\"$SLURM_ARRAY_TASK_ID\"",
        ]
        .iter()
        .map(|w| w.to_string()),
    );
    let _ = writeln!(s, "{}", cmd.join(" "));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_leaves_plain_words_and_wraps_the_rest() {
        assert_eq!(shell_quote("total_epi=300"), "total_epi=300");
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
    }

    #[test]
    fn script_has_one_task_per_run_and_the_task_command() {
        let labels: Vec<String> = (0..6).map(|i| format!("our1/seed-{i}")).collect();
        let o = SlurmOptions {
            config: Path::new("/home/me/fig4a.toml"),
            out: Path::new("/scratch/results"),
            binary: Path::new("/home/me/macdec"),
            train_args: vec!["--set".into(), "total_epi=300".into()],
            time: "01:00:00",
            mem: "2G",
            extra_sbatch: vec!["--partition=cpu".into()],
        };
        let s = job_script("fig4a", &labels, &o);
        assert!(s.contains("#SBATCH --array=0-5\n"));
        assert!(s.contains("#SBATCH --partition=cpu\n"));
        assert!(s.contains("#   5: our1/seed-5\n"));
        assert!(s.ends_with(
            "/home/me/macdec train --config /home/me/fig4a.toml --out /scratch/results --set total_epi=300 --jobs 1 --quiet --no-plot --run-index \"$SLURM_ARRAY_TASK_ID\"\n"
        ));
    }
}
