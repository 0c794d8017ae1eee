//! A stop request shared between whoever wants training to end early (Python's Ctrl-C, a
//! library caller) and the runs: each run checks it after every training episode and, when it
//! is set, saves its checkpoint, metrics and policy files and ends as stopped, so training the
//! same experiment again resumes it ([`super::train_run::train_run_until`]).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A flag that only ever goes from "run" to "stop". Clones share the flag.
#[derive(Debug, Clone, Default)]
pub struct StopSignal(Arc<AtomicBool>);

impl StopSignal {
    /// A signal not yet raised.
    pub fn new() -> Self {
        Self::default()
    }

    /// Ask every run holding a clone of this signal to stop at its next episode boundary.
    pub fn stop(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether a stop was asked for.
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}
