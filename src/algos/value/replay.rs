//! What a replay buffer hands to the learner: a batch of sequences of primitive-step records
//! (`docs/ALGORITHMS.md` §3), and the one buffer type the trainer holds, whichever kind it is.
//!
//! A sequence is a contiguous run of one stored episode's records; the zero-padding records of the
//! reference (left padding of the first windows, right padding to the window length or to the
//! batch's longest episode) are never materialised, because squeezing removes every one of them
//! (`docs/ALGORITHMS.md` §3: all v_i = 0). Their count is kept for information only.

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::episode_buffer::EpisodeBuffer;
use super::record::{Episode, Layout};
use super::window_buffer::WindowBuffer;
use super::ReplayError;

pub use super::batch::{Batch, Sequence};

/// The replay of one training environment: windows (`docs/ALGORITHMS.md` §3.1, Box Pushing) or whole episodes
/// (`docs/ALGORITHMS.md` §3.2, `sample_epi`, Warehouse).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum ReplayBuffer {
    /// Fixed-length windows (`docs/ALGORITHMS.md` §3.1).
    Windows(WindowBuffer),
    /// Whole episodes (`docs/ALGORITHMS.md` §3.2).
    Episodes(EpisodeBuffer),
}

impl ReplayBuffer {
    /// A windowed buffer: `capacity_windows` windows of `trace_len` records.
    pub fn windows(
        layout: &Layout,
        capacity_windows: usize,
        trace_len: usize,
    ) -> Result<Self, ReplayError> {
        WindowBuffer::new(layout, capacity_windows, trace_len).map(Self::Windows)
    }

    /// An episode buffer holding `capacity_episodes` episodes.
    pub fn episodes(layout: &Layout, capacity_episodes: usize) -> Result<Self, ReplayError> {
        EpisodeBuffer::new(layout, capacity_episodes).map(Self::Episodes)
    }

    /// Store a finished episode, evicting the oldest content past capacity.
    pub fn push(&mut self, episode: Episode) -> Result<(), ReplayError> {
        match self {
            Self::Windows(b) => b.push(episode),
            Self::Episodes(b) => b.push(episode),
        }
    }

    /// `batch_size` sequences drawn uniformly with replacement.
    pub fn sample(
        &self,
        batch_size: usize,
        rng: &mut ChaCha8Rng,
    ) -> Result<Batch<'_>, ReplayError> {
        match self {
            Self::Windows(b) => b.sample(batch_size, rng),
            Self::Episodes(b) => b.sample(batch_size, rng),
        }
    }

    /// Stored elements in the buffer's own unit (windows or episodes).
    pub fn len(&self) -> usize {
        match self {
            Self::Windows(b) => b.len(),
            Self::Episodes(b) => b.len(),
        }
    }

    /// True when nothing can be sampled yet.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Episodes (wholly or partly) held.
    pub fn n_episodes(&self) -> usize {
        match self {
            Self::Windows(b) => b.n_episodes(),
            Self::Episodes(b) => b.len(),
        }
    }

    /// The record layout the buffer accepts.
    pub fn layout(&self) -> &Layout {
        match self {
            Self::Windows(b) => b.layout(),
            Self::Episodes(b) => b.layout(),
        }
    }
}
