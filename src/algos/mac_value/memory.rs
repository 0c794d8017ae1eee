//! MacroMARL's two value-based replay memories (`mac_dec_q/utils/memory.py`, `docs/MACROMARL.md`
//! §8.2): `ReplayMemory_rand` keeps windows of `trace_len` records and `ReplayMemory_epi` whole
//! episodes; both are FIFO and sample `batch_size` entries without replacement.
//!
//! A window is kept as a record range of its episode, not as padded copies: the reference pads an
//! episode with `trace_len - 1` zero records in front and after it, and its windows start at every
//! record of the padded cache, so an episode of L records gives L + trace_len - 1 windows; padding
//! is never valid, so the squeeze drops it and a window is exactly its records.

use std::collections::VecDeque;

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::episode::{Episode, Step};

/// A replay memory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Memory {
    /// `ReplayMemory_rand`: the last `capacity` windows.
    Windows {
        /// Records per window.
        trace_len: usize,
        /// Windows kept.
        capacity: usize,
        /// The episodes some kept window reads, oldest first; the first has id `first_id`.
        episodes: VecDeque<Episode>,
        /// The id of `episodes[0]`.
        first_id: u64,
        /// Each kept window: its episode's id and its start in the padded cache.
        windows: VecDeque<(u64, usize)>,
    },
    /// `ReplayMemory_epi`: the last `capacity` episodes.
    Episodes {
        /// Episodes kept.
        capacity: usize,
        /// The episodes, oldest first.
        episodes: VecDeque<Episode>,
    },
}

/// The sampled memory holds fewer entries than one batch samples without replacement.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the replay memory holds {held} {what}, fewer than batch_size {batch_size} (sampled without \
     replacement): raise start_train or lower batch_size"
)]
pub struct TooFewToSample {
    /// Entries held.
    pub held: usize,
    /// `windows` or `episodes`.
    pub what: &'static str,
    /// Entries asked for.
    pub batch_size: usize,
}

impl Memory {
    /// An empty memory: windows of `trace_len` unless `sample_epi`.
    pub fn new(sample_epi: bool, trace_len: usize, capacity: usize) -> Self {
        if sample_epi {
            Memory::Episodes {
                capacity,
                episodes: VecDeque::new(),
            }
        } else {
            Memory::Windows {
                trace_len,
                capacity,
                episodes: VecDeque::new(),
                first_id: 0,
                windows: VecDeque::new(),
            }
        }
    }

    /// Entries held (windows or episodes).
    pub fn len(&self) -> usize {
        match self {
            Memory::Windows { windows, .. } => windows.len(),
            Memory::Episodes { episodes, .. } => episodes.len(),
        }
    }

    /// Whether nothing is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Store a finished episode (`flush_scenario_cache`).
    pub fn push(&mut self, episode: Episode) {
        match self {
            Memory::Windows {
                trace_len,
                capacity,
                episodes,
                first_id,
                windows,
            } => {
                let id = *first_id + episodes.len() as u64;
                for start in 0..episode.len() + *trace_len - 1 {
                    windows.push_back((id, start));
                }
                episodes.push_back(episode);
                while windows.len() > *capacity {
                    windows.pop_front();
                }
                // Drop the episodes no kept window reads any more.
                let oldest = windows.front().map_or(id + 1, |w| w.0);
                while *first_id < oldest {
                    episodes.pop_front();
                    *first_id += 1;
                }
            }
            Memory::Episodes { capacity, episodes } => {
                episodes.push_back(episode);
                while episodes.len() > *capacity {
                    episodes.pop_front();
                }
            }
        }
    }

    /// Entry `index`'s records (oldest entry first).
    pub fn entry(&self, index: usize) -> &[Step] {
        match self {
            Memory::Windows {
                trace_len,
                episodes,
                first_id,
                windows,
                ..
            } => {
                let (id, start) = windows[index];
                let ep = &episodes[(id - first_id) as usize];
                // Window `start` covers cache positions start .. start + trace_len, i.e. records
                // start + 1 - trace_len ..= start, clipped to the episode.
                let lo = (start + 1).saturating_sub(*trace_len);
                let hi = (start + 1).min(ep.len());
                &ep[lo..hi]
            }
            Memory::Episodes { episodes, .. } => &episodes[index],
        }
    }

    /// `batch_size` distinct entries, uniformly (`np.random.choice(len, batch_size,
    /// replace=False)`), in the order drawn.
    pub fn sample(
        &self,
        batch_size: usize,
        rng: &mut ChaCha8Rng,
    ) -> Result<Vec<&[Step]>, TooFewToSample> {
        Ok(self
            .sample_indices(batch_size, rng)?
            .into_iter()
            .map(|i| self.entry(i))
            .collect())
    }

    /// The entries [`Self::sample`] draws, as indices for [`Self::entry`] (the same draws).
    pub fn sample_indices(
        &self,
        batch_size: usize,
        rng: &mut ChaCha8Rng,
    ) -> Result<Vec<usize>, TooFewToSample> {
        let held = self.len();
        if held < batch_size {
            return Err(TooFewToSample {
                held,
                what: match self {
                    Memory::Windows { .. } => "windows",
                    Memory::Episodes { .. } => "episodes",
                },
                batch_size,
            });
        }
        Ok(rand::seq::index::sample(rng, held, batch_size).into_vec())
    }

    /// Whole-episode memories: the ids of `entries` (indices for [`Self::entry`]) when `pushed`
    /// episodes were stored in all, episode n having id n, so an id names one episode for as long
    /// as it is kept. `None` for window memories, whose entries overlap.
    pub fn episode_ids(&self, entries: &[usize], pushed: u64) -> Option<Vec<u64>> {
        match self {
            Memory::Windows { .. } => None,
            Memory::Episodes { episodes, .. } => {
                let first = pushed - episodes.len() as u64;
                Some(entries.iter().map(|&i| first + i as u64).collect())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn episode(tag: usize, len: usize) -> Episode {
        (0..len)
            .map(|t| Step {
                obs: vec![tag as f32, t as f32],
                actions: vec![0],
                rewards: vec![0.0],
                gammas: vec![1.0],
                joint_reward: 0.0,
                joint_gamma: 1.0,
                next_obs: vec![0.0, 0.0],
                next_avail: vec![1.0],
                terminal: false,
                valid: vec![true],
            })
            .collect()
    }

    fn times(s: &[Step]) -> Vec<(usize, usize)> {
        s.iter()
            .map(|r| (r.obs[0] as usize, r.obs[1] as usize))
            .collect()
    }

    #[test]
    fn windows_cover_each_record_trace_len_times_with_the_reference_padding() {
        let mut m = Memory::new(false, 3, 100);
        m.push(episode(0, 4));
        // 4 + 3 - 1 windows: front padding first, back padding last.
        assert_eq!(m.len(), 6);
        let all: Vec<Vec<(usize, usize)>> = (0..6).map(|i| times(m.entry(i))).collect();
        assert_eq!(
            all,
            [
                vec![(0, 0)],
                vec![(0, 0), (0, 1)],
                vec![(0, 0), (0, 1), (0, 2)],
                vec![(0, 1), (0, 2), (0, 3)],
                vec![(0, 2), (0, 3)],
                vec![(0, 3)],
            ]
        );
    }

    #[test]
    fn memories_are_fifo_and_drop_unread_episodes() {
        let mut m = Memory::new(false, 2, 4);
        m.push(episode(0, 3)); // 4 windows
        m.push(episode(1, 1)); // 2 windows: the first episode's two oldest go
        assert_eq!(m.len(), 4);
        assert_eq!(times(m.entry(0)), [(0, 1), (0, 2)]);
        m.push(episode(2, 3));
        assert_eq!(times(m.entry(0)), [(2, 0)]);
        if let Memory::Windows { episodes, .. } = &m {
            assert_eq!(episodes.len(), 1);
        }
        let mut e = Memory::new(true, 2, 2);
        for k in 0..3 {
            e.push(episode(k, 2));
        }
        assert_eq!(times(e.entry(0))[0], (1, 0));
        let mut rng = rand::SeedableRng::seed_from_u64(0);
        let err = e.sample(3, &mut rng).unwrap_err().to_string();
        assert!(err.contains("batch_size 3"), "{err}");
        let batch = e.sample(2, &mut rng).unwrap();
        assert_ne!(
            batch[0][0].obs[0], batch[1][0].obs[0],
            "without replacement"
        );
    }
}
