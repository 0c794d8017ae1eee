//! What the ACAC family refuses while training.

/// Why an ACAC run cannot proceed.
#[derive(Debug, thiserror::Error)]
pub enum AcacError {
    /// The method's learner is not in macdec yet (README "ACAC": what exists and what does not).
    #[error(
        "{method}: ACAC's learner is not implemented in macdec yet; its config, published \
         settings and experiment files are (README \"ACAC\")"
    )]
    LearnerMissing {
        /// The method asked for (its command-line name).
        method: &'static str,
    },
}
