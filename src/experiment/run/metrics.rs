//! The per-run learning curve: one `metrics.csv` row per evaluation.
//!
//! Columns (stable names other tools read): `episode` (training episodes completed),
//! `env_steps` (primitive steps taken by the training env(s)), `updates` (training iterations),
//! `eval_return` (mean return of the evaluated policy, discounted per primitive step, spec
//! `algorithms.md` 7.1), `eval_return_undiscounted` (the same episodes' mean undiscounted return,
//! as ACAC and later work report it; absent from runs trained before it existed, whose files
//! readers still take), then the method family's own columns, then `wall_seconds` (time since
//! the run started, including resumed segments; the only column that is not reproducible bit for
//! bit). The value-based family's columns are `epsilon`, `hysteresis` and `loss` (mean total TD
//! loss over the iterations since the previous row; empty before the first), see
//! [`crate::algos::value::learner::METRIC_COLUMNS`]. A reader takes any family columns between
//! `eval_return` and `wall_seconds` by their header names.

use crate::files::bounded_read::{gunzip_bounded, read_in_tree, MAX_METRICS_BYTES};
use serde::Serialize;
use std::path::Path;

/// The file name of a run's learning curve.
pub const METRICS_FILE: &str = "metrics.csv";
/// The same curve gzip-compressed, as committed results store it (`scripts/campaign.sh collect`).
pub const METRICS_FILE_GZ: &str = "metrics.csv.gz";

/// The columns every family writes before its own.
pub const LEADING_COLUMNS: [&str; 4] = ["episode", "env_steps", "updates", "eval_return"];
/// The column written after the leading ones since it exists; files of older runs lack it.
pub const EVAL_RETURN_UNDISCOUNTED: &str = "eval_return_undiscounted";
/// The family column of ACAC's counted steps (defined beside the learners that write it).
pub use crate::algos::learner::COMPLETED_EPISODE_STEPS;
/// The column every family writes after its own.
pub const WALL_SECONDS: &str = "wall_seconds";

/// The metrics file of the run in `dir`: `metrics.csv` (what a run writes as it goes) if present,
/// else the committed `metrics.csv.gz`; `None` when neither exists.
pub fn locate(dir: &Path) -> Option<std::path::PathBuf> {
    [METRICS_FILE, METRICS_FILE_GZ]
        .iter()
        .map(|name| dir.join(name))
        .find(|p| std::fs::symlink_metadata(p).is_ok())
}

/// One evaluation point of a run: the training loop's own record, written as one CSV row.
pub use crate::algos::training_loop::EvalPoint as MetricsRow;

/// A whole metrics file: the family's column names and every row.
#[derive(Debug, Clone, PartialEq)]
pub struct MetricsTable {
    /// Whether the file has the `eval_return_undiscounted` column (runs trained since it exists).
    pub has_undiscounted: bool,
    /// The names of the rows' [`MetricsRow::family`] values, in order.
    pub family_columns: Vec<String>,
    /// One row per evaluation point, in file order.
    pub rows: Vec<MetricsRow>,
}

impl MetricsTable {
    /// Every row's value of column `name` (a leading, family or `wall_seconds` column); `None`
    /// when the file has no such column. Empty cells are `None`.
    pub fn column(&self, name: &str) -> Option<Vec<Option<f64>>> {
        let common: Option<fn(&MetricsRow) -> f64> = match name {
            "episode" => Some(|r| r.episode as f64),
            "env_steps" => Some(|r| r.env_steps as f64),
            "updates" => Some(|r| r.updates as f64),
            "eval_return" => Some(|r| r.eval_return),
            WALL_SECONDS => Some(|r| r.wall_seconds),
            _ => None,
        };
        if let Some(value) = common {
            return Some(self.rows.iter().map(|r| Some(value(r))).collect());
        }
        if name == EVAL_RETURN_UNDISCOUNTED {
            return self.has_undiscounted.then(|| {
                self.rows
                    .iter()
                    .map(|r| r.eval_return_undiscounted)
                    .collect()
            });
        }
        let at = self.family_columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r.family[at]).collect())
    }
}

/// Why a metrics file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum MetricsError {
    /// The CSV reader or writer failed.
    #[error("{path}: {source}")]
    Csv {
        /// The metrics file.
        path: String,
        /// The CSV error.
        source: csv::Error,
    },
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The metrics file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The header or a row does not have the expected columns.
    #[error("{path}: {message}")]
    Layout {
        /// The metrics file.
        path: String,
        /// What was expected.
        message: String,
    },
}

/// One CSV cell, written exactly as the csv crate writes the field's type (integers as
/// integers, floats by `ryu`, `None` as an empty cell).
#[derive(Serialize)]
#[serde(untagged)]
enum Cell {
    Count(u64),
    Value(Option<f64>),
}

/// The rows as CSV text, header first. Every row must have one family value per
/// `family_columns` entry (panics otherwise: a learner defect).
pub fn to_csv(family_columns: &[&str], rows: &[MetricsRow]) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let header: Vec<&str> = LEADING_COLUMNS
        .iter()
        .chain(std::iter::once(&EVAL_RETURN_UNDISCOUNTED))
        .chain(family_columns)
        .chain(std::iter::once(&WALL_SECONDS))
        .copied()
        .collect();
    w.write_record(&header)?;
    for r in rows {
        assert_eq!(
            r.family.len(),
            family_columns.len(),
            "a metrics row has one value per family column"
        );
        let mut cells = vec![
            Cell::Count(r.episode),
            Cell::Count(r.env_steps),
            Cell::Count(r.updates),
            Cell::Value(Some(r.eval_return)),
            Cell::Value(r.eval_return_undiscounted),
        ];
        cells.extend(r.family.iter().map(|&v| Cell::Value(v)));
        cells.push(Cell::Value(Some(r.wall_seconds)));
        w.serialize(cells)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// Write the whole curve atomically.
pub fn write(
    path: &Path,
    family_columns: &[&str],
    rows: &[MetricsRow],
) -> Result<(), MetricsError> {
    let p = || path.display().to_string();
    let bytes =
        to_csv(family_columns, rows).map_err(|source| MetricsError::Csv { path: p(), source })?;
    crate::files::atomic::write_atomic(path, &bytes)
        .map_err(|source| MetricsError::Io { path: p(), source })
}

/// The bytes of a metrics file as CSV text, decompressing a `.gz` file (both at most
/// [`MAX_METRICS_BYTES`]).
pub fn read_text(path: &Path) -> Result<Vec<u8>, MetricsError> {
    let p = || path.display().to_string();
    let io = |source| MetricsError::Io { path: p(), source };
    // Inside a results tree: a regular file, not a link, of bounded size, also decompressed.
    let bytes = read_in_tree(path, MAX_METRICS_BYTES).map_err(io)?;
    if path.extension().is_some_and(|e| e == "gz") {
        gunzip_bounded(&bytes, MAX_METRICS_BYTES).map_err(io)
    } else {
        Ok(bytes)
    }
}

/// Read a curve written by [`fn@write`] (or its gzip-compressed copy), whatever the family: the
/// columns between `eval_return` (or `eval_return_undiscounted`, where the file has it) and
/// `wall_seconds` are the family's. A missing leading column, a cell that is not a number, or a
/// row of the wrong length is an error naming it.
pub fn read(path: &Path) -> Result<MetricsTable, MetricsError> {
    let p = || path.display().to_string();
    let text = read_text(path)?;
    let csv_err = |source| MetricsError::Csv { path: p(), source };
    let layout = |message: String| MetricsError::Layout { path: p(), message };
    let mut r = csv::Reader::from_reader(&text[..]);
    let header: Vec<String> = r
        .headers()
        .map_err(csv_err)?
        .iter()
        .map(str::to_string)
        .collect();
    let n = header.len();
    if n < LEADING_COLUMNS.len() + 1
        || !header
            .iter()
            .take(LEADING_COLUMNS.len())
            .eq(LEADING_COLUMNS.iter())
        || header[n - 1] != WALL_SECONDS
    {
        return Err(layout(format!(
            "the header must start with `{}` and end with `{WALL_SECONDS}`, got `{}`",
            LEADING_COLUMNS.join(","),
            header.join(",")
        )));
    }
    let has_undiscounted = header[LEADING_COLUMNS.len()] == EVAL_RETURN_UNDISCOUNTED;
    let first_family = LEADING_COLUMNS.len() + usize::from(has_undiscounted);
    let family_columns = header[first_family..n - 1].to_vec();
    // Readers index columns by name (`plot --metric`, `macdec results`, `load_results`): a name
    // given twice would make one column silently replace the other.
    for (k, name) in family_columns.iter().enumerate() {
        let reserved = LEADING_COLUMNS.contains(&name.as_str())
            || name == EVAL_RETURN_UNDISCOUNTED
            || name == WALL_SECONDS;
        if reserved || family_columns[..k].contains(name) || name.is_empty() {
            return Err(layout(format!(
                "the column name `{name}` is empty or appears twice in the header `{}`",
                header.join(",")
            )));
        }
    }
    let mut rows = Vec::new();
    for (i, record) in r.records().enumerate() {
        let record = record.map_err(csv_err)?;
        let line = i + 2;
        let cell = |k: usize| record.get(k).unwrap_or("");
        let number = |k: usize| -> Result<f64, MetricsError> {
            cell(k).parse::<f64>().map_err(|_| {
                layout(format!(
                    "line {line}: `{}` is not a number: {:?}",
                    header[k],
                    cell(k)
                ))
            })
        };
        let count = |k: usize| -> Result<u64, MetricsError> {
            cell(k).parse::<u64>().map_err(|_| {
                layout(format!(
                    "line {line}: `{}` is not a count: {:?}",
                    header[k],
                    cell(k)
                ))
            })
        };
        let optional = |k: usize| match cell(k) {
            "" => Ok(None),
            _ => number(k).map(Some),
        };
        let family = (first_family..n - 1)
            .map(optional)
            .collect::<Result<Vec<_>, _>>()?;
        rows.push(MetricsRow {
            episode: count(0)?,
            env_steps: count(1)?,
            updates: count(2)?,
            eval_return: number(3)?,
            eval_return_undiscounted: if has_undiscounted { optional(4)? } else { None },
            family,
            wall_seconds: number(n - 1)?,
        });
    }
    Ok(MetricsTable {
        has_undiscounted,
        family_columns,
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_round_trip_with_missing_loss() {
        let rows = vec![
            MetricsRow {
                episode: 0,
                env_steps: 0,
                updates: 0,
                eval_return: -4.5,
                eval_return_undiscounted: Some(-6.0),
                family: vec![Some(1.0), Some(1.0), None],
                wall_seconds: 0.1,
            },
            MetricsRow {
                episode: 10,
                env_steps: 900,
                updates: 50,
                eval_return: 80.7,
                eval_return_undiscounted: Some(92.0),
                family: vec![Some(0.99), Some(1.0), Some(0.25)],
                wall_seconds: 1.5,
            },
        ];
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("metrics.csv");
        let columns = ["epsilon", "hysteresis", "loss"];
        write(&p, &columns, &rows).unwrap();
        let table = read(&p).unwrap();
        assert_eq!(table.rows, rows);
        assert_eq!(table.family_columns, columns);
        assert_eq!(table.column("loss"), Some(vec![None, Some(0.25)]));
        assert_eq!(table.column("episode"), Some(vec![Some(0.0), Some(10.0)]));
        assert_eq!(table.column("q_loss"), None);
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.starts_with(
            "episode,env_steps,updates,eval_return,eval_return_undiscounted,epsilon,hysteresis,loss,wall_seconds\n"
        ));
        assert_eq!(
            table.column(EVAL_RETURN_UNDISCOUNTED),
            Some(vec![Some(-6.0), Some(92.0)])
        );
        assert_eq!(locate(dir.path()), Some(p.clone()));

        // The committed form: gzip only, read back to the same rows.
        let gz = dir.path().join(METRICS_FILE_GZ);
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        std::io::Write::write_all(&mut enc, text.as_bytes()).unwrap();
        std::fs::write(&gz, enc.finish().unwrap()).unwrap();
        std::fs::remove_file(&p).unwrap();
        assert_eq!(locate(dir.path()), Some(gz.clone()));
        assert_eq!(read(&gz).unwrap().rows, rows);
        std::fs::write(&gz, b"not gzip").unwrap();
        assert!(matches!(read(&gz), Err(MetricsError::Io { .. })));
    }

    #[test]
    fn any_family_columns_round_trip_and_an_empty_curve_keeps_its_header() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("metrics.csv");
        write(&p, &["actor_loss", "critic_loss"], &[]).unwrap();
        assert_eq!(
            std::fs::read_to_string(&p).unwrap(),
            "episode,env_steps,updates,eval_return,eval_return_undiscounted,actor_loss,critic_loss,wall_seconds\n"
        );
        let row = MetricsRow {
            episode: 96,
            env_steps: 9600,
            updates: 12,
            eval_return: 1e20,
            eval_return_undiscounted: Some(3.5),
            family: vec![None, Some(-0.5)],
            wall_seconds: 2.0,
        };
        write(
            &p,
            &["actor_loss", "critic_loss"],
            std::slice::from_ref(&row),
        )
        .unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(
            text.ends_with("\n96,9600,12,1e20,3.5,,-0.5,2.0\n"),
            "{text}"
        );
        let table = read(&p).unwrap();
        assert_eq!(table.family_columns, ["actor_loss", "critic_loss"]);
        assert_eq!(table.rows, vec![row]);
    }

    #[test]
    fn a_file_of_a_run_trained_before_the_undiscounted_column_reads_as_before() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("metrics.csv");
        std::fs::write(
            &p,
            "episode,env_steps,updates,eval_return,eps,critic_loss,wall_seconds\n0,0,0,1.5,1,,0.1\n",
        )
        .unwrap();
        let table = read(&p).unwrap();
        assert!(!table.has_undiscounted);
        assert_eq!(table.family_columns, ["eps", "critic_loss"]);
        assert_eq!(table.rows[0].eval_return_undiscounted, None);
        assert_eq!(table.column(EVAL_RETURN_UNDISCOUNTED), None);
        assert_eq!(table.column("eps"), Some(vec![Some(1.0)]));
        // With the column, an empty cell is a missing value and a bad one is named.
        std::fs::write(
            &p,
            "episode,env_steps,updates,eval_return,eval_return_undiscounted,wall_seconds\n0,0,0,1.5,,0.1\n",
        )
        .unwrap();
        let table = read(&p).unwrap();
        assert!(table.has_undiscounted && table.family_columns.is_empty());
        assert_eq!(table.column(EVAL_RETURN_UNDISCOUNTED), Some(vec![None]));
        std::fs::write(
            &p,
            "episode,env_steps,updates,eval_return,eval_return_undiscounted,wall_seconds\n0,0,0,1.5,x,0.1\n",
        )
        .unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("`eval_return_undiscounted`"), "{e}");
    }

    #[test]
    fn a_file_without_the_leading_columns_or_with_a_bad_cell_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("metrics.csv");
        std::fs::write(&p, "episode,eval_return\n0,1.5\n").unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("must start with"), "{e}");
        std::fs::write(
            &p,
            "episode,env_steps,updates,eval_return,loss,wall_seconds\n0,0,0,1.5,abc,0.1\n",
        )
        .unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("`loss`"), "{e}");
        std::fs::write(
            &p,
            "episode,env_steps,updates,eval_return,wall_seconds\n-1,0,0,1.5,0.1\n",
        )
        .unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("`episode` is not a count"), "{e}");
    }

    #[test]
    fn a_column_name_given_twice_is_refused_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("metrics.csv");
        for (family, name) in [
            ("loss,loss", "loss"),
            ("eval_return", "eval_return"),
            ("wall_seconds", "wall_seconds"),
            ("episode", "episode"),
            ("eps,eval_return_undiscounted", "eval_return_undiscounted"),
        ] {
            let cells = vec!["1"; family.split(',').count()].join(",");
            std::fs::write(
                &p,
                format!(
                    "episode,env_steps,updates,eval_return,{family},wall_seconds\n0,0,0,1.5,{cells},0.1\n"
                ),
            )
            .unwrap();
            let e = read(&p).unwrap_err().to_string();
            assert!(
                e.contains(&format!("`{name}` is empty or appears twice")),
                "{e}"
            );
        }
        // The undiscounted return in its own place is no family column.
        std::fs::write(
            &p,
            "episode,env_steps,updates,eval_return,eval_return_undiscounted,loss,wall_seconds\n0,0,0,1.5,2,3,0.1\n",
        )
        .unwrap();
        assert_eq!(read(&p).unwrap().family_columns, ["loss"]);
    }
}
