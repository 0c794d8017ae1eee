//! Why `macdec plot` could not produce its figures.

use std::path::PathBuf;

/// A failure of the plotting pipeline. Messages name the file and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("{path}: cannot read the results directory: {source}")]
    ReadResults {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{path}: no runs found (expected <results>/<experiment>/<curve>/seed-<k>/metrics.csv)"
    )]
    NoRuns { path: PathBuf },
    #[error("{path}: malformed metrics file, and no other run is readable: {message}")]
    Malformed { path: PathBuf, message: String },
    #[error("{path}: cannot write: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: cannot draw the figure: {message}")]
    Draw { path: PathBuf, message: String },
    #[error("the embedded DejaVu Sans font could not be loaded")]
    Font,
}
