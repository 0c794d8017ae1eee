//! Every run of a results tree as one long ("tidy") CSV for pandas or R: `macdec results`.
//!
//! One row per evaluation of every run: `experiment` (its path below the root, `fig4a_bp10` or
//! `macromarl/bp6`), `method` and `variant` (the curve directory `our1@l_rate=0.001` split at
//! `@`; the variant is empty without a sweep), `seed`, then the metrics columns as
//! `metrics.csv` names them (the leading ones, every family column found in any run in order of
//! first appearance, empty where a run's family has no such column, and `wall_seconds` last).
//! Cells are written as `metrics.csv` writes them, so a value reads back to the same bits.
//!
//! The tree is read twice (headers first, to know every column, then rows), so memory stays at
//! one run's curve however large the tree is.

use super::metrics::{
    self, MetricsError, MetricsTable, EVAL_RETURN_UNDISCOUNTED, LEADING_COLUMNS, WALL_SECONDS,
};
use super::results_tree;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The columns naming a row's run, before the metrics columns.
pub const RUN_COLUMNS: [&str; 4] = ["experiment", "method", "variant", "seed"];

/// Why the table could not be made.
#[derive(Debug, thiserror::Error)]
pub enum TidyError {
    /// The results tree could not be listed.
    #[error("{path}: cannot read the results tree: {source}")]
    ReadTree {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// No run with a metrics file below the root.
    #[error("{path}: no runs found (expected <experiment>/<method>/seed-<k>/metrics.csv[.gz])")]
    NoRuns {
        /// The root.
        path: PathBuf,
    },
    /// A metrics file could not be read.
    #[error(transparent)]
    Metrics(#[from] MetricsError),
    /// A metrics column is named like one of the table's run columns.
    #[error(
        "{path}: a metrics column is named `{name}`, which the table uses for the run's own \
         {name}; rename the column"
    )]
    RunColumnName {
        /// The metrics file.
        path: PathBuf,
        /// The column's name.
        name: String,
    },
    /// The table could not be written.
    #[error("{path}: {source}")]
    Write {
        /// The output file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// One run of the tree: where it is and what names it in the table.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TidyRun {
    /// The run directory.
    pub dir: PathBuf,
    /// The experiment directory's path below the root, `/`-separated.
    pub experiment: String,
    /// The curve directory's name before `@`.
    pub method: String,
    /// The sweep point after `@` (empty without one).
    pub variant: String,
    /// The run's seed (from `seed-<k>`).
    pub seed: u64,
}

/// Every run below `root` with a metrics file, sorted by path.
pub fn tidy_runs(root: &Path) -> Result<Vec<TidyRun>, TidyError> {
    let is_run = |dir: &Path| {
        let named = dir
            .file_name()
            .and_then(|n| n.to_str())
            .and_then(results_tree::parse_seed_dir)
            .is_some();
        named && metrics::locate(dir).is_some()
    };
    let dirs = results_tree::find_runs(root, &is_run)
        .map_err(|(path, source)| TidyError::ReadTree { path, source })?;
    if dirs.is_empty() {
        return Err(TidyError::NoRuns {
            path: root.to_path_buf(),
        });
    }
    Ok(dirs.into_iter().filter_map(|d| name_run(root, d)).collect())
}

/// Split a run directory's path below `root` into experiment, curve and seed.
fn name_run(root: &Path, dir: PathBuf) -> Option<TidyRun> {
    let rel = dir.strip_prefix(root).ok()?;
    let parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let (seed_dir, rest) = parts.split_last()?;
    let (curve, experiment) = rest.split_last()?;
    let seed = results_tree::parse_seed_dir(seed_dir)?;
    let (method, variant) = curve.split_once('@').unwrap_or((curve, ""));
    Some(TidyRun {
        experiment: experiment.join("/"),
        method: method.to_string(),
        variant: variant.to_string(),
        seed,
        dir,
    })
}

/// The table's header: [`RUN_COLUMNS`], the leading metrics columns, `eval_return_undiscounted`
/// (empty for runs trained before it existed), every family column of the runs in order of first
/// appearance, `wall_seconds`.
fn header<'a>(family_lists: impl Iterator<Item = &'a [String]>) -> Vec<String> {
    let mut family: Vec<String> = Vec::new();
    for list in family_lists {
        for c in list {
            if !family.contains(c) {
                family.push(c.clone());
            }
        }
    }
    RUN_COLUMNS
        .iter()
        .chain(LEADING_COLUMNS.iter())
        .chain(std::iter::once(&EVAL_RETURN_UNDISCOUNTED))
        .map(|s| s.to_string())
        .chain(family)
        .chain(std::iter::once(WALL_SECONDS.to_string()))
        .collect()
}

/// Write the table of every run below `root` to `out`; returns how many runs and rows.
pub fn write_tidy_table(root: &Path, out: &mut dyn Write) -> Result<(usize, usize), TidyError> {
    let runs = tidy_runs(root)?;
    let mut family_lists = Vec::with_capacity(runs.len());
    for run in &runs {
        family_lists.push(read_run(run)?.family_columns);
    }
    let header = header(family_lists.iter().map(Vec::as_slice));
    let family_header = &header[RUN_COLUMNS.len() + LEADING_COLUMNS.len() + 1..header.len() - 1];
    let io = |source| TidyError::Write {
        path: PathBuf::from("<output>"),
        source,
    };
    let csv_io = |e: csv::Error| io(std::io::Error::other(e));
    let mut w = csv::Writer::from_writer(out);
    w.write_record(&header).map_err(csv_io)?;
    let mut rows = 0;
    for run in &runs {
        let table = read_run(run)?;
        // Where each of the header's family columns sits in this run's rows, if it has it.
        let at: Vec<Option<usize>> = family_header
            .iter()
            .map(|c| table.family_columns.iter().position(|f| f == c))
            .collect();
        for r in &table.rows {
            let mut cells: Vec<Cell> = vec![
                Cell::Text(&run.experiment),
                Cell::Text(&run.method),
                Cell::Text(&run.variant),
                Cell::Count(run.seed),
                Cell::Count(r.episode),
                Cell::Count(r.env_steps),
                Cell::Count(r.updates),
                Cell::Value(Some(r.eval_return)),
                Cell::Value(r.eval_return_undiscounted),
            ];
            cells.extend(at.iter().map(|k| Cell::Value(k.and_then(|k| r.family[k]))));
            cells.push(Cell::Value(Some(r.wall_seconds)));
            w.serialize(cells).map_err(csv_io)?;
            rows += 1;
        }
    }
    w.flush().map_err(io)?;
    Ok((runs.len(), rows))
}

/// Write the table to the file `path`, atomically (a reader never sees half a table).
pub fn write_tidy_file(root: &Path, path: &Path) -> Result<(usize, usize), TidyError> {
    crate::files::atomic::write_atomic_try(
        path,
        |f| write_tidy_table(root, f),
        |source| TidyError::Write {
            path: path.to_path_buf(),
            source,
        },
    )
}

/// The metrics of one run of [`tidy_runs`] (its `metrics.csv`, else `metrics.csv.gz`): what
/// each row of the table is made from, for readers that build their own table (the Python
/// package's `load_results`).
pub fn read_run(run: &TidyRun) -> Result<MetricsTable, TidyError> {
    let path = metrics::locate(&run.dir).ok_or_else(|| TidyError::NoRuns {
        path: run.dir.clone(),
    })?;
    let table = metrics::read(&path)?;
    if let Some(name) = table
        .family_columns
        .iter()
        .find(|c| RUN_COLUMNS.contains(&c.as_str()))
    {
        return Err(TidyError::RunColumnName {
            path,
            name: name.clone(),
        });
    }
    Ok(table)
}

/// One cell, written as `metrics.csv` writes its type (floats by `ryu`, `None` empty).
#[derive(serde::Serialize)]
#[serde(untagged)]
enum Cell<'a> {
    Text(&'a str),
    Count(u64),
    Value(Option<f64>),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::run::metrics::MetricsRow;

    fn row(episode: u64, ret: f64, family: Vec<Option<f64>>) -> MetricsRow {
        MetricsRow {
            episode,
            env_steps: episode * 7,
            updates: episode / 2,
            eval_return: ret,
            eval_return_undiscounted: Some(ret * 2.0),
            family,
            wall_seconds: 0.5,
        }
    }

    fn run(root: &Path, rel: &str, family: &[&str], rows: &[MetricsRow], gz: bool) {
        let dir = root.join(rel);
        std::fs::create_dir_all(&dir).unwrap();
        let bytes = metrics::to_csv(family, rows).unwrap();
        if gz {
            let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
            e.write_all(&bytes).unwrap();
            std::fs::write(dir.join(metrics::METRICS_FILE_GZ), e.finish().unwrap()).unwrap();
        } else {
            std::fs::write(dir.join(metrics::METRICS_FILE), bytes).unwrap();
        }
    }

    #[test]
    fn every_run_of_every_family_lands_in_one_long_table() {
        let t = tempfile::tempdir().unwrap();
        let root = t.path();
        let value = ["epsilon", "hysteresis", "loss"];
        run(
            root,
            "fig4a/our1/seed-1",
            &value,
            &[
                row(0, -4.25, vec![Some(1.0), Some(0.2), None]),
                row(10, 0.1 + 0.2, vec![Some(0.9), Some(0.3), Some(2.5)]),
            ],
            true,
        );
        run(
            root,
            "fig4a/our1@l_rate=0.001/seed-0",
            &value,
            &[row(0, 1.0, vec![Some(1.0), Some(0.2), None])],
            false,
        );
        run(
            root,
            "macromarl/bp6/mac-iac/seed-3",
            &["actor_loss"],
            &[row(0, 2.0, vec![Some(-0.5)])],
            false,
        );
        // Not runs: no metrics yet, a stray directory, a link to a run elsewhere.
        std::fs::create_dir_all(root.join("fig4a/our1/seed-2")).unwrap();
        std::fs::create_dir_all(root.join("fig4a/notes")).unwrap();
        let outside = tempfile::tempdir().unwrap();
        run(
            outside.path(),
            "e/our1/seed-0",
            &value,
            &[row(0, 9.0, vec![None, None, None])],
            false,
        );
        std::os::unix::fs::symlink(
            outside.path().join("e/our1/seed-0"),
            root.join("fig4a/our1/seed-9"),
        )
        .unwrap();

        let mut out = Vec::new();
        let (runs, rows) = write_tidy_table(root, &mut out).unwrap();
        assert_eq!((runs, rows), (3, 4));
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines,
            [
                "experiment,method,variant,seed,episode,env_steps,updates,eval_return,eval_return_undiscounted,epsilon,hysteresis,loss,actor_loss,wall_seconds",
                "fig4a,our1,,1,0,0,0,-4.25,-8.5,1.0,0.2,,,0.5",
                "fig4a,our1,,1,10,70,5,0.30000000000000004,0.6000000000000001,0.9,0.3,2.5,,0.5",
                "fig4a,our1,l_rate=0.001,0,0,0,0,1.0,2.0,1.0,0.2,,,0.5",
                "macromarl/bp6,mac-iac,,3,0,0,0,2.0,4.0,,,,-0.5,0.5",
            ]
        );
        // The file form is the same bytes, written atomically.
        let file = t.path().join("all.csv");
        assert_eq!(write_tidy_file(root, &file).unwrap(), (3, 4));
        assert_eq!(std::fs::read_to_string(&file).unwrap(), text);
    }

    #[test]
    fn an_empty_tree_or_a_bad_metrics_file_is_named_and_nothing_is_written() {
        let t = tempfile::tempdir().unwrap();
        let err = write_tidy_table(t.path(), &mut Vec::new()).unwrap_err();
        assert!(err.to_string().contains("no runs found"), "{err}");
        let dir = t.path().join("e/our1/seed-0");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(metrics::METRICS_FILE), "not,a,metrics,file\n").unwrap();
        let file = t.path().join("out.csv");
        let err = write_tidy_file(t.path(), &file).unwrap_err();
        assert!(err.to_string().contains("metrics.csv"), "{err}");
        assert!(!file.exists());
        assert_eq!(
            std::fs::read_dir(t.path()).unwrap().count(),
            1,
            "no temp file left"
        );
    }

    #[test]
    fn a_metrics_column_named_like_a_run_column_is_refused_naming_the_file() {
        for name in RUN_COLUMNS {
            let t = tempfile::tempdir().unwrap();
            let dir = t.path().join("e/our1/seed-0");
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(
                dir.join(metrics::METRICS_FILE),
                format!(
                    "episode,env_steps,updates,eval_return,{name},wall_seconds\n0,0,0,1,7,0.1\n"
                ),
            )
            .unwrap();
            let err = write_tidy_table(t.path(), &mut Vec::new())
                .unwrap_err()
                .to_string();
            assert!(
                err.contains(&format!("a metrics column is named `{name}`")),
                "{err}"
            );
            assert!(err.contains("metrics.csv"), "{err}");
        }
    }
}
