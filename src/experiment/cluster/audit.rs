//! Checking committed results by recomputing them: `macdec audit`.
//!
//! A committed run directory holds `config.toml` (the run's identity, resolved config and
//! provenance), its metrics (`metrics.csv` or `metrics.csv.gz`) and `finished`. Auditing a run
//! retrains it from that config alone in a scratch directory and compares the metrics row by row,
//! byte for byte, with the `wall_seconds` column (the only one that depends on the machine's
//! speed) left out, and `eval_return_undiscounted` too where the committed run was trained
//! before that column existed. Every committed run must pass at HEAD; a change that alters numerics must
//! recompute the results it affects.

use crate::experiment::definition::config::RunSpec;
use crate::experiment::run::metrics::{
    self, MetricsError, COMPLETED_EPISODE_STEPS, EVAL_RETURN_UNDISCOUNTED,
};
use crate::experiment::run::progress::Progress;
use crate::experiment::run::provenance::Provenance;
use crate::experiment::run::results_tree::{self, CONFIG};
use crate::experiment::run::train_run::{train_run, RunError, RunManifest};
use crate::files::bounded_read::{read_text_in_tree, MAX_TEXT_BYTES};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use std::path::{Path, PathBuf};

/// The column a retrained run may differ in.
const WALL_COLUMN: &str = "wall_seconds";

/// Why a run could not be audited (as opposed to being audited and found different).
#[derive(Debug, thiserror::Error)]
pub enum AuditError {
    /// The results tree could not be listed.
    #[error("{path}: cannot read the results tree: {source}")]
    ReadTree {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A directory that is not a finished run.
    #[error("{dir}: not a finished run (needs {CONFIG}, metrics.csv[.gz] and `finished`)")]
    NotARun {
        /// The directory.
        dir: PathBuf,
    },
    /// The run's `config.toml` does not parse.
    #[error("{path}: not a run config: {message}")]
    BadConfig {
        /// The config file.
        path: PathBuf,
        /// The parser's reason.
        message: String,
    },
    /// The committed metrics could not be read.
    #[error(transparent)]
    Metrics(#[from] MetricsError),
    /// The metrics header does not end in the wall-clock column.
    #[error("{path}: the header's last column is not `{WALL_COLUMN}`")]
    BadHeader {
        /// The metrics file.
        path: PathBuf,
    },
    /// Retraining the run failed.
    #[error("retraining failed: {0}")]
    Retrain(#[from] RunError),
    /// The scratch directory for the retrained run could not be made.
    #[error("{path}: cannot make a scratch directory: {source}")]
    Scratch {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// What retraining a run showed.
#[derive(Debug, Clone, PartialEq)]
pub enum AuditOutcome {
    /// Every row equal (wall-clock aside).
    Identical {
        /// Data rows compared.
        rows: usize,
    },
    /// The first data row (1-based) whose text differs; a missing row is shown as `<none>`.
    Differs {
        /// Row number, 1-based.
        row: usize,
        /// The committed row's text.
        committed: String,
        /// The retrained row's text.
        retrained: String,
    },
}

/// The audit of one run: where it is, how it was made, what retraining gave.
#[derive(Debug, Clone)]
pub struct RunAudit {
    /// The run's directory.
    pub dir: PathBuf,
    /// The build that trained the committed run, if it recorded one.
    pub provenance: Option<Provenance>,
    /// What retraining gave.
    pub outcome: AuditOutcome,
}

impl RunAudit {
    /// One line for the terminal: the run and `identical`, or where it first differs.
    pub fn line(&self) -> String {
        match &self.outcome {
            AuditOutcome::Identical { rows } => {
                format!("{}: identical ({rows} rows)", self.dir.display())
            }
            AuditOutcome::Differs {
                row,
                committed,
                retrained,
            } => format!(
                "{}: DIFFERS at row {row}\n  committed: {committed}\n  retrained: {retrained}",
                self.dir.display()
            ),
        }
    }
}

/// Every finished run under `results` (`<experiment>/<curve>/seed-<k>/` with `finished`, also
/// one level deeper for a group of experiments such as `macromarl/<block>/<method>/seed-<k>/`),
/// sorted by path. Shared curves reached through another experiment are listed once, where they
/// live.
pub fn finished_runs(results: &Path) -> Result<Vec<PathBuf>, AuditError> {
    let is_run = |dir: &Path| results_tree::is_finished(dir) && dir.join(CONFIG).is_file();
    results_tree::find_runs(results, &is_run)
        .map_err(|(path, source)| AuditError::ReadTree { path, source })
}

/// `k` of `runs` chosen at random with `seed` (all of them when `k` is at least their number),
/// in path order.
pub fn choose(runs: &[PathBuf], k: usize, seed: u64) -> Vec<PathBuf> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut chosen: Vec<PathBuf> = runs.choose_multiple(&mut rng, k).cloned().collect();
    chosen.sort();
    chosen
}

/// Read a committed run's manifest.
pub fn read_manifest(dir: &Path) -> Result<RunManifest, AuditError> {
    let path = dir.join(CONFIG);
    let text = read_text_in_tree(&path, MAX_TEXT_BYTES).map_err(|e| AuditError::BadConfig {
        path: path.clone(),
        message: e.to_string(),
    })?;
    toml::from_str(&text).map_err(|e| AuditError::BadConfig {
        path,
        message: e.to_string(),
    })
}

/// Retrain the run in `dir` inside `scratch` (which must not hold another run) and compare.
pub fn audit_run(dir: &Path, scratch: &Path) -> Result<RunAudit, AuditError> {
    let committed_path = metrics::locate(dir)
        .filter(|_| results_tree::is_finished(dir))
        .ok_or_else(|| AuditError::NotARun {
            dir: dir.to_path_buf(),
        })?;
    let manifest = read_manifest(dir)?;
    let spec = RunSpec {
        experiment: manifest.experiment.clone(),
        method: manifest.method,
        variant: manifest.variant.clone(),
        seed: manifest.seed,
        env: manifest.config.env,
        config: manifest.config.config.clone(),
    };
    let run_dir = scratch.join("run");
    train_run(&spec, &run_dir, &Progress::hidden(), true)?;
    let retrained_path = run_dir.join(metrics::METRICS_FILE);
    let committed = rows_without_wall(&committed_path)?;
    let mut retrained = rows_without_wall(&retrained_path)?;
    drop_columns_added_since(&committed, &mut retrained);
    Ok(RunAudit {
        dir: dir.to_path_buf(),
        provenance: manifest.provenance,
        outcome: compare(&committed, &retrained),
    })
}

/// The lines of a metrics file (header included) with the last column, `wall_seconds`, cut off.
fn rows_without_wall(path: &Path) -> Result<Vec<String>, AuditError> {
    let text = metrics::read_text(path)?;
    let text = String::from_utf8_lossy(&text);
    let mut lines = text.lines();
    let header = lines.next().unwrap_or("");
    if header.rsplit(',').next() != Some(WALL_COLUMN) {
        return Err(AuditError::BadHeader {
            path: path.to_path_buf(),
        });
    }
    Ok(std::iter::once(header)
        .chain(lines)
        .map(|l| l.rsplit_once(',').map_or(l, |(rest, _)| rest).to_string())
        .collect())
}

/// The columns added to `metrics.csv` after runs had been committed (each changed no number):
/// a run committed without one is compared without it.
const ADDED_COLUMNS: [&str; 2] = [EVAL_RETURN_UNDISCOUNTED, COMPLETED_EPISODE_STEPS];

/// Drop from `retrained` each of [`ADDED_COLUMNS`] that `committed` lacks.
fn drop_columns_added_since(committed: &[String], retrained: &mut [String]) {
    for column in ADDED_COLUMNS {
        if !has_column(committed, column) {
            drop_column(retrained, column);
        }
    }
}

/// Whether the header (the first of `lines`) names `column`.
fn has_column(lines: &[String], column: &str) -> bool {
    lines
        .first()
        .is_some_and(|h| h.split(',').any(|c| c == column))
}

/// Remove `column` (if the header names it) from every line.
fn drop_column(lines: &mut [String], column: &str) {
    let Some(at) = lines
        .first()
        .and_then(|h| h.split(',').position(|c| c == column))
    else {
        return;
    };
    for line in lines.iter_mut() {
        let kept: Vec<&str> = line
            .split(',')
            .enumerate()
            .filter(|&(i, _)| i != at)
            .map(|(_, cell)| cell)
            .collect();
        *line = kept.join(",");
    }
}

/// Compare two metrics files' lines (header first): identical, or the first data row that differs.
fn compare(committed: &[String], retrained: &[String]) -> AuditOutcome {
    let none = || "<none>".to_string();
    for i in 0..committed.len().max(retrained.len()) {
        let (a, b) = (committed.get(i), retrained.get(i));
        if a != b {
            return AuditOutcome::Differs {
                row: i,
                committed: a.cloned().unwrap_or_else(none),
                retrained: b.cloned().unwrap_or_else(none),
            };
        }
    }
    AuditOutcome::Identical {
        rows: committed.len().saturating_sub(1),
    }
}

/// Audit each of `dirs`, `jobs` at a time, each in its own scratch directory under the system's
/// temp dir (removed afterwards). `report` is called with each audit as soon as it ends.
pub fn audit_all(
    dirs: &[PathBuf],
    jobs: usize,
    report: impl Fn(&Result<RunAudit, (PathBuf, AuditError)>) + Sync,
) -> Vec<Result<RunAudit, (PathBuf, AuditError)>> {
    let one = |i: usize| {
        let dir = &dirs[i];
        let scratch = tempfile::Builder::new()
            .prefix("macdec-audit-")
            .tempdir()
            .map_err(|source| AuditError::Scratch {
                path: std::env::temp_dir(),
                source,
            });
        let result = scratch
            .and_then(|s| audit_run(dir, s.path()))
            .map_err(|e| (dir.clone(), e));
        report(&result);
        result
    };
    let order: Vec<usize> = (0..dirs.len()).collect();
    crate::experiment::run::work_queue::run_in_order(&order, jobs, one)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(xs: &[&str]) -> Vec<String> {
        xs.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn wall_seconds_is_cut_and_the_first_differing_row_is_named() {
        let t = tempfile::tempdir().unwrap();
        let p = t.path().join("metrics.csv");
        std::fs::write(
            &p,
            "episode,eval_return,wall_seconds\n0,1.5,0.1\n10,2.5,0.2\n",
        )
        .unwrap();
        let a = rows_without_wall(&p).unwrap();
        assert_eq!(a, lines(&["episode,eval_return", "0,1.5", "10,2.5"]));
        assert_eq!(compare(&a, &a), AuditOutcome::Identical { rows: 2 });
        let b = lines(&["episode,eval_return", "0,1.5", "10,2.6"]);
        assert_eq!(
            compare(&a, &b),
            AuditOutcome::Differs {
                row: 2,
                committed: "10,2.5".into(),
                retrained: "10,2.6".into()
            }
        );
        let short = lines(&["episode,eval_return", "0,1.5"]);
        assert!(matches!(
            compare(&a, &short),
            AuditOutcome::Differs { row: 2, ref retrained, .. } if retrained == "<none>"
        ));
        std::fs::write(&p, "episode,eval_return\n0,1.5\n").unwrap();
        assert!(matches!(
            rows_without_wall(&p),
            Err(AuditError::BadHeader { .. })
        ));
    }

    #[test]
    fn a_run_committed_before_the_undiscounted_column_is_compared_without_it() {
        let old = lines(&["episode,eval_return,loss", "0,1.5,", "10,2.5,0.3"]);
        let mut new = lines(&[
            "episode,eval_return,eval_return_undiscounted,loss",
            "0,1.5,2,",
            "10,2.5,3,0.3",
        ]);
        assert!(!has_column(&old, EVAL_RETURN_UNDISCOUNTED));
        assert!(has_column(&new, EVAL_RETURN_UNDISCOUNTED));
        assert!(matches!(
            compare(&old, &new),
            AuditOutcome::Differs { row: 0, .. }
        ));
        drop_column(&mut new, EVAL_RETURN_UNDISCOUNTED);
        assert_eq!(compare(&old, &new), AuditOutcome::Identical { rows: 2 });
        // A moved number in a kept column still differs.
        let mut moved = lines(&[
            "episode,eval_return,eval_return_undiscounted,loss",
            "0,1.5,2,",
            "10,2.5,3,0.4",
        ]);
        drop_column(&mut moved, EVAL_RETURN_UNDISCOUNTED);
        assert!(matches!(
            compare(&old, &moved),
            AuditOutcome::Differs { row: 2, .. }
        ));
    }

    #[test]
    fn a_run_committed_before_the_counted_steps_column_is_compared_without_it_and_others_with() {
        let header = "episode,eval_return,eval_return_undiscounted,eps,train_return";
        let old = lines(&[header, "0,1.5,2,1,", "96,2.5,3,0.9,4"]);
        let retrained = lines(&[
            &format!("{header},acac_timesteps"),
            "0,1.5,2,1,,0",
            "96,2.5,3,0.9,4,1150",
        ]);
        let mut new = retrained.clone();
        drop_columns_added_since(&old, &mut new);
        assert_eq!(compare(&old, &new), AuditOutcome::Identical { rows: 2 });
        // A run committed with the column keeps it compared: a moved count differs.
        let mut moved = retrained.clone();
        moved[2] = "96,2.5,3,0.9,4,1151".into();
        drop_columns_added_since(&retrained, &mut moved);
        assert!(matches!(
            compare(&retrained, &moved),
            AuditOutcome::Differs { row: 2, .. }
        ));
        // Both added columns go for a run older than either.
        let oldest = lines(&["episode,eval_return,eps", "0,1.5,1"]);
        let mut new = lines(&[
            "episode,eval_return,eval_return_undiscounted,eps,acac_timesteps",
            "0,1.5,2,1,0",
        ]);
        drop_columns_added_since(&oldest, &mut new);
        assert_eq!(compare(&oldest, &new), AuditOutcome::Identical { rows: 1 });
    }

    #[test]
    fn runs_are_found_in_experiments_and_in_groups_of_experiments() {
        let t = tempfile::tempdir().unwrap();
        let make = |rel: &str, finished: bool| {
            let d = t.path().join(rel);
            std::fs::create_dir_all(&d).unwrap();
            std::fs::write(d.join(CONFIG), "").unwrap();
            if finished {
                std::fs::write(d.join(results_tree::FINISHED), "").unwrap();
            }
            d
        };
        let icra = make("fig4a/our1/seed-0", true);
        let grouped = make("macromarl/bp6/mac-iac/seed-3", true);
        make("macromarl/bp6/mac-iac/seed-4", false);
        make("too/deep/for/a/run/seed-0", true);
        make("shallow/seed-0", true);
        assert_eq!(finished_runs(t.path()).unwrap(), [icra, grouped]);
    }

    #[test]
    fn choosing_is_reproducible_and_bounded() {
        let runs: Vec<PathBuf> = (0..10).map(|i| PathBuf::from(format!("r{i}"))).collect();
        assert_eq!(choose(&runs, 3, 7), choose(&runs, 3, 7));
        assert_eq!(choose(&runs, 3, 7).len(), 3);
        assert_eq!(choose(&runs, 30, 7), runs);
    }
}
