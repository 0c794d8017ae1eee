//! The per-run learning curve: one `metrics.csv` row per evaluation.
//!
//! Columns (stable names other tools read): `episode` (training episodes completed),
//! `env_steps` (primitive steps taken by the training env(s)), `updates` (training iterations),
//! `eval_return` (mean greedy discounted return, spec `algorithms.md` 7.1), `epsilon`,
//! `hysteresis`, `loss` (mean total TD loss over the iterations since the previous row; empty
//! before the first), `wall_seconds` (time since the run started, including resumed segments; the
//! only column that is not reproducible bit for bit).

use std::path::Path;

/// The file name of a run's learning curve.
pub const METRICS_FILE: &str = "metrics.csv";

/// One evaluation point of a run: the trainer's own record, written as one CSV row.
pub use crate::algos::trainer::EvalPoint as MetricsRow;

/// Why a metrics file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum MetricsError {
    #[error("{path}: {source}")]
    Csv { path: String, source: csv::Error },
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

/// The rows as CSV text, header first.
pub fn to_csv(rows: &[MetricsRow]) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    if rows.is_empty() {
        w.write_record([
            "episode",
            "env_steps",
            "updates",
            "eval_return",
            "epsilon",
            "hysteresis",
            "loss",
            "wall_seconds",
        ])?;
    }
    for r in rows {
        w.serialize(r)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// Write the whole curve atomically.
pub fn write(path: &Path, rows: &[MetricsRow]) -> Result<(), MetricsError> {
    let p = || path.display().to_string();
    let bytes = to_csv(rows).map_err(|source| MetricsError::Csv { path: p(), source })?;
    super::atomic::write_atomic(path, &bytes)
        .map_err(|source| MetricsError::Io { path: p(), source })
}

/// Read a curve written by [`write`].
pub fn read(path: &Path) -> Result<Vec<MetricsRow>, MetricsError> {
    let p = || path.display().to_string();
    let mut r =
        csv::Reader::from_path(path).map_err(|source| MetricsError::Csv { path: p(), source })?;
    r.deserialize()
        .collect::<Result<_, _>>()
        .map_err(|source| MetricsError::Csv { path: p(), source })
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
                epsilon: 1.0,
                hysteresis: 1.0,
                loss: None,
                wall_seconds: 0.1,
            },
            MetricsRow {
                episode: 10,
                env_steps: 900,
                updates: 50,
                eval_return: 80.7,
                epsilon: 0.99,
                hysteresis: 1.0,
                loss: Some(0.25),
                wall_seconds: 1.5,
            },
        ];
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("metrics.csv");
        write(&p, &rows).unwrap();
        assert_eq!(read(&p).unwrap(), rows);
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.starts_with(
            "episode,env_steps,updates,eval_return,epsilon,hysteresis,loss,wall_seconds\n"
        ));
    }
}
