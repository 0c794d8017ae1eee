//! Slurm job arrays: one array task per run of an experiment.
//!
//! Each task runs `macdec train` for exactly one run (`--run-index $SLURM_ARRAY_TASK_ID`) into the
//! shared results directory (no figures: tasks would race to draw them). Runs checkpoint and resume, so a preempted and requeued task
//! continues where it stopped; `macdec plot` then reads the union of the run directories.

use crate::experiment::definition::names::{check_curve_name, check_experiment_name, NameError};
use std::fmt::Write as _;
use std::path::Path;

/// Why a job script could not be written. Nothing from a config or a flag reaches the script
/// unchecked: a newline would end a `#SBATCH` directive or a comment and run the rest as a command.
#[derive(Debug, thiserror::Error)]
pub enum SlurmError {
    /// A value holds a newline or control character.
    #[error("{what} {value:?} contains a newline or control character, which would break the job script")]
    ControlChar {
        /// What the value is (e.g. a flag's name).
        what: String,
        /// The value.
        value: String,
    },
    /// A value the option does not accept.
    #[error("{what} {value:?}: {expected}")]
    BadValue {
        /// The option, e.g. `--time`.
        what: &'static str,
        /// The value given.
        value: String,
        /// What it accepts.
        expected: &'static str,
    },
    /// An experiment or curve name that cannot be a path component.
    #[error(transparent)]
    Name(#[from] NameError),
}

/// What the generated script needs besides the experiment.
#[derive(Debug, Clone)]
pub struct SlurmOptions<'a> {
    /// The experiment file, as the cluster nodes will see it.
    pub config: &'a Path,
    /// The results root, as the cluster nodes will see it.
    pub out: &'a Path,
    /// The `macdec` binary, as the cluster nodes will see it.
    pub binary: &'a Path,
    /// Extra `macdec train` arguments (`--seeds`, `--methods`, `--set`) as plain words; the
    /// script quotes each one.
    pub train_args: Vec<String>,
    /// Wall-clock limit per task, e.g. `04:00:00` or `1-12:00:00`.
    pub time: &'a str,
    /// Memory per task, e.g. `2G`.
    pub mem: &'a str,
    /// Extra `#SBATCH` lines (partition, account), without the prefix, e.g. `--partition=cpu`.
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

fn no_control(what: impl Into<String>, value: &str) -> Result<(), SlurmError> {
    if value.chars().any(char::is_control) {
        return Err(SlurmError::ControlChar {
            what: what.into(),
            value: value.to_string(),
        });
    }
    Ok(())
}

/// Check the values that end up in `#SBATCH` directives, where shell quoting does not apply:
/// a time like `12:00:00` or `2-00:00:00`, a memory like `4G`, and extra lines that are one
/// option (`--partition=cpu`), with no whitespace or control characters.
fn check_directives(o: &SlurmOptions<'_>) -> Result<(), SlurmError> {
    let time_ok = !o.time.is_empty()
        && o.time.len() <= 32
        && o.time
            .chars()
            .all(|c| c.is_ascii_digit() || c == ':' || c == '-')
        && o.time.starts_with(|c: char| c.is_ascii_digit());
    if !time_ok {
        no_control("--time", o.time)?;
        return Err(SlurmError::BadValue {
            what: "--time",
            value: o.time.to_string(),
            expected: "expected a Slurm time such as 12:00:00, 90 or 1-12:00:00",
        });
    }
    let digits = o.mem.trim_end_matches(|c: char| "KMGTkmgt".contains(c));
    let mem_ok = !digits.is_empty()
        && digits.len() <= 16
        && digits.chars().all(|c| c.is_ascii_digit())
        && o.mem.len() <= digits.len() + 1;
    if !mem_ok {
        no_control("--mem", o.mem)?;
        return Err(SlurmError::BadValue {
            what: "--mem",
            value: o.mem.to_string(),
            expected: "expected a Slurm memory size such as 4G, 500M or 2048",
        });
    }
    for line in &o.extra_sbatch {
        no_control("--sbatch", line)?;
        let plain = line
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_=.,:@%/+".contains(c));
        if !line.starts_with('-') || !plain {
            return Err(SlurmError::BadValue {
                what: "--sbatch",
                value: line.clone(),
                expected: "expected one Slurm option of letters, digits and `-_=.,:@%/+`, e.g. --partition=cpu",
            });
        }
    }
    Ok(())
}

/// The job-array script for the runs named by `labels` (`<curve>/seed-<k>`, one comment line
/// each, so a reader can map task ids to runs). Refuses any name, path or flag value that could
/// change the script's structure; every shell word is quoted.
pub fn job_script(
    experiment: &str,
    labels: &[String],
    o: &SlurmOptions<'_>,
) -> Result<String, SlurmError> {
    check_experiment_name(experiment)?;
    for label in labels {
        no_control("run label", label)?;
        let (curve, seed) = label.split_once('/').unwrap_or((label, ""));
        check_curve_name(curve)?;
        if crate::experiment::run::results_tree::parse_seed_dir(seed).is_none() {
            return Err(SlurmError::BadValue {
                what: "run label",
                value: label.clone(),
                expected: "expected <curve>/seed-<k>",
            });
        }
    }
    check_directives(o)?;
    let paths = [
        ("--config path", o.config),
        ("--out path", o.out),
        ("macdec binary path", o.binary),
    ];
    let mut words = Vec::new();
    for (what, path) in paths {
        let text = path.to_str().ok_or_else(|| SlurmError::BadValue {
            what,
            value: path.display().to_string(),
            expected: "expected a UTF-8 path",
        })?;
        no_control(what, text)?;
        words.push(text.to_string());
    }
    for arg in &o.train_args {
        no_control("train argument", arg)?;
    }
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
        shell_quote(&words[2]),
        "train".into(),
        "--config".into(),
        shell_quote(&words[0]),
        "--out".into(),
        shell_quote(&words[1]),
    ];
    cmd.extend(o.train_args.iter().map(|w| shell_quote(w)));
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
    Ok(s)
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
        let s = job_script("fig4a", &labels, &o).unwrap();
        assert!(s.contains("#SBATCH --array=0-5\n"));
        assert!(s.contains("#SBATCH --partition=cpu\n"));
        assert!(s.contains("#   5: our1/seed-5\n"));
        assert!(s.ends_with(
            "/home/me/macdec train --config /home/me/fig4a.toml --out /scratch/results --set total_epi=300 --jobs 1 --quiet --no-plot --run-index \"$SLURM_ARRAY_TASK_ID\"\n"
        ));
    }

    fn options<'a>(train_args: Vec<String>) -> SlurmOptions<'a> {
        SlurmOptions {
            config: Path::new("/home/me/fig4a.toml"),
            out: Path::new("/scratch/results"),
            binary: Path::new("/home/me/macdec"),
            train_args,
            time: "01:00:00",
            mem: "2G",
            extra_sbatch: vec![],
        }
    }

    const HOSTILE: [&str; 9] = [
        "a\nrm -rf ~",
        "$(touch pwned)",
        "`id`",
        "x; id",
        "it's",
        "a\rb",
        "tab\there",
        "\\",
        "'\"'",
    ];

    #[test]
    fn hostile_names_and_directive_values_are_refused() {
        let labels = vec!["our1/seed-0".to_string()];
        for bad in HOSTILE {
            assert!(
                job_script(bad, &labels, &options(vec![])).is_err(),
                "{bad:?}"
            );
            let label = vec![format!("{bad}/seed-0")];
            assert!(
                job_script("e", &label, &options(vec![])).is_err(),
                "{bad:?}"
            );
            let o = SlurmOptions {
                time: bad,
                ..options(vec![])
            };
            assert!(job_script("e", &labels, &o).is_err(), "time {bad:?}");
            let o = SlurmOptions {
                mem: bad,
                ..options(vec![])
            };
            assert!(job_script("e", &labels, &o).is_err(), "mem {bad:?}");
            let o = SlurmOptions {
                extra_sbatch: vec![format!("--partition={bad}")],
                ..options(vec![])
            };
            assert!(job_script("e", &labels, &o).is_err(), "sbatch {bad:?}");
        }
        let o = SlurmOptions {
            config: Path::new("/tmp/a\nb.toml"),
            ..options(vec![])
        };
        assert!(job_script("e", &labels, &o).is_err());
        for ok in ["12:00:00", "1-00:00:00", "90"] {
            let o = SlurmOptions {
                time: ok,
                ..options(vec![])
            };
            job_script("e", &labels, &o).unwrap();
        }
    }

    #[test]
    fn train_arguments_reach_the_shell_as_the_same_words() {
        // Let a real shell split the generated command line: every argument must come back intact
        // and nothing else may run.
        let dir = tempfile::tempdir().unwrap();
        let args: Vec<String> = HOSTILE
            .iter()
            .filter(|w| !w.chars().any(char::is_control))
            .map(|w| format!("total_epi={w}"))
            .collect();
        let labels = vec!["our1/seed-0".to_string()];
        let printer = dir.path().join("print args");
        std::fs::write(
            &printer,
            "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\0' \"$a\"; done\n",
        )
        .unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&printer, std::fs::Permissions::from_mode(0o755)).unwrap();
        let o = SlurmOptions {
            binary: &printer,
            ..options(args.clone())
        };
        let script = job_script("e", &labels, &o).unwrap();
        let out = std::process::Command::new("bash")
            .arg("-c")
            .arg(&script)
            .current_dir(dir.path())
            .env("SLURM_ARRAY_TASK_ID", "0")
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let words: Vec<String> = String::from_utf8(out.stdout)
            .unwrap()
            .split_terminator('\0')
            .map(str::to_string)
            .collect();
        let mut expected = vec![
            "train".to_string(),
            "--config".into(),
            "/home/me/fig4a.toml".into(),
            "--out".into(),
            "/scratch/results".into(),
        ];
        expected.extend(args);
        expected
            .extend(["--jobs", "1", "--quiet", "--no-plot", "--run-index", "0"].map(String::from));
        assert_eq!(words, expected);
        assert!(!dir.path().join("pwned").exists());
        let o = SlurmOptions {
            ..options(vec!["a\nb".into()])
        };
        assert!(job_script("e", &labels, &o).is_err());
    }
}
