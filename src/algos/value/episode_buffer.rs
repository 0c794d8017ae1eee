//! `ReplayMemory_epi` (`docs/ALGORITHMS.md` §3.2, `--sample_epi`, Warehouse): a FIFO of whole
//! episodes; a batch is `batch_size` episodes drawn with replacement, padded (in the reference) to
//! the longest one, T = that length.

use std::collections::VecDeque;

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::batch::{Batch, Sequence};
use super::record::{Episode, Layout};
use super::ReplayError;

/// Episode replay; capacity counts episodes (WTD: 1000).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "EpisodeBufferState")]
pub struct EpisodeBuffer {
    layout: Layout,
    capacity: usize,
    episodes: VecDeque<Episode>,
}

#[derive(Deserialize)]
struct EpisodeBufferState {
    layout: Layout,
    capacity: usize,
    episodes: VecDeque<Episode>,
}

impl TryFrom<EpisodeBufferState> for EpisodeBuffer {
    type Error = ReplayError;
    fn try_from(st: EpisodeBufferState) -> Result<Self, Self::Error> {
        let mut buf = EpisodeBuffer::new(&st.layout, st.capacity)?;
        if st.episodes.len() > st.capacity {
            return Err(ReplayError::Corrupt(format!(
                "{} episodes exceed the capacity of {}",
                st.episodes.len(),
                st.capacity
            )));
        }
        for episode in st.episodes {
            buf.push(episode)?;
        }
        Ok(buf)
    }
}

impl EpisodeBuffer {
    /// `capacity` episodes (spec: `replay_buffer_size` with `--sample_epi`).
    pub fn new(layout: &Layout, capacity: usize) -> Result<Self, ReplayError> {
        if capacity == 0 {
            return Err(ReplayError::Zero {
                name: "replay_buffer_size",
            });
        }
        Ok(Self {
            layout: layout.clone(),
            capacity,
            episodes: VecDeque::with_capacity(capacity.min(4096)),
        })
    }

    /// Store `episode`, dropping the oldest one when full. Refuses an empty episode or one of
    /// another layout.
    pub fn push(&mut self, episode: Episode) -> Result<(), ReplayError> {
        if episode.is_empty() {
            return Err(ReplayError::EmptyEpisode);
        }
        episode.check_layout(&self.layout)?;
        if self.episodes.len() == self.capacity {
            self.episodes.pop_front();
        }
        self.episodes.push_back(episode);
        Ok(())
    }

    /// `batch_size` episodes drawn uniformly with replacement; `padded_len` = the longest.
    pub fn sample(
        &self,
        batch_size: usize,
        rng: &mut ChaCha8Rng,
    ) -> Result<Batch<'_>, ReplayError> {
        if self.episodes.is_empty() {
            return Err(ReplayError::EmptyBuffer);
        }
        let sequences: Vec<Sequence<'_>> = (0..batch_size)
            .map(|_| {
                let episode = &self.episodes[rng.gen_range(0..self.episodes.len())];
                Sequence {
                    episode,
                    start: 0,
                    end: episode.len(),
                    lead_pad: 0,
                }
            })
            .collect();
        let padded_len = sequences.iter().map(Sequence::len).max().unwrap_or(0);
        Ok(Batch {
            sequences,
            padded_len,
        })
    }

    /// Episodes held.
    pub fn len(&self) -> usize {
        self.episodes.len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.episodes.is_empty()
    }
    /// Capacity in episodes.
    pub fn capacity(&self) -> usize {
        self.capacity
    }
    /// The record layout accepted.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::value::record::RecordRef;
    use crate::algos::value::replay::ReplayBuffer;
    use rand::SeedableRng;

    fn layout() -> Layout {
        Layout::new(&[1], &[2]).unwrap()
    }

    fn episode(len: usize, tag: f32) -> Episode {
        let mut ep = Episode::new(1, 1, len);
        for t in 0..len {
            ep.push(RecordRef {
                obs: &[tag + t as f32],
                executed: &[t % 2],
                acc_id: &[-1.0],
                acc_joint: -1.0,
                next_obs: &[tag + t as f32 + 1.0],
                done: t + 1 == len,
                valid: &[true],
            })
            .unwrap();
        }
        ep
    }

    fn tags(batch: &Batch<'_>) -> Vec<f32> {
        batch
            .sequences
            .iter()
            .map(|s| s.episode.obs(0)[0])
            .collect()
    }

    #[test]
    fn batch_covers_whole_episodes_and_pads_to_the_longest() {
        let mut buf = EpisodeBuffer::new(&layout(), 10).unwrap();
        buf.push(episode(3, 0.0)).unwrap();
        buf.push(episode(7, 100.0)).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let batch = buf.sample(16, &mut rng).unwrap();
        assert_eq!(batch.sequences.len(), 16);
        for s in &batch.sequences {
            assert_eq!((s.start, s.end, s.lead_pad), (0, s.episode.len(), 0));
        }
        let longest = batch.sequences.iter().map(|s| s.len()).max().unwrap();
        assert_eq!(batch.padded_len, longest);
        assert!(tags(&batch).contains(&0.0) && tags(&batch).contains(&100.0));
        assert_eq!(batch.padded_len, 7);
    }

    #[test]
    fn fifo_drops_the_oldest_episode_when_full() {
        let mut buf = EpisodeBuffer::new(&layout(), 2).unwrap();
        for k in 0..3 {
            buf.push(episode(2, 100.0 * k as f32)).unwrap();
        }
        assert_eq!(buf.len(), 2);
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let seen = tags(&buf.sample(64, &mut rng).unwrap());
        assert!(!seen.contains(&0.0));
        assert!(seen.contains(&100.0) && seen.contains(&200.0));
    }

    #[test]
    fn same_seed_same_batch_and_serde_round_trip() {
        let mut buf = ReplayBuffer::episodes(&layout(), 5).unwrap();
        for k in 0..4 {
            buf.push(episode(1 + k, 10.0 * k as f32)).unwrap();
        }
        let json = serde_json::to_string(&buf).unwrap();
        let back: ReplayBuffer = serde_json::from_str(&json).unwrap();
        let mut r1 = ChaCha8Rng::seed_from_u64(9);
        let mut r2 = ChaCha8Rng::seed_from_u64(9);
        let a = buf.sample(16, &mut r1).unwrap();
        let b = back.sample(16, &mut r2).unwrap();
        assert_eq!(tags(&a), tags(&b));
        assert_eq!(a.padded_len, b.padded_len);
        let mut r3 = ChaCha8Rng::seed_from_u64(9);
        assert_eq!(tags(&buf.sample(16, &mut r3).unwrap()), tags(&a));
    }

    #[test]
    fn refuses_empty_and_foreign_episodes() {
        let mut buf = EpisodeBuffer::new(&layout(), 2).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        assert_eq!(
            buf.sample(1, &mut rng).unwrap_err(),
            ReplayError::EmptyBuffer
        );
        assert_eq!(
            buf.push(Episode::new(1, 1, 0)),
            Err(ReplayError::EmptyEpisode)
        );
        assert!(matches!(
            buf.push(Episode::new(2, 1, 0)),
            Err(ReplayError::EmptyEpisode)
        ));
        let mut two = Episode::new(1, 2, 1);
        two.push(RecordRef {
            obs: &[0.0, 0.0],
            executed: &[0],
            acc_id: &[0.0],
            acc_joint: 0.0,
            next_obs: &[0.0, 0.0],
            done: true,
            valid: &[true],
        })
        .unwrap();
        assert!(matches!(
            buf.push(two),
            Err(ReplayError::LayoutMismatch { .. })
        ));
    }
}
