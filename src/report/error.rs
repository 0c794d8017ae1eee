//! Why `macdec report` could not produce its statistics.

use crate::plot::PlotError;

/// A failure of the report. Messages name the file or option and what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// Reading the results tree, or writing or drawing an output, failed (`plot`'s errors,
    /// which name the path).
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// The resample count is outside 1..=[`MAX_RESAMPLES`](super::bootstrap::MAX_RESAMPLES).
    #[error("resamples must be 1 to {max}, got {got}")]
    Resamples {
        /// The count asked for.
        got: usize,
        /// The largest allowed.
        max: usize,
    },
    /// A block asked for is not in the results tree.
    #[error("no block `{name}` with runs in the results tree (it has {found})")]
    NoSuchBlock {
        /// The block asked for.
        name: String,
        /// The blocks found, comma-separated.
        found: String,
    },
}
