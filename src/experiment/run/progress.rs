//! What a training run and the runner tell each other: the progress handle the run updates as
//! its episodes complete ([`Progress`]: a bar, or a heartbeat line without a terminal) and how
//! it ended when it did not fail ([`RunEnd`]). The runner ([`super::runner`]) makes the handles
//! and reads the ends; the function training a run ([`super::train_run`]) only uses these.

use indicatif::ProgressBar;
use std::sync::Arc;

/// How often a run reports how far it got when there are no progress bars and no `--quiet`
/// (stderr is not a terminal: a log file, a pipe, a batch job).
pub const HEARTBEAT: std::time::Duration = std::time::Duration::from_secs(60);

/// The heartbeat of one run drawn without bars: its name, its episode count and when it last
/// reported.
pub(super) struct Heartbeat {
    pub(super) name: String,
    pub(super) total_epi: u64,
    pub(super) last: std::sync::Mutex<std::time::Instant>,
}

/// How a run that did not fail ended, as the function training it reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunEnd {
    /// Trained to its end (or the rest of the way from its checkpoint).
    Trained,
    /// Already finished when its turn came (another process finished it meanwhile).
    AlreadyFinished,
    /// Another process holds the run's lock and is training it: left to that process, so
    /// several processes (or machines sharing the results tree) can work through one campaign.
    Busy,
    /// Stopped early on request ([`crate::experiment::run::stop::StopSignal`]), its checkpoint
    /// saved: training it again resumes it.
    Stopped,
}

/// A progress handle a run updates as episodes complete.
#[derive(Clone)]
pub struct Progress {
    pub(super) bar: ProgressBar,
    pub(super) total: ProgressBar,
    pub(super) last: Arc<std::sync::atomic::AtomicU64>,
    pub(super) heartbeat: Option<Arc<Heartbeat>>,
}

impl Progress {
    /// A handle that draws nothing (for tests and library callers).
    pub fn hidden() -> Self {
        Progress {
            bar: ProgressBar::hidden(),
            total: ProgressBar::hidden(),
            last: Arc::default(),
            heartbeat: None,
        }
    }

    /// Report that `episodes` training episodes are complete, with a short status message.
    pub fn update(&self, episodes: u64, message: impl Into<std::borrow::Cow<'static, str>>) {
        use std::sync::atomic::Ordering;
        let before = self.last.swap(episodes, Ordering::Relaxed);
        self.total.inc(episodes.saturating_sub(before));
        self.bar.set_position(episodes);
        let message = message.into();
        if let Some(h) = &self.heartbeat {
            let mut last = h.last.lock().unwrap_or_else(|e| e.into_inner());
            if last.elapsed() >= HEARTBEAT {
                *last = std::time::Instant::now();
                eprintln!(
                    "{}: episode {episodes} of {} {message}",
                    h.name, h.total_epi
                );
            }
        }
        self.bar.set_message(message);
    }
}
