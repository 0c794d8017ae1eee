//! Why `macdec plot` could not produce its figures.

use std::path::PathBuf;

/// A failure of the plotting pipeline. Messages name the file and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The results directory could not be listed.
    #[error("{path}: cannot read the results directory: {source}")]
    ReadResults {
        /// The directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// No run with a metrics file below the directory.
    #[error(
        "{path}: no runs found (expected <results>/<experiment>/<curve>/seed-<k>/metrics.csv)"
    )]
    NoRuns {
        /// The directory.
        path: PathBuf,
    },
    /// Every metrics file is unreadable; this is one of them.
    #[error("{path}: malformed metrics file, and no other run is readable: {message}")]
    Malformed {
        /// The metrics file.
        path: PathBuf,
        /// The reader's reason.
        message: String,
    },
    /// A figure or table could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// The output file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The plotting backend failed.
    #[error("{path}: cannot draw the figure: {message}")]
    Draw {
        /// The figure.
        path: PathBuf,
        /// The backend's reason.
        message: String,
    },
    /// `--beside`'s file or one of the logs it names cannot be used.
    #[error("{path}: {reason}")]
    Beside {
        /// The file or directory.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// `--beside` with axes the outside logs do not have.
    #[error("--beside draws outside logs of undiscounted returns against step counts: give --y undiscounted with --x env_steps (or --x acac_timesteps, the steps ACAC's logs count)")]
    BesideAxes,
    /// The embedded font did not load (a build error).
    #[error("the embedded DejaVu Sans font could not be loaded")]
    Font,
}
