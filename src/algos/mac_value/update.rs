//! One training iteration of MacDec-Q (`learning_methods.py: QLearn_squ`) and MacCen-Q
//! (`learning_methods_cen_condi.py: QLearn_squ_cen_condi_0`), `docs/MACROMARL.md` §8.2:
//!
//! 1. squeeze each sampled sequence to the records where the net's macro-action ended (agent i's
//!    for MacDec-Q, any agent's for MacCen-Q), dropping sequences with fewer than
//!    `sub_trace_len`;
//! 2. Q(h, a) from one unroll over the squeezed observations; the next-history values from the
//!    continuation [o_0, o'_0, o'_1, ...] of the same unroll, its outputs from position 1 on
//!    (for the online net, when the continuation repeats the observations bit for bit, those
//!    outputs are the first unroll's from position 1 plus one step past each end, which is how
//!    they are computed then);
//! 3. double Q: a' = argmax of the online net's next values among the available macro-actions
//!    (MacCen-Q: the conditional argmax, keeping the running macro-actions of agents that did not
//!    finish), valued by the target net;
//! 4. y = r + discount x gamma_b x Q'(a') x (1 - terminal), gamma_b = discount^(duration - 1);
//! 5. loss = mean over records of max(h d, d)^2 with d = y - Q(h, a); one Adam step.
//!
//! MacDec-Q updates no agent when any agent's squeeze is empty (the reference returns from the
//! learner before any optimizer step).
//!
//! MacDec-DDRQN (`mac_dec_ddrqn/learning_methods.py: QLearn_squ_dec_cen_0`, ICRA 2020's
//! MacDec-MADDRQN) first takes MacCen-Q's step on its centralized net **without hysteresis**, then
//! lets the updated centralized net choose every agent's a': agent i's component of the
//! conditional argmax at the joint records where i finished; the decentralized nets then take
//! MacDec-Q's hysteretic step with those actions. Parallel-MacDec-DDRQN
//! (`parallel_mac_dec_ddrqn/learning_methods.py: QLearn_squ_dec_cen_0`) does the same with the
//! centralized net's batch from the memory its own exploration filled and the agents' batch from
//! the memory the agents' exploration filled.

use std::collections::HashMap;

use ndarray::{Array2, ArrayView1, ArrayView2};
use serde::{Deserialize, Serialize};

use super::choice::{masked_argmax, Dims};
use super::episode::Step;
use super::prefetch::prefetch_batch;
use super::squeeze::{agent_squeeze, EpisodeKeys, KeptSqueezes, Squeezed};
use crate::autograd::{SeqPacking, Tape, Var};
use crate::nn::joint_index::unravel_component;
use crate::nn::loss::hysteretic_td_loss_taken;
use crate::nn::{Adam, AdamConfig, GruActor, GruActorConfig};

/// A Q-net (MacroMARL's `DDRQN`: fc1, fc2, GRU, fc3, fc4, the actor's layers), its target and
/// its optimizer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QNet {
    /// The net being trained.
    pub net: GruActor,
    /// The target, hard-copied from `net`.
    pub target: GruActor,
    /// Adam on `net`.
    pub adam: Adam,
}

impl QNet {
    /// A fresh net, its target a copy, Adam at learning rate `lr`.
    pub fn new(cfg: GruActorConfig, lr: f64, rng: &mut rand_chacha::ChaCha8Rng) -> Self {
        QNet::from_net(GruActor::new(cfg, rng), lr)
    }

    /// `net` with a target copy and a fresh Adam.
    pub fn from_net(net: GruActor, lr: f64) -> Self {
        QNet {
            target: net.clone(),
            adam: Adam::new(AdamConfig::with_lr(lr), &net),
            net,
        }
    }
}

/// Memory the TD steps reuse from one update to the next (the learner keeps it as
/// [`crate::algos::scratch::Scratch`]): the autodiff tape, reset after every pass, one gradient
/// buffer per net shape, the next values, and what is kept per stored episode (its squeezes, the
/// targets' rows). Every buffer is overwritten before it is read and every kept value is the bits
/// a recomputation gives, so a fresh one gives the same numbers.
#[derive(Debug, Default)]
pub struct UpdateScratch {
    tape: Tape,
    grads: Vec<GruActor>,
    online_next: Vec<f32>,
    /// [records, m1]: the target's last hidden layer at each record's next position.
    target_next: Vec<f32>,
    target_rows: TargetRows,
    squeezes: KeptSqueezes,
}

impl UpdateScratch {
    /// The targets were synced: rows kept from the old ones no longer hold.
    pub fn targets_changed(&mut self) {
        self.target_rows.rows.clear();
    }

    /// Episodes before id `oldest` left the memory: drop their rows and squeezes.
    pub fn forget_episodes_before(&mut self, oldest: u64) {
        self.target_rows.rows.retain(|&(_, id), _| id >= oldest);
        self.squeezes.forget_episodes_before(oldest);
    }
}

/// The target nets' last hidden layer (what fc4 reads) at every kept record's next position of
/// stored whole episodes, from one update to the next while the targets do not change: the
/// published Overcooked and Warehouse rows sample 64 of 500-2 000 stored episodes an update and
/// sync the targets every 5 000 steps (some 40-80 updates), so most sampled episodes were
/// unrolled by the same target before. Rows are a function of the target's weights and the
/// episode alone (every kernel computes a row whatever other rows it runs with), so a kept row
/// is the bits a new unroll gives: the learner clears them at every sync, a resumed run starts
/// with none, and neither changes a number.
#[derive(Debug, Default)]
struct TargetRows {
    /// (net slot, episode id) -> [records, m1].
    rows: HashMap<(usize, u64), Vec<f32>>,
}

/// The gradient buffer for nets of `cfg`'s shape (made on first use).
fn grads_for(grads: &mut Vec<GruActor>, cfg: GruActorConfig) -> &mut GruActor {
    let at = match grads.iter().position(|g| g.config() == cfg) {
        Some(at) => at,
        None => {
            grads.push(GruActor::zeros(cfg));
            grads.len() - 1
        }
    };
    &mut grads[at]
}

/// `net`'s outputs over sequences of `lengths` (flat rows `x` of `width`) and its GRU's outputs
/// h, both in packed order (see [`SeqPacking`]).
fn packed_outputs(
    tape: &mut Tape,
    net: &GruActor,
    x: &[f32],
    width: usize,
    packing: &SeqPacking,
) -> (Var, Var, crate::nn::GruActorVars) {
    let vars = net.bind(tape);
    let packed = packed_input(tape, x, width, packing);
    let (out, h) = net.forward_with_hidden(tape, &vars, packed, packing);
    (out, h, vars)
}

/// Flat rows `x` of `width` on `tape` in `packing`'s order.
fn packed_input(tape: &mut Tape, x: &[f32], width: usize, packing: &SeqPacking) -> Var {
    let mut packed = tape.pool().array(packing.total(), width);
    let rows = packed
        .as_slice_mut()
        .expect("pool arrays are contiguous")
        .chunks_exact_mut(width);
    for (row, &f) in rows.zip(packing.packed_to_flat()) {
        row.copy_from_slice(&x[f * width..(f + 1) * width]);
    }
    tape.constant_owned(packed)
}

/// Row `i` of a standard-layout `a` as a slice (a copy of it is one `memcpy`, not an element-wise
/// iterator). Panics if the rows are not contiguous.
fn row_slice<'a>(a: &ArrayView2<'a, f32>, i: usize) -> &'a [f32] {
    let w = a.ncols();
    let all = a
        .to_slice()
        .expect("tape and fresh arrays are in standard layout");
    &all[i * w..(i + 1) * w]
}

/// Values (no gradient) of `net` over the continuation sequences at each record's next row, into
/// `into` as [records, n_out] row-major; the tape is left empty.
fn next_values(tape: &mut Tape, net: &GruActor, s: &Squeezed, into: &mut Vec<f32>) {
    let lengths: Vec<usize> = s.lengths.iter().map(|l| l + 1).collect();
    let packing = SeqPacking::new(&lengths);
    let (out, _, _) = packed_outputs(tape, net, &s.x_next, s.width, &packing);
    let v = tape.value(out);
    into.clear();
    let mut start = 0;
    for &l in &s.lengths {
        // Record k of the sequence is continuation position k + 1.
        for f in start + 1..start + 1 + l {
            into.extend_from_slice(row_slice(&v, packing.flat_to_packed()[f]));
        }
        start += l + 1;
    }
    tape.reset();
}

/// `target`'s last hidden layer at each record's next position (its continuation unrolled, as
/// [`next_values`] does, short of fc4), into `into` as [records, m1]; with `keys`, from `rows`
/// where they hold the sequence's episode and kept there otherwise. The tape is left empty.
fn target_features(
    tape: &mut Tape,
    target: &GruActor,
    s: &Squeezed,
    keys: Option<EpisodeKeys>,
    rows: &mut TargetRows,
    into: &mut Vec<f32>,
) {
    let m1 = target.config().mlp[1];
    let key = |seq: usize| keys.as_ref().map(|k| (k.slot, k.ids[s.entries[seq]]));
    // Each sequence's first continuation row in x_next (L + 1 rows a sequence).
    let mut starts = Vec::with_capacity(s.lengths.len());
    let mut at = 0;
    for &l in &s.lengths {
        starts.push(at);
        at += l + 1;
    }
    let missing: Vec<usize> = (0..s.lengths.len())
        .filter(|&seq| key(seq).is_none_or(|k| !rows.rows.contains_key(&k)))
        .collect();
    into.clear();
    if !missing.is_empty() {
        let w = s.width;
        let lengths: Vec<usize> = missing.iter().map(|&seq| s.lengths[seq] + 1).collect();
        let mut x = Vec::with_capacity(lengths.iter().sum::<usize>() * w);
        for (&seq, &l) in missing.iter().zip(&lengths) {
            let c = starts[seq];
            x.extend_from_slice(&s.x_next[c * w..(c + l) * w]);
        }
        let packing = SeqPacking::new(&lengths);
        let vars = target.bind(tape);
        let packed = packed_input(tape, &x, w, &packing);
        let (a3, _) = target.features(tape, &vars, packed, &packing);
        let a3 = tape.value(a3);
        let mut c = 0;
        for (&seq, &l) in missing.iter().zip(&lengths) {
            // Record k of the sequence is continuation position k + 1.
            let mut seq_rows = Vec::with_capacity((l - 1) * m1);
            for f in c + 1..c + l {
                seq_rows.extend_from_slice(row_slice(&a3, packing.flat_to_packed()[f]));
            }
            match key(seq) {
                Some(k) => {
                    rows.rows.insert(k, seq_rows);
                }
                // Without keys every sequence is missing, in order.
                None => into.extend_from_slice(&seq_rows),
            }
            c += l;
        }
        tape.reset();
    }
    if keys.is_some() {
        for seq in 0..s.lengths.len() {
            let k = key(seq).expect("keys are given");
            into.extend_from_slice(&rows.rows[&k]);
        }
    }
}

/// The online net's next values when `s` [`Squeezed::continues`], into `into` as [records,
/// n_out]: from its training unroll's outputs `out` and GRU outputs `h` (packed by `packing`),
/// record k's is the output at its sequence's next position, and a sequence's last record's is one
/// step past the end from h there with input o'_{L-1} ([`GruActor::continue_rows`]): the bits a
/// separate unroll over the continuation gives.
fn next_values_from_unroll(
    net: &GruActor,
    out: ArrayView2<f32>,
    h: ArrayView2<f32>,
    packing: &SeqPacking,
    s: &Squeezed,
    into: &mut Vec<f32>,
) {
    let (w, n_seq) = (s.width, s.lengths.len());
    let to_packed = packing.flat_to_packed();
    let mut last_x = Array2::zeros((n_seq, w));
    let mut last_h = Array2::zeros((n_seq, h.ncols()));
    let mut at = 0;
    for (seq, &l) in s.lengths.iter().enumerate() {
        // o'_{L-1}: the last row of the sequence's continuation (L + 1 rows from at + seq).
        let c = at + seq + l;
        last_x
            .row_mut(seq)
            .assign(&ArrayView1::from(&s.x_next[c * w..(c + 1) * w]));
        last_h.row_mut(seq).assign(&h.row(to_packed[at + l - 1]));
        at += l;
    }
    let past = net.continue_rows(last_x.view(), last_h.view());
    into.clear();
    let mut at = 0;
    for (seq, &l) in s.lengths.iter().enumerate() {
        for &p in &to_packed[at + 1..at + l] {
            into.extend_from_slice(row_slice(&out, p));
        }
        into.extend_from_slice(row_slice(&past.view(), seq));
        at += l;
    }
}

/// What one net's TD step computed.
#[derive(Debug, Clone, PartialEq)]
pub struct TdTrace {
    /// Squeezed sequence lengths.
    pub lengths: Vec<usize>,
    /// The bootstrap actions a' (joint indices for MacCen-Q).
    pub next_actions: Vec<usize>,
    /// The targets y.
    pub targets: Vec<f32>,
    /// The loss before the step.
    pub loss: f32,
}

/// The TD step on `q` given the squeezed batch and a chooser of a' from the online net's next
/// values of record k.
fn td_step(
    q: &mut QNet,
    s: &Squeezed,
    mut pick: impl FnMut(usize, &[f32]) -> usize,
    hysteresis: f64,
    discount: f64,
    keys: Option<EpisodeKeys>,
    scratch: &mut UpdateScratch,
) -> TdTrace {
    let UpdateScratch {
        tape,
        grads,
        online_next,
        target_next,
        target_rows,
        ..
    } = scratch;
    let n_out = q.net.config().output;
    // One online unroll gives both Q(h, a) and the next values when the continuation repeats
    // the observations (checked, bit for bit); otherwise the continuation is unrolled apart.
    let continues = s.continues();
    if !continues {
        next_values(tape, &q.net, s, online_next);
    }
    target_features(tape, &q.target, s, keys, target_rows, target_next);
    let packing = SeqPacking::new(&s.lengths);
    let vars = q.net.bind(tape);
    let packed = packed_input(tape, &s.x, s.width, &packing);
    let (a3, h) = q.net.features(tape, &vars, packed, &packing);
    if continues {
        let out = q.net.output_rows(tape.value(a3));
        next_values_from_unroll(&q.net, out.view(), tape.value(h), &packing, s, online_next);
    }
    let next_actions: Vec<usize> = online_next
        .chunks_exact(n_out)
        .enumerate()
        .map(|(k, row)| pick(k, row))
        .collect();
    let d = discount as f32;
    let m1 = q.target.config().mlp[1];
    let targets: Vec<f32> = (0..s.total())
        .map(|k| {
            let boot = q
                .target
                .output_at(&target_next[k * m1..(k + 1) * m1], next_actions[k]);
            s.rewards[k] + d * s.gammas[k] * boot * (1.0 - s.terminals[k])
        })
        .collect();
    // Q(h, a) of the action taken, in packed order, then in the records' order.
    let mut taken = vec![0; s.total()];
    for (&p, &a) in packing.flat_to_packed().iter().zip(&s.actions) {
        taken[p] = a;
    }
    let values = q.net.output_taken(tape, &vars, a3, &taken);
    let values = tape.gather_rows(values, packing.flat_to_packed());
    let y = ArrayView1::from(&targets[..]);
    let loss = hysteretic_td_loss_taken(tape, values, y, hysteresis as f32);
    let loss_value = tape.scalar(loss);
    tape.backward(loss);
    let grads = grads_for(grads, q.net.config());
    vars.grads_into(tape, grads);
    tape.reset();
    q.adam.step(&mut q.net, grads);
    TdTrace {
        lengths: s.lengths.clone(),
        next_actions,
        targets,
        loss: loss_value,
    }
}

/// MacDec-Q's iteration on every agent's net; `None` when some agent's squeeze kept nothing
/// (then no net changes). `ids`: each batch entry's episode id when the batch is of whole stored
/// episodes, under which the episodes' squeezes are kept, and the targets' rows until
/// [`UpdateScratch::targets_changed`]. `scratch` is reused memory (see [`UpdateScratch`]).
#[allow(clippy::too_many_arguments)]
pub fn update_dec(
    nets: &mut [QNet],
    batch: &[&[Step]],
    ids: Option<&[u64]>,
    dims: &Dims,
    hysteresis: f64,
    discount: f64,
    sub_trace_len: usize,
    scratch: &mut UpdateScratch,
) -> Option<Vec<TdTrace>> {
    let keys = |i: usize| ids.map(|ids| EpisodeKeys { slot: 1 + i, ids });
    if ids.is_none() {
        prefetch_batch(batch);
    }
    let squeezed: Vec<_> = (0..nets.len())
        .map(|i| {
            scratch
                .squeezes
                .squeeze(batch, keys(i), |b| agent_squeeze(b, sub_trace_len, dims, i))
        })
        .collect();
    if squeezed.iter().any(|s| s.lengths.is_empty()) {
        return None;
    }
    Some(
        nets.iter_mut()
            .zip(&squeezed)
            .enumerate()
            .map(|(i, (q, s))| {
                td_step(
                    q,
                    s,
                    |k, row| masked_argmax(row, s.next_avail(k)),
                    hysteresis,
                    discount,
                    keys(i),
                    scratch,
                )
            })
            .collect(),
    )
}

/// MacCen-Q's iteration on the centralized net; `None` when the squeeze kept nothing. `ids` as
/// for [`update_dec`]; `scratch` is reused memory (see [`UpdateScratch`]).
#[allow(clippy::too_many_arguments)]
pub fn update_cen(
    q: &mut QNet,
    batch: &[&[Step]],
    ids: Option<&[u64]>,
    dims: &Dims,
    hysteresis: f64,
    discount: f64,
    sub_trace_len: usize,
    scratch: &mut UpdateScratch,
) -> Option<TdTrace> {
    let keys = ids.map(|ids| EpisodeKeys { slot: 0, ids });
    if ids.is_none() {
        prefetch_batch(batch);
    }
    let s = scratch
        .squeezes
        .squeeze(batch, keys, |b| Squeezed::joint(b, sub_trace_len, dims).0);
    if s.lengths.is_empty() {
        return None;
    }
    Some(td_step(
        q,
        &s,
        |k, row| s.conditional_argmax(k, row, dims),
        hysteresis,
        discount,
        keys,
        scratch,
    ))
}

/// MacDec-DDRQN's iteration (`mac_dec_ddrqn`: `cen_batch` and `dec_batch` the same sample;
/// `parallel_mac_dec_ddrqn`: one from each memory): the centralized net `cen` steps on
/// `cen_batch`, then every agent's net in `decs` steps on `dec_batch` with the centralized net's
/// choices there. `None` when `cen_batch`'s joint squeeze kept nothing; the decentralized traces
/// are empty when `dec_batch`'s joint squeeze or some agent's squeeze kept nothing (the reference
/// returns before their optimizer steps, after the centralized one). `scratch` is reused memory
/// (see [`UpdateScratch`]).
#[allow(clippy::too_many_arguments)]
pub fn update_dec_cen(
    cen: &mut QNet,
    decs: &mut [QNet],
    cen_batch: &[&[Step]],
    dec_batch: &[&[Step]],
    dims: &Dims,
    hysteresis: f64,
    discount: f64,
    sub_trace_len: usize,
    scratch: &mut UpdateScratch,
) -> Option<(TdTrace, Vec<TdTrace>)> {
    let joint = |batch| Squeezed::joint(batch, sub_trace_len, dims);
    prefetch_batch(cen_batch);
    let (s, _) = joint(cen_batch);
    if s.lengths.is_empty() {
        return None;
    }
    // The centralized step is plain double Q (no hysteresis in `QLearn_squ_dec_cen_0`).
    let cen_trace = td_step(
        cen,
        &s,
        |k, row| s.conditional_argmax(k, row, dims),
        1.0,
        discount,
        None,
        scratch,
    );
    prefetch_batch(dec_batch);
    let (s, records) = joint(dec_batch);
    if s.lengths.is_empty() {
        return Some((cen_trace, Vec::new()));
    }
    next_values(&mut scratch.tape, &cen.net, &s, &mut scratch.online_next);
    let joint_next: Vec<usize> = scratch
        .online_next
        .chunks_exact(cen.net.config().output)
        .enumerate()
        .map(|(k, row)| s.conditional_argmax(k, row, dims))
        .collect();
    let squeezed: Vec<_> = (0..decs.len())
        .map(|i| agent_squeeze(dec_batch, sub_trace_len, dims, i))
        .collect();
    if squeezed.iter().any(|s| s.lengths.is_empty()) {
        return Some((cen_trace, Vec::new()));
    }
    let dec_traces = decs
        .iter_mut()
        .zip(&squeezed)
        .enumerate()
        .map(|(i, (q, s))| {
            // Agent i's records are the joint records where it finished, in the same order.
            let a_next: Vec<usize> = records
                .iter()
                .zip(&joint_next)
                .filter(|(r, _)| r.valid[i])
                .map(|(_, &j)| unravel_component(j, &dims.n_actions, i))
                .collect();
            td_step(q, s, |k, _| a_next[k], hysteresis, discount, None, scratch)
        })
        .collect();
    Some((cen_trace, dec_traces))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dims() -> Dims {
        Dims {
            obs_sizes: vec![1, 1],
            n_actions: vec![2, 3],
        }
    }

    /// Records of one episode whose observations are held between decisions: record t+1's
    /// observation is record t's next one. Agent 0 finishes every other step, agent 1 always.
    fn held_episode(len: usize) -> Vec<Step> {
        let obs = |t: usize| vec![(t / 2) as f32 * 0.3 - 0.5, (t as f32 * 0.7).sin()];
        (0..len)
            .map(|t| Step {
                obs: obs(t),
                actions: vec![t % 2, (t + 1) % 3],
                rewards: vec![0.1 * t as f32, -0.2],
                gammas: vec![1.0, 1.0],
                joint_reward: 0.05,
                joint_gamma: 1.0,
                next_obs: obs(t + 1),
                next_avail: vec![1.0; 5],
                terminal: t + 1 == len,
                valid: vec![t % 2 == 1, true],
            })
            .collect()
    }

    #[test]
    fn next_values_from_the_training_unroll_are_the_separate_unrolls_bits() {
        use rand::SeedableRng;
        let episode = held_episode(9);
        let batch: Vec<&[Step]> = vec![&episode[..], &episode[2..7], &episode[5..6]];
        let agent = |i: usize| agent_squeeze(&batch, 1, &dims(), i);
        // Agent 0's squeeze (every other record), agent 1's (every record), the joint one.
        let squeezes = [agent(0), agent(1), Squeezed::joint(&batch, 1, &dims()).0];
        for (k, s) in squeezes.iter().enumerate() {
            assert!(s.continues(), "squeeze {k}");
            let cfg = GruActorConfig {
                input: s.width,
                mlp: [17, 9],
                hidden: 21,
                output: 6,
            };
            let net = GruActor::new(cfg, &mut rand_chacha::ChaCha8Rng::seed_from_u64(k as u64));
            let mut tape = Tape::new();
            let mut apart = Vec::new();
            next_values(&mut tape, &net, s, &mut apart);
            let packing = SeqPacking::new(&s.lengths);
            let (out, h, _) = packed_outputs(&mut tape, &net, &s.x, s.width, &packing);
            let mut shared = Vec::new();
            let (out, h) = (tape.value(out), tape.value(h));
            next_values_from_unroll(&net, out, h, &packing, s, &mut shared);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(apart.len(), s.total() * cfg.output, "squeeze {k}");
            assert_eq!(bits(&shared), bits(&apart), "squeeze {k}");
        }
    }

    #[test]
    fn the_targets_rows_give_its_values_bits_at_every_column() {
        use rand::SeedableRng;
        let episode = held_episode(9);
        let batch: Vec<&[Step]> = vec![&episode[..], &episode[2..7], &episode[5..6]];
        let s = Squeezed::joint(&batch, 1, &dims()).0;
        let cfg = GruActorConfig {
            input: s.width,
            mlp: [17, 9],
            hidden: 21,
            output: 6,
        };
        let net = GruActor::new(cfg, &mut rand_chacha::ChaCha8Rng::seed_from_u64(4));
        let mut tape = Tape::new();
        let (mut values, mut rows) = (Vec::new(), Vec::new());
        next_values(&mut tape, &net, &s, &mut values);
        target_features(
            &mut tape,
            &net,
            &s,
            None,
            &mut TargetRows::default(),
            &mut rows,
        );
        assert_eq!(rows.len(), s.total() * cfg.mlp[1]);
        for k in 0..s.total() {
            for a in 0..cfg.output {
                let one = net.output_at(&rows[k * 9..(k + 1) * 9], a);
                assert_eq!(
                    one.to_bits(),
                    values[k * 6 + a].to_bits(),
                    "record {k} action {a}"
                );
            }
        }
    }

    #[test]
    fn kept_target_rows_change_no_number() {
        use crate::nn::Params;
        use rand::{Rng, SeedableRng};
        // Five stored episodes, each its own numbers; batches of three drawn with repeats.
        let episodes: Vec<Vec<Step>> = (0..5)
            .map(|e| {
                let mut ep = held_episode(6 + e);
                for r in &mut ep {
                    r.obs
                        .iter_mut()
                        .chain(&mut r.next_obs)
                        .for_each(|o| *o += e as f32 * 0.1);
                }
                ep
            })
            .collect();
        let cfg = |input, output| GruActorConfig {
            input,
            mlp: [8, 5],
            hidden: 7,
            output,
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let dec = vec![
            QNet::new(cfg(1, 2), 1e-2, &mut rng),
            QNet::new(cfg(1, 3), 1e-2, &mut rng),
        ];
        let cen = QNet::new(cfg(2, 6), 1e-2, &mut rng);
        let (mut dec_kept, mut cen_kept) = (dec.clone(), cen.clone());
        let (mut dec_fresh, mut cen_fresh) = (dec, cen);
        let (mut kept, mut fresh) = (UpdateScratch::default(), UpdateScratch::default());
        for update in 0..12 {
            let picks: Vec<usize> = rand::seq::index::sample(&mut rng, 5, 3).into_vec();
            let ids: Vec<u64> = picks.iter().map(|&p| p as u64).collect();
            let batch: Vec<&[Step]> = picks.iter().map(|&p| &episodes[p][..]).collect();
            let h = rng.gen_range(0.2..1.0);
            let a = update_dec(
                &mut dec_kept,
                &batch,
                Some(&ids),
                &dims(),
                h,
                0.9,
                1,
                &mut kept,
            );
            let b = update_dec(&mut dec_fresh, &batch, None, &dims(), h, 0.9, 1, &mut fresh);
            assert_eq!(a, b, "update {update}");
            let a = update_cen(
                &mut cen_kept,
                &batch,
                Some(&ids),
                &dims(),
                h,
                0.9,
                1,
                &mut kept,
            );
            let b = update_cen(&mut cen_fresh, &batch, None, &dims(), h, 0.9, 1, &mut fresh);
            assert_eq!(a, b, "update {update}");
            if update == 5 {
                for q in dec_kept.iter_mut().chain(dec_fresh.iter_mut()) {
                    q.target.copy_values_from(&q.net);
                }
                for q in [&mut cen_kept, &mut cen_fresh] {
                    q.target.copy_values_from(&q.net);
                }
                kept.targets_changed();
            }
        }
        let bytes = |q: &QNet| bincode::serialize(q).unwrap();
        for (x, y) in dec_kept.iter().zip(&dec_fresh) {
            assert_eq!(bytes(x), bytes(y));
        }
        assert_eq!(bytes(&cen_kept), bytes(&cen_fresh));
        assert!(!kept.target_rows.rows.is_empty());
        kept.forget_episodes_before(3);
        assert!(kept.target_rows.rows.keys().all(|&(_, id)| id >= 3));
    }

    #[test]
    fn a_next_observation_that_is_not_the_following_one_is_unrolled_apart() {
        let mut episode = held_episode(6);
        assert!(Squeezed::joint(&[&episode[..]], 1, &dims()).0.continues());
        episode[2].next_obs[1] += 1.0;
        assert!(!Squeezed::joint(&[&episode[..]], 1, &dims()).0.continues());
    }
}
