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
/// The same curve gzip-compressed, as committed results store it (`scripts/campaign.sh collect`).
pub const METRICS_FILE_GZ: &str = "metrics.csv.gz";

/// The metrics file of the run in `dir`: `metrics.csv` (what a run writes as it goes) if present,
/// else the committed `metrics.csv.gz`; `None` when neither exists.
pub fn locate(dir: &Path) -> Option<std::path::PathBuf> {
    [METRICS_FILE, METRICS_FILE_GZ]
        .iter()
        .map(|name| dir.join(name))
        .find(|p| p.is_file())
}

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

/// The bytes of a metrics file as CSV text, decompressing a `.gz` file.
pub fn read_text(path: &Path) -> Result<Vec<u8>, MetricsError> {
    let p = || path.display().to_string();
    let io = |source| MetricsError::Io { path: p(), source };
    let bytes = std::fs::read(path).map_err(io)?;
    if path.extension().is_some_and(|e| e == "gz") {
        let mut text = Vec::new();
        std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&bytes[..]), &mut text)
            .map_err(io)?;
        Ok(text)
    } else {
        Ok(bytes)
    }
}

/// Read a curve written by [`write`] (or its gzip-compressed copy).
pub fn read(path: &Path) -> Result<Vec<MetricsRow>, MetricsError> {
    let p = || path.display().to_string();
    let text = read_text(path)?;
    let mut r = csv::Reader::from_reader(&text[..]);
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
        assert_eq!(locate(dir.path()), Some(p.clone()));

        // The committed form: gzip only, read back to the same rows.
        let gz = dir.path().join(METRICS_FILE_GZ);
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        std::io::Write::write_all(&mut enc, text.as_bytes()).unwrap();
        std::fs::write(&gz, enc.finish().unwrap()).unwrap();
        std::fs::remove_file(&p).unwrap();
        assert_eq!(locate(dir.path()), Some(gz.clone()));
        assert_eq!(read(&gz).unwrap(), rows);
        std::fs::write(&gz, b"not gzip").unwrap();
        assert!(matches!(read(&gz), Err(MetricsError::Io { .. })));
    }
}
