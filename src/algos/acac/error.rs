//! What the ACAC family refuses while training.

/// Why an ACAC run cannot proceed.
#[derive(Debug, thiserror::Error)]
pub enum AcacError {
    /// An update could not run on the batch collected (named by the reference's check).
    #[error("{method} seed {seed}, after {episodes} episodes: {reason}")]
    Update {
        /// The method.
        method: &'static str,
        /// The run's seed.
        seed: u64,
        /// Training episodes done.
        episodes: u64,
        /// Why.
        reason: String,
    },
}
