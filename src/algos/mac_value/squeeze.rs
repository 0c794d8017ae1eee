//! Squeezing a batch (`docs/MACROMARL.md` §8.2, step 1): each sampled sequence cut down to the
//! records where the net's macro-action ended (agent i's for MacDec-Q, any agent's for MacCen-Q),
//! copied out of the memory's scattered records into flat arrays the unrolls read, sequences with
//! fewer than `sub_trace_len` records dropped. With whole stored episodes, each episode's squeeze
//! is kept from one update to the next ([`KeptSqueezes`]).

use std::collections::HashMap;

use super::choice::{conditional_argmax, Dims};
use super::episode::Step;
use super::prefetch::prefetch_batch;
use crate::nn::joint_index::ravel;

/// What a squeeze or a target's rows may be kept under between updates: the net's slot (0 for
/// the centralized net, 1 + i for agent i's) and each batch entry's stored-episode id (given for
/// whole-episode memories only: a window is cut afresh every time).
#[derive(Debug, Clone, Copy)]
pub(super) struct EpisodeKeys<'a> {
    pub(super) slot: usize,
    pub(super) ids: &'a [u64],
}

/// One net's squeezed batch: sequences of kept records, flat (sequence-major).
#[derive(Debug, Clone, Default)]
pub(super) struct Squeezed {
    pub(super) lengths: Vec<usize>,
    /// Each sequence's position in the batch (a batch entry gives one sequence or none).
    pub(super) entries: Vec<usize>,
    pub(super) width: usize,
    /// [sum lengths, width]: the observations the macro-actions were chosen on.
    pub(super) x: Vec<f32>,
    /// [sum (lengths + 1), width]: each sequence's first observation, then every next one.
    pub(super) x_next: Vec<f32>,
    pub(super) actions: Vec<usize>,
    pub(super) rewards: Vec<f32>,
    pub(super) gammas: Vec<f32>,
    pub(super) terminals: Vec<f32>,
    /// [sum lengths, avail_width]: the availability after each kept record (the net's own
    /// masks). Copied out while the squeeze has the records in cache: choosing a' comes after the
    /// unrolls, whose buffers evict the scattered records, and reading them again there cost more
    /// than the choice itself.
    pub(super) next_avail: Vec<f32>,
    pub(super) avail_width: usize,
    /// [sum lengths, n_agents] for the joint squeeze (empty otherwise): each agent's running
    /// macro-action at each kept record, `None` where it ended (read by the conditional argmax).
    pub(super) running: Vec<Option<usize>>,
}

impl Squeezed {
    /// Keep the records `keep` accepts, reading each with `obs`/`next_obs` (the net's input
    /// slice), `fields` (action, reward, gamma) and `avail` (the net's slice of `next_avail`);
    /// sequences shorter than `sub_trace_len` go. Also gives the kept records, in the same (flat)
    /// order.
    fn of<'a>(
        batch: &[&'a [Step]],
        sub_trace_len: usize,
        width: usize,
        keep: impl Fn(&Step) -> bool,
        input: impl Fn(&'a [f32]) -> &'a [f32],
        fields: impl Fn(&Step) -> (usize, f32, f32),
        avail: impl Fn(&'a Step) -> &'a [f32],
    ) -> (Squeezed, Vec<&'a Step>) {
        let mut s = Squeezed {
            width,
            ..Squeezed::default()
        };
        // At most every record is kept: room for all of them up front.
        let most: usize = batch.iter().map(|seq| seq.len()).sum();
        let mut records: Vec<&'a Step> = Vec::with_capacity(most);
        s.x.reserve(most * width);
        s.x_next.reserve((most + batch.len()) * width);
        for v in [&mut s.rewards, &mut s.gammas, &mut s.terminals] {
            v.reserve(most);
        }
        s.actions.reserve(most);
        // Every record of a net has a mask of the same width.
        if let Some(r) = batch.iter().find_map(|seq| seq.first()) {
            s.avail_width = avail(r).len();
            s.next_avail.reserve(most * s.avail_width);
        }
        for (entry, seq) in batch.iter().enumerate() {
            let first = records.len();
            records.extend(seq.iter().filter(|r| keep(r)));
            let n = records.len() - first;
            if n == 0 || n < sub_trace_len {
                records.truncate(first);
                continue;
            }
            s.lengths.push(n);
            s.entries.push(entry);
            s.x_next.extend_from_slice(input(&records[first].obs));
            for r in &records[first..] {
                s.x.extend_from_slice(input(&r.obs));
                s.x_next.extend_from_slice(input(&r.next_obs));
                let (a, rew, g) = fields(r);
                s.actions.push(a);
                s.rewards.push(rew);
                s.gammas.push(g);
                s.terminals.push(if r.terminal { 1.0 } else { 0.0 });
                let mask = avail(r);
                debug_assert_eq!(mask.len(), s.avail_width);
                s.next_avail.extend_from_slice(mask);
            }
        }
        (s, records)
    }

    /// The joint squeeze (the centralized net's): records where any agent's macro-action ended,
    /// the joint observation, joint macro-action, reward and gamma.
    pub(super) fn joint<'a>(
        batch: &[&'a [Step]],
        sub_trace_len: usize,
        dims: &Dims,
    ) -> (Squeezed, Vec<&'a Step>) {
        let (mut s, records) = Squeezed::of(
            batch,
            sub_trace_len,
            dims.obs_sizes.iter().sum(),
            Step::any_valid,
            |o| o,
            |r| {
                (
                    ravel(&r.actions, &dims.n_actions),
                    r.joint_reward,
                    r.joint_gamma,
                )
            },
            |r| &r.next_avail,
        );
        s.running.reserve(records.len() * dims.n_actions.len());
        for r in &records {
            push_running_actions(r, &mut s.running);
        }
        (s, records)
    }

    /// Record k's availability after it (the net's masks).
    pub(super) fn next_avail(&self, k: usize) -> &[f32] {
        &self.next_avail[k * self.avail_width..(k + 1) * self.avail_width]
    }

    /// Record k's running macro-actions (joint squeezes only), `n_agents` of them.
    fn running(&self, k: usize, n_agents: usize) -> &[Option<usize>] {
        &self.running[k * n_agents..(k + 1) * n_agents]
    }

    /// The joint conditional argmax of record k's next values `row` (`get_conditional_action`:
    /// agents whose macro-action did not end keep it).
    pub(super) fn conditional_argmax(&self, k: usize, row: &[f32], dims: &Dims) -> usize {
        let running = self.running(k, dims.n_actions.len());
        conditional_argmax(row, running, self.next_avail(k), dims)
    }

    /// Whether every sequence's continuation starts with its observations, bit for bit
    /// ([o_0, o'_0, ..., o'_{L-2}] = [o_0, o_1, ..., o_{L-1}]: a record's next observation is the
    /// following record's, as when observations are held between an agent's decisions). Then the
    /// online net's next values are its training unroll's outputs one position on, and one step
    /// past each sequence's end.
    pub(super) fn continues(&self) -> bool {
        let w = self.width;
        let mut at = 0;
        for (seq, &l) in self.lengths.iter().enumerate() {
            // The continuation of sequence `seq` starts at row at + seq of x_next.
            let observed = &self.x[at * w..(at + l) * w];
            let continued = &self.x_next[(at + seq) * w..(at + seq + l) * w];
            if observed
                .iter()
                .zip(continued)
                .any(|(a, b)| a.to_bits() != b.to_bits())
            {
                return false;
            }
            at += l;
        }
        true
    }

    pub(super) fn total(&self) -> usize {
        self.actions.len()
    }

    /// The squeeze of a batch whose entries squeezed alone gave `parts` (in batch order), onto
    /// `empty`, the batch-less squeeze (which carries the input width): each part's sequence, if
    /// it kept one, becomes the sequence of its entry, and the availability width is the first
    /// part's that saw a record, as [`Squeezed::of`] takes it from the batch's first record.
    fn concat(empty: Squeezed, parts: &[&Squeezed]) -> Squeezed {
        let mut s = empty;
        let sum = |f: fn(&Squeezed) -> usize| parts.iter().map(|p| f(p)).sum::<usize>();
        s.lengths.reserve(parts.len());
        s.entries.reserve(parts.len());
        s.x.reserve(sum(|p| p.x.len()));
        s.x_next.reserve(sum(|p| p.x_next.len()));
        s.actions.reserve(sum(|p| p.actions.len()));
        for v in [&mut s.rewards, &mut s.gammas, &mut s.terminals] {
            v.reserve(sum(|p| p.rewards.len()));
        }
        s.next_avail.reserve(sum(|p| p.next_avail.len()));
        s.running.reserve(sum(|p| p.running.len()));
        for (entry, p) in parts.iter().enumerate() {
            debug_assert!(p.lengths.len() <= 1 && p.width == s.width);
            if s.avail_width == 0 {
                s.avail_width = p.avail_width;
            }
            s.lengths.extend_from_slice(&p.lengths);
            s.entries.extend(p.entries.iter().map(|_| entry));
            s.x.extend_from_slice(&p.x);
            s.x_next.extend_from_slice(&p.x_next);
            s.actions.extend_from_slice(&p.actions);
            s.rewards.extend_from_slice(&p.rewards);
            s.gammas.extend_from_slice(&p.gammas);
            s.terminals.extend_from_slice(&p.terminals);
            s.next_avail.extend_from_slice(&p.next_avail);
            s.running.extend_from_slice(&p.running);
        }
        s
    }

    /// Gives back the room [`Squeezed::of`] reserved for records it did not keep.
    fn shrink_to_fit(&mut self) {
        self.lengths.shrink_to_fit();
        self.entries.shrink_to_fit();
        self.x.shrink_to_fit();
        self.x_next.shrink_to_fit();
        self.actions.shrink_to_fit();
        self.rewards.shrink_to_fit();
        self.gammas.shrink_to_fit();
        self.terminals.shrink_to_fit();
        self.next_avail.shrink_to_fit();
        self.running.shrink_to_fit();
    }
}

/// Appends to `running` each agent's macro-action in `r` where it did not end there (it keeps
/// running), `None` where it ended.
fn push_running_actions(r: &Step, running: &mut Vec<Option<usize>>) {
    running.extend(
        r.valid
            .iter()
            .zip(&r.actions)
            .map(|(&v, &a)| (!v).then_some(a)),
    );
}

/// Agent i's squeeze (MacDec-Q's): the records where its macro-action ended, its observation,
/// macro-action, reward, gamma and availability masks.
pub(super) fn agent_squeeze(
    batch: &[&[Step]],
    sub_trace_len: usize,
    dims: &Dims,
    i: usize,
) -> Squeezed {
    let (obs, masks) = (dims.obs_range(i), dims.action_range(i));
    Squeezed::of(
        batch,
        sub_trace_len,
        obs.len(),
        |r| r.valid[i],
        |o| &o[obs.clone()],
        |r| (r.actions[i], r.rewards[i], r.gammas[i]),
        |r| &r.next_avail[masks.clone()],
    )
    .0
}

/// Each stored episode's squeeze for each net, from one update to the next: a whole-episode
/// memory hands out the same episodes again and again (the published Warehouse and Overcooked rows
/// sample 64 of 500-2 000 stored episodes every 128 steps or so, about a hundred draws each over
/// an episode's stay), and squeezing them afresh, reading every record's scattered vectors, took
/// 12% of a Warehouse A MacDec-Q run. A squeeze is a function of the episode alone, so a kept one
/// holds the bits a new one gives; the learner drops an episode's when it leaves the memory, and
/// a resumed run starts with none.
#[derive(Debug, Default)]
pub(super) struct KeptSqueezes {
    /// (net slot, episode id) -> the episode's squeeze alone (one sequence or none).
    parts: HashMap<(usize, u64), Squeezed>,
}

impl KeptSqueezes {
    /// What `squeeze` gives for `batch`: with `keys`, assembled from each entry's kept squeeze
    /// (squeezed alone and kept on first sight), otherwise squeezed as a whole. Panics if `keys`
    /// does not give one id per entry.
    pub(super) fn squeeze(
        &mut self,
        batch: &[&[Step]],
        keys: Option<EpisodeKeys>,
        squeeze: impl Fn(&[&[Step]]) -> Squeezed,
    ) -> Squeezed {
        let Some(keys) = keys else {
            return squeeze(batch);
        };
        assert_eq!(
            keys.ids.len(),
            batch.len(),
            "one episode id per batch entry"
        );
        let missing: Vec<&[Step]> = batch
            .iter()
            .zip(keys.ids)
            .filter(|&(_, &id)| !self.parts.contains_key(&(keys.slot, id)))
            .map(|(&seq, _)| seq)
            .collect();
        prefetch_batch(&missing);
        for (&seq, &id) in batch.iter().zip(keys.ids) {
            self.parts.entry((keys.slot, id)).or_insert_with(|| {
                let mut part = squeeze(&[seq]);
                part.shrink_to_fit();
                part
            });
        }
        let parts: Vec<&Squeezed> = keys
            .ids
            .iter()
            .map(|&id| &self.parts[&(keys.slot, id)])
            .collect();
        Squeezed::concat(squeeze(&[]), &parts)
    }

    /// Episodes before id `oldest` left the memory: drop their squeezes.
    pub(super) fn forget_episodes_before(&mut self, oldest: u64) {
        self.parts.retain(|&(_, id), _| id >= oldest);
    }

    /// Squeezes held (for tests).
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.parts.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// An episode of `len` records of two agents (observation widths 2 and 1, 2 and 3
    /// macro-actions), each agent finishing its macro-action at random steps, every number its own.
    fn episode(len: usize, rng: &mut impl Rng) -> Vec<Step> {
        let mut f = || rng.gen_range(-1.0f32..1.0);
        let mut steps: Vec<Step> = (0..len)
            .map(|t| Step {
                obs: vec![f(), f(), f()],
                actions: vec![t % 2, t % 3],
                rewards: vec![f(), f()],
                gammas: vec![f(), f()],
                joint_reward: f(),
                joint_gamma: f(),
                next_obs: vec![f(), f(), f()],
                next_avail: vec![f(), 1.0, 0.0, f(), 1.0],
                terminal: t + 1 == len,
                valid: vec![],
            })
            .collect();
        for s in &mut steps {
            s.valid = vec![rng.gen_bool(0.4), rng.gen_bool(0.7)];
        }
        steps
    }

    /// Every field, floats by their exact (round-trip) text, -0 apart from +0.
    fn fields(s: &Squeezed) -> String {
        format!("{s:?}")
    }

    #[test]
    fn kept_squeezes_assemble_the_batch_squeeze_bit_for_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        // Lengths 0..7: empty episodes, and episodes some squeezes drop at sub_trace_len 3.
        let episodes: Vec<Vec<Step>> = (0..8).map(|e| episode(e, &mut rng)).collect();
        let dims = Dims {
            obs_sizes: vec![2, 1],
            n_actions: vec![2, 3],
        };
        for sub_trace_len in [1, 3] {
            let mut kept = KeptSqueezes::default();
            for update in 0..20 {
                let n = rng.gen_range(0..6);
                let ids: Vec<u64> = (0..n).map(|_| rng.gen_range(0..8)).collect();
                let batch: Vec<&[Step]> = ids.iter().map(|&e| &episodes[e as usize][..]).collect();
                for slot in 0..3 {
                    let squeeze = |b: &[&[Step]]| match slot {
                        0 => Squeezed::joint(b, sub_trace_len, &dims).0,
                        i => agent_squeeze(b, sub_trace_len, &dims, i - 1),
                    };
                    let keys = EpisodeKeys { slot, ids: &ids };
                    let assembled = kept.squeeze(&batch, Some(keys), squeeze);
                    let whole = kept.squeeze(&batch, None, squeeze);
                    assert_eq!(
                        fields(&assembled),
                        fields(&whole),
                        "sub_trace_len {sub_trace_len} update {update} slot {slot}"
                    );
                }
            }
            assert!(kept.len() > 8, "squeezes are kept per slot and episode");
            kept.forget_episodes_before(5);
            assert!(kept.parts.keys().all(|&(_, id)| id >= 5));
        }
    }
}
