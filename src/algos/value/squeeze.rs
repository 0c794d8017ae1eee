//! Squeezing (`docs/ALGORITHMS.md` §3.3): from a sampled batch of primitive-step sequences to each
//! agent's macro-level sequences (records with v_i = 1, the Mac-CERTs) and to the joint ones
//! (records with vj = 1, the Mac-JERTs), as padded inputs plus flat per-record vectors.
//!
//! A sequence without any kept record is dropped, so S <= B. Kept records keep their time order;
//! flat vectors run over the K kept records in (sequence, time) order, the order in which a net
//! unrolled over `inputs` with `lengths` emits its outputs (see [`packed_rows`]). Padding past a
//! sequence's length is zero. Zero-padding records of the reference never reach this point
//! ([`crate::algos::value::replay`]), and they would be dropped here anyway (all v_i = 0).

use ndarray::Array3;

use super::record::{Episode, Layout};
use super::replay::Batch;
use super::ReplayError;
use crate::nn::joint_index::ravel;

/// Agent i's view of a batch (Dec-HDDRQN, Our-1, Our-2): its records with v_i = 1.
#[derive(Debug, Clone, PartialEq)]
pub struct AgentView {
    /// z_i per kept record: [S, T_max, d_i].
    pub inputs: Array3<f32>,
    /// z'_i per kept record (the next-history unroll, quirk Q3): [S, T_max, d_i].
    pub next_inputs: Array3<f32>,
    /// Kept records per kept sequence: \[S\], each >= 1.
    pub lengths: Vec<usize>,
    /// m_i (executed macro-action): \[K\].
    pub actions: Vec<usize>,
    /// r^c_i (acc_id\[i\]): \[K\].
    pub rewards: Vec<f32>,
    /// done as 0.0 / 1.0: \[K\].
    pub dones: Vec<f32>,
}

/// The joint view of a batch (Cen-DDRQN, Our-1, Our-2): records with vj = 1.
#[derive(Debug, Clone, PartialEq)]
pub struct JointView {
    /// N (row k's per-agent entries sit at `k * n_agents + i`).
    pub n_agents: usize,
    /// z (joint observation) per kept record: [S, T_max, D].
    pub inputs: Array3<f32>,
    /// z' per kept record: [S, T_max, D].
    pub next_inputs: Array3<f32>,
    /// Kept records per kept sequence: \[S\], each >= 1.
    pub lengths: Vec<usize>,
    /// ravel(executed), C-order, agent 0 most significant: \[K\].
    pub joint_actions: Vec<usize>,
    /// r^c (acc_joint): \[K\].
    pub rewards: Vec<f32>,
    /// done as 0.0 / 1.0: \[K\].
    pub dones: Vec<f32>,
    /// Executed macro-actions: [K * N].
    pub executed: Vec<usize>,
    /// v_i: [K * N].
    pub valid: Vec<bool>,
    /// Conditioning for the target's conditional argmax (`docs/ALGORITHMS.md` §4.5): `-1` if v_i (agent i chooses
    /// anew) else `executed_i` (agent i keeps running it): [K * N].
    pub cond: Vec<i32>,
}

impl AgentView {
    /// S.
    pub fn n_sequences(&self) -> usize {
        self.lengths.len()
    }
    /// K.
    pub fn n_records(&self) -> usize {
        self.actions.len()
    }
    /// True when no sampled sequence has a record of this agent (`docs/ALGORITHMS.md` Q9: nothing to learn).
    pub fn is_empty(&self) -> bool {
        self.actions.is_empty()
    }
}

impl JointView {
    /// S.
    pub fn n_sequences(&self) -> usize {
        self.lengths.len()
    }
    /// K.
    pub fn n_records(&self) -> usize {
        self.joint_actions.len()
    }
    /// True when no sampled sequence has a record with vj = 1 (`docs/ALGORITHMS.md` Q9).
    pub fn is_empty(&self) -> bool {
        self.joint_actions.is_empty()
    }
}

/// (sequence, time) of each of the K flat rows, given the per-sequence lengths.
pub fn packed_rows(lengths: &[usize]) -> Vec<(usize, usize)> {
    lengths
        .iter()
        .enumerate()
        .flat_map(|(s, &len)| (0..len).map(move |t| (s, t)))
        .collect()
}

/// Agent `agent`'s squeezed view of `batch`, dropping only sequences without a kept record.
/// Refuses an out-of-range agent or episodes whose shape differs from `layout`.
pub fn squeeze_agent(
    batch: &Batch<'_>,
    layout: &Layout,
    agent: usize,
) -> Result<AgentView, ReplayError> {
    squeeze_agent_min(batch, layout, agent, 1)
}

/// [`squeeze_agent`] keeping only the sequences with at least `min_records` kept records
/// (`sub_trace_len`, `docs/ALGORITHMS.md` §3.3; values below 1 act as 1).
pub fn squeeze_agent_min(
    batch: &Batch<'_>,
    layout: &Layout,
    agent: usize,
    min_records: usize,
) -> Result<AgentView, ReplayError> {
    let n = layout.n_agents();
    if agent >= n {
        return Err(ReplayError::AgentOutOfRange { agent, n_agents: n });
    }
    check_batch(batch, layout)?;
    let range = layout.obs_range(agent);
    let d = range.len();
    let kept = Kept::count(batch, min_records, |ep, t| ep.valid_of(t, agent));

    let mut inputs = Array3::<f32>::zeros((kept.lengths.len(), kept.t_max, d));
    let mut next_inputs = Array3::<f32>::zeros((kept.lengths.len(), kept.t_max, d));
    let k = kept.total;
    let (mut actions, mut rewards, mut dones) = (
        Vec::with_capacity(k),
        Vec::with_capacity(k),
        Vec::with_capacity(k),
    );
    {
        let x = inputs.as_slice_mut().expect("fresh array is contiguous");
        let xn = next_inputs
            .as_slice_mut()
            .expect("fresh array is contiguous");
        for (s, seq) in kept.sequences(batch) {
            let ep = seq.episode;
            let mut at = s * kept.t_max * d;
            for t in seq.records() {
                if !ep.valid_of(t, agent) {
                    continue;
                }
                x[at..at + d].copy_from_slice(&ep.obs(t)[range.clone()]);
                xn[at..at + d].copy_from_slice(&ep.next_obs(t)[range.clone()]);
                at += d;
                actions.push(ep.executed(t)[agent]);
                rewards.push(ep.acc_id(t)[agent]);
                dones.push(f32::from(u8::from(ep.done(t))));
            }
        }
    }
    Ok(AgentView {
        inputs,
        next_inputs,
        lengths: kept.lengths,
        actions,
        rewards,
        dones,
    })
}

/// The joint squeezed view of `batch`. Refuses episodes whose shape differs from `layout` or
/// whose executed actions are out of range.
pub fn squeeze_joint(batch: &Batch<'_>, layout: &Layout) -> Result<JointView, ReplayError> {
    check_batch(batch, layout)?;
    let n = layout.n_agents();
    let n_actions = layout.n_actions();
    let d = layout.joint_obs_size();
    let kept = Kept::count(batch, 1, Episode::vj);

    let mut inputs = Array3::<f32>::zeros((kept.lengths.len(), kept.t_max, d));
    let mut next_inputs = Array3::<f32>::zeros((kept.lengths.len(), kept.t_max, d));
    let k = kept.total;
    let mut view = JointView {
        n_agents: n,
        inputs: Array3::zeros((0, 0, 0)),
        next_inputs: Array3::zeros((0, 0, 0)),
        lengths: Vec::new(),
        joint_actions: Vec::with_capacity(k),
        rewards: Vec::with_capacity(k),
        dones: Vec::with_capacity(k),
        executed: Vec::with_capacity(k * n),
        valid: Vec::with_capacity(k * n),
        cond: Vec::with_capacity(k * n),
    };
    {
        let x = inputs.as_slice_mut().expect("fresh array is contiguous");
        let xn = next_inputs
            .as_slice_mut()
            .expect("fresh array is contiguous");
        for (s, seq) in kept.sequences(batch) {
            let ep = seq.episode;
            let mut at = s * kept.t_max * d;
            for t in seq.records() {
                if !ep.vj(t) {
                    continue;
                }
                x[at..at + d].copy_from_slice(ep.obs(t));
                xn[at..at + d].copy_from_slice(ep.next_obs(t));
                at += d;
                let executed = ep.executed(t);
                let valid = ep.valid(t);
                for (agent, (&a, &n_a)) in executed.iter().zip(n_actions).enumerate() {
                    if a >= n_a {
                        return Err(ReplayError::ActionOutOfRange {
                            agent,
                            action: a,
                            n_actions: n_a,
                        });
                    }
                }
                view.joint_actions.push(ravel(executed, n_actions));
                view.rewards.push(ep.acc_joint(t));
                view.dones.push(f32::from(u8::from(ep.done(t))));
                view.executed.extend_from_slice(executed);
                view.valid.extend_from_slice(valid);
                view.cond.extend(
                    executed
                        .iter()
                        .zip(valid)
                        .map(|(&a, &v)| if v { -1 } else { a as i32 }),
                );
            }
        }
    }
    view.inputs = inputs;
    view.next_inputs = next_inputs;
    view.lengths = kept.lengths;
    Ok(view)
}

/// The joint-view rows k with v_i = 1, in order. They pair one-to-one, in order, with agent i's
/// squeezed records of the same batch (`docs/ALGORITHMS.md` §5.3 Step C): a record with v_i = 1 has vj = 1, and
/// both views walk the sequences and records in the same order. Panics if `agent >= n_agents`.
pub fn joint_rows_of_agent(joint: &JointView, agent: usize) -> Vec<usize> {
    assert!(agent < joint.n_agents, "agent {agent} out of range");
    joint
        .valid
        .chunks(joint.n_agents)
        .enumerate()
        .filter(|(_, v)| v[agent])
        .map(|(k, _)| k)
        .collect()
}

fn check_batch(batch: &Batch<'_>, layout: &Layout) -> Result<(), ReplayError> {
    for seq in &batch.sequences {
        let ep = seq.episode;
        if ep.n_agents() != layout.n_agents() || ep.joint_obs_size() != layout.joint_obs_size() {
            return Err(ReplayError::LayoutMismatch {
                n_agents: ep.n_agents(),
                joint_obs: ep.joint_obs_size(),
                expected_agents: layout.n_agents(),
                expected_obs: layout.joint_obs_size(),
            });
        }
        if seq.start > seq.end || seq.end > ep.len() {
            return Err(ReplayError::Corrupt(format!(
                "sequence {}..{} outside an episode of {} records",
                seq.start,
                seq.end,
                ep.len()
            )));
        }
    }
    Ok(())
}

/// First pass of a squeeze: how many records each sampled sequence keeps.
struct Kept {
    /// Per sampled sequence (B entries), 0 if dropped.
    per_sequence: Vec<usize>,
    /// Per kept sequence (S entries).
    lengths: Vec<usize>,
    t_max: usize,
    total: usize,
}

impl Kept {
    /// Sequences with fewer than `min_records` kept records (at least 1) count as dropped.
    fn count(
        batch: &Batch<'_>,
        min_records: usize,
        keep: impl Fn(&Episode, usize) -> bool,
    ) -> Self {
        let min_records = min_records.max(1);
        let per_sequence: Vec<usize> = batch
            .sequences
            .iter()
            .map(|seq| seq.records().filter(|&t| keep(seq.episode, t)).count())
            .map(|c| if c >= min_records { c } else { 0 })
            .collect();
        let lengths: Vec<usize> = per_sequence.iter().copied().filter(|&c| c > 0).collect();
        Self {
            t_max: lengths.iter().copied().max().unwrap_or(0),
            total: lengths.iter().sum(),
            per_sequence,
            lengths,
        }
    }

    /// The kept sequences with their index s among the kept ones.
    fn sequences<'b, 'a>(
        &'b self,
        batch: &'b Batch<'a>,
    ) -> impl Iterator<Item = (usize, &'b super::replay::Sequence<'a>)> + 'b {
        batch
            .sequences
            .iter()
            .zip(&self.per_sequence)
            .filter(|(_, &c)| c > 0)
            .map(|(seq, _)| seq)
            .enumerate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::value::record::RecordRef;
    use crate::algos::value::replay::Sequence;
    use ndarray::s;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Agent 0 sees 2 floats, agent 1 one float; agent 0 has 3 actions, agent 1 two.
    fn layout() -> Layout {
        Layout::new(&[2, 1], &[3, 2]).unwrap()
    }

    /// obs(t) = [100 tag + 10 t, .. + 1, .. + 2]; next_obs(t) = obs(t + 1).
    fn obs(tag: usize, t: usize) -> [f32; 3] {
        let b = (100 * tag + 10 * t) as f32;
        [b, b + 1.0, b + 2.0]
    }

    /// (valid, executed, acc_id, acc_joint) per step; done on the last.
    type Step = ([bool; 2], [usize; 2], [f32; 2], f32);

    fn episode(tag: usize, steps: &[Step]) -> Episode {
        let mut ep = Episode::new(2, 3, steps.len());
        for (t, &(valid, executed, acc_id, acc_joint)) in steps.iter().enumerate() {
            ep.push(RecordRef {
                obs: &obs(tag, t),
                executed: &executed,
                acc_id: &acc_id,
                acc_joint,
                next_obs: &obs(tag, t + 1),
                done: t + 1 == steps.len(),
                valid: &valid,
            })
            .unwrap();
        }
        ep
    }

    fn whole(ep: &Episode) -> Sequence<'_> {
        Sequence {
            episode: ep,
            start: 0,
            end: ep.len(),
            lead_pad: 0,
        }
    }

    /// Episode A (tag 1): agent 0 finishes at t = 1 and 3, agent 1 at t = 3 and 4 (the end).
    /// Episode B (tag 2): nobody finishes. Episode C (tag 3): agent 1 at t = 0, agent 0 at t = 1.
    fn hand_batch_episodes() -> (Episode, Episode, Episode) {
        let a = episode(
            1,
            &[
                ([false, false], [1, 0], [-1.0, -1.0], -1.0),
                ([true, false], [1, 0], [-2.0, -2.0], -2.0),
                ([false, false], [2, 0], [-1.0, -3.0], -1.0),
                ([true, true], [2, 0], [-2.0, -4.0], -2.0),
                ([false, true], [0, 1], [10.0, 10.0], 10.0),
            ],
        );
        let b = episode(
            2,
            &[
                ([false, false], [0, 0], [-1.0, -1.0], -1.0),
                ([false, false], [0, 0], [-2.0, -2.0], -2.0),
            ],
        );
        let c = episode(
            3,
            &[
                ([false, true], [2, 1], [-1.0, -1.0], -1.0),
                ([true, false], [2, 0], [-2.0, -1.0], -1.0),
            ],
        );
        (a, b, c)
    }

    #[test]
    fn agent_views_keep_the_steps_where_the_agent_finished() {
        let (a, b, c) = hand_batch_episodes();
        // a window of A covering t = 2..5, placed last
        let window = Sequence {
            episode: &a,
            start: 2,
            end: 5,
            lead_pad: 0,
        };
        let batch = Batch {
            sequences: vec![whole(&a), whole(&b), whole(&c), window],
            padded_len: 5,
        };
        let v0 = squeeze_agent(&batch, &layout(), 0).unwrap();
        assert_eq!(v0.lengths, vec![2, 1, 1]); // A: t 1, 3; B dropped; C: t 1; window: t 3
        assert_eq!(v0.inputs.dim(), (3, 2, 2));
        assert_eq!(
            v0.inputs.slice(s![0, .., ..]),
            ndarray::arr2(&[[110.0, 111.0], [130.0, 131.0]])
        );
        assert_eq!(
            v0.inputs.slice(s![1, .., ..]),
            ndarray::arr2(&[[310.0, 311.0], [0.0, 0.0]])
        );
        assert_eq!(
            v0.next_inputs.slice(s![2, 0, ..]).to_vec(),
            vec![140.0, 141.0]
        );
        assert_eq!(v0.actions, vec![1, 2, 2, 2]);
        assert_eq!(v0.rewards, vec![-2.0, -2.0, -2.0, -2.0]);
        assert_eq!(v0.dones, vec![0.0, 0.0, 1.0, 0.0]); // C ends at its t = 1
                                                        // sub_trace_len: 1 is the plain view; 2 keeps only A's two-record sequence; 3 none.
        let same = squeeze_agent_min(&batch, &layout(), 0, 1).unwrap();
        assert_eq!(
            (same.lengths, same.actions),
            (v0.lengths.clone(), v0.actions.clone())
        );
        let two = squeeze_agent_min(&batch, &layout(), 0, 2).unwrap();
        assert_eq!(two.lengths, vec![2]);
        assert_eq!(two.actions, vec![1, 2]);
        assert_eq!(
            two.inputs.slice(s![0, .., ..]),
            ndarray::arr2(&[[110.0, 111.0], [130.0, 131.0]])
        );
        assert!(squeeze_agent_min(&batch, &layout(), 0, 3)
            .unwrap()
            .is_empty());

        let v1 = squeeze_agent(&batch, &layout(), 1).unwrap();
        assert_eq!(v1.lengths, vec![2, 1, 2]); // A: t 3, 4; C: t 0; window: t 3, 4
        assert_eq!(v1.inputs.dim(), (3, 2, 1));
        assert_eq!(
            v1.inputs.iter().copied().collect::<Vec<_>>(),
            vec![132.0, 142.0, 302.0, 0.0, 132.0, 142.0]
        );
        assert_eq!(v1.next_inputs.slice(s![0, 1, ..]).to_vec(), vec![152.0]);
        assert_eq!(v1.actions, vec![0, 1, 1, 0, 1]);
        assert_eq!(v1.rewards, vec![-4.0, 10.0, -1.0, -4.0, 10.0]);
        assert_eq!(v1.dones, vec![0.0, 1.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn joint_view_keeps_steps_where_anyone_finished_with_conditioning() {
        let (a, b, c) = hand_batch_episodes();
        let batch = Batch {
            sequences: vec![whole(&b), whole(&a), whole(&c)],
            padded_len: 5,
        };
        let j = squeeze_joint(&batch, &layout()).unwrap();
        assert_eq!(j.lengths, vec![3, 2]); // A: t 1, 3, 4; C: t 0, 1
        assert_eq!(j.inputs.dim(), (2, 3, 3));
        assert_eq!(
            j.inputs.slice(s![0, 2, ..]).to_vec(),
            vec![140.0, 141.0, 142.0]
        );
        assert_eq!(
            j.next_inputs.slice(s![1, 1, ..]).to_vec(),
            vec![320.0, 321.0, 322.0]
        );
        assert_eq!(j.inputs.slice(s![1, 2, ..]).to_vec(), vec![0.0, 0.0, 0.0]); // padding
                                                                                // ravel with n = [3, 2]: [1,0] -> 2, [2,0] -> 4, [0,1] -> 1, [2,1] -> 5
        assert_eq!(j.joint_actions, vec![2, 4, 1, 5, 4]);
        assert_eq!(j.rewards, vec![-2.0, -2.0, 10.0, -1.0, -1.0]);
        assert_eq!(j.dones, vec![0.0, 0.0, 1.0, 0.0, 1.0]);
        assert_eq!(j.executed, vec![1, 0, 2, 0, 0, 1, 2, 1, 2, 0]);
        let f = false;
        let t = true;
        assert_eq!(j.valid, vec![t, f, t, t, f, t, f, t, t, f]);
        assert_eq!(j.cond, vec![-1, 0, -1, -1, 0, -1, 2, -1, -1, 0]);
        assert_eq!(joint_rows_of_agent(&j, 0), vec![0, 1, 4]);
        assert_eq!(joint_rows_of_agent(&j, 1), vec![1, 2, 3]);
    }

    #[test]
    fn a_batch_without_finishes_squeezes_to_nothing() {
        let (_, b, _) = hand_batch_episodes();
        let batch = Batch {
            sequences: vec![whole(&b)],
            padded_len: 2,
        };
        let v = squeeze_agent(&batch, &layout(), 0).unwrap();
        assert!(v.is_empty());
        assert_eq!(v.inputs.dim(), (0, 0, 2));
        assert!(squeeze_joint(&batch, &layout()).unwrap().is_empty());
        assert!(squeeze_agent(&batch, &layout(), 2).is_err());
    }

    /// Random episodes and windows: agent i's records align one-to-one with the joint rows where
    /// v_i = 1 (same observations, actions, dones), as Our-1 Step C assumes.
    #[test]
    fn joint_rows_of_agent_align_with_the_agent_view_on_random_data() {
        let layout = Layout::new(&[2, 1, 3], &[3, 2, 4]).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let episodes: Vec<Episode> = (0..6)
            .map(|tag| {
                let len = rng.gen_range(1..25);
                let mut ep = Episode::new(3, 6, len);
                for t in 0..len {
                    let o: Vec<f32> = (0..6).map(|c| (1000 * tag + 10 * t + c) as f32).collect();
                    let on: Vec<f32> = o.iter().map(|x| x + 0.5).collect();
                    let valid = [rng.gen_bool(0.3), rng.gen_bool(0.3), rng.gen_bool(0.2)];
                    ep.push(RecordRef {
                        obs: &o,
                        executed: &[
                            rng.gen_range(0..3),
                            rng.gen_range(0..2),
                            rng.gen_range(0..4),
                        ],
                        acc_id: &[rng.gen(), rng.gen(), rng.gen()],
                        acc_joint: rng.gen(),
                        next_obs: &on,
                        done: t + 1 == len,
                        valid: &valid,
                    })
                    .unwrap();
                }
                ep
            })
            .collect();
        let sequences: Vec<Sequence<'_>> = (0..40)
            .map(|_| {
                let ep = &episodes[rng.gen_range(0..episodes.len())];
                let start = rng.gen_range(0..ep.len());
                let end = rng.gen_range(start + 1..=ep.len());
                Sequence {
                    episode: ep,
                    start,
                    end,
                    lead_pad: 0,
                }
            })
            .collect();
        let batch = Batch {
            sequences,
            padded_len: 25,
        };
        let joint = squeeze_joint(&batch, &layout).unwrap();
        let joint_pos = packed_rows(&joint.lengths);
        assert_eq!(joint_pos.len(), joint.n_records());
        for agent in 0..3 {
            let view = squeeze_agent(&batch, &layout, agent).unwrap();
            let rows = joint_rows_of_agent(&joint, agent);
            assert_eq!(rows.len(), view.n_records());
            assert!(view.n_records() > 0);
            let range = layout.obs_range(agent);
            for (j, ((s, t), &k)) in packed_rows(&view.lengths)
                .into_iter()
                .zip(&rows)
                .enumerate()
            {
                let (js, jt) = joint_pos[k];
                assert_eq!(
                    view.inputs.slice(s![s, t, ..]).to_vec(),
                    joint.inputs.slice(s![js, jt, range.clone()]).to_vec()
                );
                assert_eq!(
                    view.next_inputs.slice(s![s, t, ..]).to_vec(),
                    joint.next_inputs.slice(s![js, jt, range.clone()]).to_vec()
                );
                assert_eq!(view.actions[j], joint.executed[k * 3 + agent]);
                assert_eq!(view.dones[j], joint.dones[k]);
                assert_eq!(joint.cond[k * 3 + agent], -1);
            }
        }
    }

    /// Squeeze timing on batches shaped like the paper's (BP: 128 windows x 15; WTD: 16 episodes
    /// x 150). `cargo test --release squeeze_speed -- --ignored --nocapture`
    #[test]
    #[ignore]
    fn squeeze_speed() {
        use crate::algos::value::replay::ReplayBuffer;
        use std::time::Instant;
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let mut run = |name: &str,
                       obs: &[usize],
                       acts: &[usize],
                       buffer: ReplayBuffer,
                       batch: usize| {
            let layout = Layout::new(obs, acts).unwrap();
            let mut buffer = buffer;
            let n = obs.len();
            let d = layout.joint_obs_size();
            for _ in 0..200 {
                let len = rng.gen_range(30..=150);
                let mut ep = Episode::new(n, d, len);
                for t in 0..len {
                    let o: Vec<f32> = (0..d).map(|_| rng.gen_range(0..2) as f32).collect();
                    let valid: Vec<bool> = (0..n).map(|_| rng.gen_bool(0.25)).collect();
                    let ex: Vec<usize> = acts.iter().map(|&a| rng.gen_range(0..a)).collect();
                    let acc = vec![-1.0; n];
                    ep.push(RecordRef {
                        obs: &o,
                        executed: &ex,
                        acc_id: &acc,
                        acc_joint: -1.0,
                        next_obs: &o,
                        done: t + 1 == len,
                        valid: &valid,
                    })
                    .unwrap();
                }
                buffer.push(ep).unwrap();
            }
            let iters = 2000;
            let start = Instant::now();
            let mut sink = 0usize;
            for _ in 0..iters {
                let b = buffer.sample(batch, &mut rng).unwrap();
                let j = squeeze_joint(&b, &layout).unwrap();
                sink += j.n_records();
                for i in 0..n {
                    sink += squeeze_agent(&b, &layout, i).unwrap().n_records();
                    sink += joint_rows_of_agent(&j, i).len();
                }
            }
            let us = start.elapsed().as_secs_f64() * 1e6 / iters as f64;
            println!("{name}: sample + joint + {n} agent squeezes: {us:.1} us per batch ({sink})");
            let b = buffer.sample(batch, &mut rng).unwrap();
            let start = Instant::now();
            for _ in 0..iters {
                sink += buffer.sample(batch, &mut rng).unwrap().sequences.len();
            }
            let sample_us = start.elapsed().as_secs_f64() * 1e6 / iters as f64;
            let start = Instant::now();
            for _ in 0..iters {
                sink += squeeze_joint(&b, &layout).unwrap().n_records();
            }
            let joint_us = start.elapsed().as_secs_f64() * 1e6 / iters as f64;
            let start = Instant::now();
            for _ in 0..iters {
                sink += squeeze_agent(&b, &layout, 0).unwrap().n_records();
            }
            let agent_us = start.elapsed().as_secs_f64() * 1e6 / iters as f64;
            println!("  sample {sample_us:.1} us, joint {joint_us:.1} us, agent 0 {agent_us:.1} us ({sink})");
        };
        let bp = Layout::new(&[5, 5], &[8, 8]).unwrap();
        run(
            "BP 128 x 15",
            &[5, 5],
            &[8, 8],
            ReplayBuffer::windows(&bp, 80000, 15).unwrap(),
            128,
        );
        let wtd = Layout::new(&[13, 13, 4], &[3, 3, 6]).unwrap();
        run(
            "WTD 16 x ~150",
            &[13, 13, 4],
            &[3, 3, 6],
            ReplayBuffer::episodes(&wtd, 1000).unwrap(),
            16,
        );
    }
}
