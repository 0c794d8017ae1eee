//! `ReplayMemory_rand` (`docs/ALGORITHMS.md` §3.1, quirk Q16): a FIFO of fixed-length windows.
//!
//! An episode of L records contributes the L + trace_len - 1 windows `cache[s .. s + trace_len]`
//! of `cache = [zero] * (trace_len - 1) + records`, right-padded with zeros: the first trace_len - 1
//! are left-padded prefixes, the last trace_len - 1 right-padded suffixes, and every record sits in
//! exactly trace_len windows. Capacity counts windows. Each episode is stored once; a window is a
//! (episode, start) reference, and an episode is dropped when its last window is evicted.

use std::collections::VecDeque;

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize, Serializer};

use super::batch::{Batch, Sequence};
use super::record::{Episode, Layout};
use super::ReplayError;

/// One window: the window with start index `s` (into the padded cache) of episode `episode_no`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct WindowRef {
    /// Running number of the episode since the buffer was built (or loaded).
    episode_no: u64,
    s: u32,
}

/// Windowed replay. Serialised as its episodes plus how many windows of the oldest one were
/// already evicted; the window list is rebuilt (and checked) on load.
#[derive(Debug, Clone, Deserialize)]
#[serde(try_from = "WindowBufferState")]
pub struct WindowBuffer {
    layout: Layout,
    capacity: usize,
    trace_len: usize,
    episodes: VecDeque<Episode>,
    /// Running number of `episodes[0]`.
    first_episode_no: u64,
    windows: VecDeque<WindowRef>,
}

#[derive(Serialize)]
struct WindowBufferStateRef<'a> {
    layout: &'a Layout,
    capacity: usize,
    trace_len: usize,
    episodes: &'a VecDeque<Episode>,
    front_skip: usize,
}

#[derive(Deserialize)]
struct WindowBufferState {
    layout: Layout,
    capacity: usize,
    trace_len: usize,
    episodes: VecDeque<Episode>,
    front_skip: usize,
}

impl Serialize for WindowBuffer {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        WindowBufferStateRef {
            layout: &self.layout,
            capacity: self.capacity,
            trace_len: self.trace_len,
            episodes: &self.episodes,
            front_skip: self.windows.front().map_or(0, |w| w.s as usize),
        }
        .serialize(serializer)
    }
}

impl TryFrom<WindowBufferState> for WindowBuffer {
    type Error = ReplayError;
    fn try_from(st: WindowBufferState) -> Result<Self, Self::Error> {
        let mut buf = WindowBuffer::new(&st.layout, st.capacity, st.trace_len)?;
        for (k, episode) in st.episodes.into_iter().enumerate() {
            let n = buf.windows_of(&episode);
            if episode.is_empty() {
                return Err(ReplayError::EmptyEpisode);
            }
            episode.check_layout(&buf.layout)?;
            let skip = if k == 0 { st.front_skip } else { 0 };
            if skip >= n {
                return Err(ReplayError::Corrupt(format!(
                    "front_skip {skip} leaves no window of the oldest episode ({n} windows)"
                )));
            }
            let no = k as u64;
            buf.windows.extend((skip..n).map(|s| WindowRef {
                episode_no: no,
                s: s as u32,
            }));
            buf.episodes.push_back(episode);
        }
        if buf.windows.len() > buf.capacity {
            return Err(ReplayError::Corrupt(format!(
                "{} windows exceed the capacity of {}",
                buf.windows.len(),
                buf.capacity
            )));
        }
        Ok(buf)
    }
}

impl WindowBuffer {
    /// `capacity` windows (spec: `replay_buffer_size`, BP 80000) of `trace_len` records (BP 15).
    pub fn new(layout: &Layout, capacity: usize, trace_len: usize) -> Result<Self, ReplayError> {
        if capacity == 0 {
            return Err(ReplayError::Zero {
                name: "replay_buffer_size",
            });
        }
        if trace_len == 0 {
            return Err(ReplayError::Zero { name: "trace_len" });
        }
        if u32::try_from(trace_len).is_err() {
            return Err(ReplayError::Corrupt(format!(
                "trace_len {trace_len} is too large"
            )));
        }
        Ok(Self {
            layout: layout.clone(),
            capacity,
            trace_len,
            episodes: VecDeque::new(),
            first_episode_no: 0,
            windows: VecDeque::new(),
        })
    }

    /// Add the L + trace_len - 1 windows of `episode`, then evict the oldest windows beyond
    /// capacity (and the episodes left without windows). Refuses an empty episode or one of
    /// another layout.
    pub fn push(&mut self, episode: Episode) -> Result<(), ReplayError> {
        if episode.is_empty() {
            return Err(ReplayError::EmptyEpisode);
        }
        episode.check_layout(&self.layout)?;
        let n = self.windows_of(&episode);
        if u32::try_from(n).is_err() {
            return Err(ReplayError::Corrupt(format!(
                "an episode of {} records is too long",
                episode.len()
            )));
        }
        let no = self.first_episode_no + self.episodes.len() as u64;
        self.episodes.push_back(episode);
        // Only the last `capacity` windows can survive; skip pushing the others.
        let skip = n.saturating_sub(self.capacity);
        self.windows.extend((skip..n).map(|s| WindowRef {
            episode_no: no,
            s: s as u32,
        }));
        while self.windows.len() > self.capacity {
            self.windows.pop_front();
        }
        let oldest_needed = self.windows.front().map_or(no, |w| w.episode_no);
        while self.first_episode_no < oldest_needed {
            self.episodes.pop_front();
            self.first_episode_no += 1;
        }
        Ok(())
    }

    /// `batch_size` windows drawn uniformly with replacement (numpy `choice(len, batch_size)`).
    pub fn sample(
        &self,
        batch_size: usize,
        rng: &mut ChaCha8Rng,
    ) -> Result<Batch<'_>, ReplayError> {
        if self.windows.is_empty() {
            return Err(ReplayError::EmptyBuffer);
        }
        let sequences = (0..batch_size)
            .map(|_| self.window(rng.gen_range(0..self.windows.len())))
            .collect();
        Ok(Batch {
            sequences,
            padded_len: self.trace_len,
        })
    }

    /// Window `index` (0 = oldest) as a sequence of real records. Panics if out of range.
    fn window(&self, index: usize) -> Sequence<'_> {
        let w = self.windows[index];
        let episode = &self.episodes[(w.episode_no - self.first_episode_no) as usize];
        let s = w.s as usize;
        let tl = self.trace_len;
        Sequence {
            episode,
            start: (s + 1).saturating_sub(tl),
            end: (s + 1).min(episode.len()),
            lead_pad: (tl - 1).saturating_sub(s),
        }
    }

    fn windows_of(&self, episode: &Episode) -> usize {
        episode.len() + self.trace_len - 1
    }

    /// Windows held.
    pub fn len(&self) -> usize {
        self.windows.len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.windows.is_empty()
    }
    /// Episodes with at least one window held.
    pub fn n_episodes(&self) -> usize {
        self.episodes.len()
    }
    /// Capacity in windows.
    pub fn capacity(&self) -> usize {
        self.capacity
    }
    /// Window length in records.
    pub fn trace_len(&self) -> usize {
        self.trace_len
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
    use rand::SeedableRng;

    fn layout() -> Layout {
        Layout::new(&[1, 1], &[4, 4]).unwrap()
    }

    /// An episode of `len` records whose obs[0] = tag + t, so a record identifies itself.
    fn episode(len: usize, tag: f32) -> Episode {
        let mut ep = Episode::new(2, 2, len);
        for t in 0..len {
            let x = tag + t as f32;
            ep.push(RecordRef {
                obs: &[x, 0.0],
                executed: &[t % 4, 0],
                acc_id: &[0.0, 0.0],
                acc_joint: 0.0,
                next_obs: &[x + 1.0, 0.0],
                done: t + 1 == len,
                valid: &[true, t % 2 == 0],
            })
            .unwrap();
        }
        ep
    }

    fn real_records(seq: &Sequence<'_>) -> Vec<f32> {
        seq.records().map(|t| seq.episode.obs(t)[0]).collect()
    }

    #[test]
    fn episode_of_30_steps_adds_44_windows_with_one_real_record_at_each_end() {
        let mut buf = WindowBuffer::new(&layout(), 1000, 15).unwrap();
        buf.push(episode(30, 0.0)).unwrap();
        assert_eq!(buf.len(), 44);
        let first = buf.window(0);
        assert_eq!(real_records(&first), vec![0.0]);
        assert_eq!(first.lead_pad, 14);
        let last = buf.window(43);
        assert_eq!(real_records(&last), vec![29.0]);
        assert_eq!(last.lead_pad, 0);
        let full = buf.window(14);
        assert_eq!(
            real_records(&full),
            (0..15).map(|t| t as f32).collect::<Vec<_>>()
        );
        // every record sits in exactly trace_len windows
        let mut count = [0usize; 30];
        for k in 0..buf.len() {
            for t in buf.window(k).records() {
                count[t] += 1;
            }
        }
        assert!(count.iter().all(|&c| c == 15));
    }

    #[test]
    fn fifo_eviction_counts_windows_and_drops_episodes_without_windows() {
        // trace_len 3: an episode of L records adds L + 2 windows.
        let mut buf = WindowBuffer::new(&layout(), 10, 3).unwrap();
        buf.push(episode(4, 100.0)).unwrap(); // 6 windows
        buf.push(episode(2, 200.0)).unwrap(); // 4 windows -> 10, full
        assert_eq!((buf.len(), buf.n_episodes()), (10, 2));
        buf.push(episode(1, 300.0)).unwrap(); // 3 windows -> evict 3 of the first episode
        assert_eq!((buf.len(), buf.n_episodes()), (10, 3));
        // oldest window left is the first episode's 4th (s = 3): records 1..=3
        assert_eq!(real_records(&buf.window(0)), vec![101.0, 102.0, 103.0]);
        buf.push(episode(1, 400.0)).unwrap(); // 3 more: the first episode's last 3 windows go
        assert_eq!((buf.len(), buf.n_episodes()), (10, 3));
        assert_eq!(real_records(&buf.window(0)), vec![200.0]);
    }

    #[test]
    fn an_episode_longer_than_capacity_keeps_only_its_last_windows() {
        let mut buf = WindowBuffer::new(&layout(), 4, 3).unwrap();
        buf.push(episode(2, 0.0)).unwrap();
        buf.push(episode(10, 100.0)).unwrap(); // 12 windows, keep s = 8..12
        assert_eq!((buf.len(), buf.n_episodes()), (4, 1));
        assert_eq!(real_records(&buf.window(0)), vec![106.0, 107.0, 108.0]);
        assert_eq!(real_records(&buf.window(3)), vec![109.0]);
    }

    #[test]
    fn sampling_is_uniform_with_replacement_and_deterministic() {
        let mut buf = WindowBuffer::new(&layout(), 100, 3).unwrap();
        buf.push(episode(5, 0.0)).unwrap(); // 7 windows
        let draw = |seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let b = buf.sample(2000, &mut rng).unwrap();
            assert_eq!(b.padded_len, 3);
            b.sequences
                .iter()
                .map(|s| (s.start, s.end))
                .collect::<Vec<_>>()
        };
        let a = draw(7);
        assert_eq!(a, draw(7));
        assert_ne!(a, draw(8));
        // all 7 windows appear, each roughly 2000 / 7 = 286 times
        let mut counts = std::collections::BTreeMap::new();
        for w in &a {
            *counts.entry(*w).or_insert(0usize) += 1;
        }
        assert_eq!(counts.len(), 7);
        assert!(
            counts.values().all(|&c| (200..380).contains(&c)),
            "{counts:?}"
        );
    }

    #[test]
    fn serde_round_trip_keeps_windows_and_sampling() {
        let mut buf = WindowBuffer::new(&layout(), 10, 3).unwrap();
        buf.push(episode(4, 100.0)).unwrap();
        buf.push(episode(2, 200.0)).unwrap();
        buf.push(episode(1, 300.0)).unwrap();
        let json = serde_json::to_string(&buf).unwrap();
        let back: WindowBuffer = serde_json::from_str(&json).unwrap();
        assert_eq!(back.len(), buf.len());
        assert_eq!(back.n_episodes(), buf.n_episodes());
        for k in 0..buf.len() {
            assert_eq!(real_records(&back.window(k)), real_records(&buf.window(k)));
        }
        let mut r1 = ChaCha8Rng::seed_from_u64(3);
        let mut r2 = ChaCha8Rng::seed_from_u64(3);
        let s1: Vec<_> = buf
            .sample(20, &mut r1)
            .unwrap()
            .sequences
            .iter()
            .map(real_records)
            .collect();
        let s2: Vec<_> = back
            .sample(20, &mut r2)
            .unwrap()
            .sequences
            .iter()
            .map(real_records)
            .collect();
        assert_eq!(s1, s2);
        let broken = json.replace("\"front_skip\":3", "\"front_skip\":6");
        assert_ne!(broken, json);
        assert!(serde_json::from_str::<WindowBuffer>(&broken).is_err());
    }

    #[test]
    fn refuses_empty_buffers_episodes_and_zero_sizes() {
        let mut buf = WindowBuffer::new(&layout(), 10, 3).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        assert_eq!(
            buf.sample(1, &mut rng).unwrap_err(),
            ReplayError::EmptyBuffer
        );
        assert_eq!(
            buf.push(Episode::new(2, 2, 0)),
            Err(ReplayError::EmptyEpisode)
        );
        assert!(WindowBuffer::new(&layout(), 0, 3).is_err());
        assert!(WindowBuffer::new(&layout(), 10, 0).is_err());
    }
}
