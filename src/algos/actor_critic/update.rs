//! One training update of an actor-critic method on its batch of episodes (`docs/MACROMARL.md`
//! 2.6, 2.7; the reference's `learner.train`): squeeze, returns from the target critics, one
//! critic step, advantages from the updated critics (P7), one actor step.
//!
//! The six methods differ in what their critics see and which advantage each actor takes; that
//! is the one `match` on [`AcCritic`] in `critic_inputs` and on the design in
//! `actor_advantages`. Everything else is shared.

use super::episode::Episode;
use super::nets::{AcNets, CriticNet};
use super::returns::{discount_at, macro_returns, MacroSequence};
use super::squeeze::Squeezed;
use crate::algos::actor_critic::method::{AcActor, AcCritic, AcDesign};
use crate::autograd::{SeqPacking, Tape, Var};
use crate::nn::{GruActor, StateCritic};

/// What an update needs besides the nets and the batch.
#[derive(Debug, Clone, PartialEq)]
pub struct UpdateParams {
    /// The method: which critics and which advantage each actor takes.
    pub design: AcDesign,
    /// Discount per primitive step.
    pub gamma: f64,
    /// Macro-steps of the n-step return (0 and 1: one step).
    pub n_step: usize,
    /// The exploration weight the batch was collected with (the eps-mixture's, P3).
    pub eps: f64,
    /// Quirk P2 switch, as [`super::config::AcConfig::pg_discount_at_start`].
    pub pg_discount_at_start: bool,
    /// Quirk P3 switch, as [`super::config::AcConfig::pg_plain_log_prob`].
    pub pg_plain_log_prob: bool,
    /// Each agent's observation length.
    pub obs_sizes: Vec<usize>,
    /// Each agent's number of macro-actions.
    pub n_actions: Vec<usize>,
}

/// What one critic's step computed (for goldens and metrics).
#[derive(Debug, Clone, PartialEq)]
pub struct CriticTrace {
    /// The squeezed sequences' lengths, in batch order.
    pub lengths: Vec<usize>,
    /// The bootstrap values B from the target critic, then the returns G, per macro-action.
    pub bootstraps: Vec<f32>,
    /// The returns G, one per macro-action.
    pub returns: Vec<f32>,
    /// The values before the step, its loss, its gradients, and the advantages G - V after it.
    pub values: Vec<f32>,
    /// The critic's loss before the step.
    pub loss: f32,
    /// The critic's gradients of that loss.
    pub grads: CriticNet,
    /// G - V under the updated critic, one per macro-action.
    pub advantages: Vec<f32>,
}

/// What one actor's step computed.
#[derive(Debug, Clone, PartialEq)]
pub struct ActorTrace {
    /// The squeezed sequences' lengths, in batch order.
    pub lengths: Vec<usize>,
    /// Per macro-action: the action taken, gamma^t (the policy gradient's weight, P2), the
    /// advantage and the log-probability of the action under the trained mixture (P3).
    pub actions: Vec<usize>,
    /// gamma^t, the policy gradient's weight (P2), one per macro-action.
    pub discounts: Vec<f32>,
    /// The advantage each macro-action is trained with.
    pub advantages: Vec<f32>,
    /// Log-probability of the action under the trained mixture (P3).
    pub log_probs: Vec<f32>,
    /// The actor's loss.
    pub loss: f32,
    /// The actor's gradients of that loss.
    pub grads: GruActor,
}

/// Everything an update computed; `None` for a net the update skipped (no macro-action of it
/// ended in the whole batch).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct UpdateTrace {
    /// One entry per critic, in [`AcNets::critics`] order.
    pub critics: Vec<Option<CriticTrace>>,
    /// One entry per actor, in [`AcNets::actors`] order.
    pub actors: Vec<Option<ActorTrace>>,
}

/// Rows of a batch of sequences, sequence-major.
#[derive(Debug, Clone, Default)]
struct Rows {
    width: usize,
    data: Vec<f32>,
    lengths: Vec<usize>,
}

impl Rows {
    fn new(width: usize) -> Self {
        Rows {
            width,
            ..Default::default()
        }
    }

    /// Append one sequence of the given rows.
    fn push_seq<'a>(&mut self, rows: impl Iterator<Item = &'a [f32]>) {
        let mut n = 0;
        for r in rows {
            debug_assert_eq!(r.len(), self.width);
            self.data.extend_from_slice(r);
            n += 1;
        }
        self.lengths.push(n);
    }

    fn total(&self) -> usize {
        self.lengths.iter().sum()
    }

    fn offsets(&self) -> Vec<usize> {
        let mut at = 0;
        self.lengths
            .iter()
            .map(|&l| {
                let o = at;
                at += l;
                o
            })
            .collect()
    }
}

/// Where a critic's values come from.
#[derive(Debug, Clone)]
enum Inputs {
    /// The critic's outputs over these sequences, at these flat row positions.
    History { seqs: Rows, positions: Vec<usize> },
    /// The critic on these rows (one per macro-action).
    State(Rows),
}

/// One critic's training data: its sequences' returns and where its values and bootstraps
/// come from.
#[derive(Debug, Clone)]
struct CriticData {
    lengths: Vec<usize>,
    reward: Vec<f32>,
    terminate: Vec<bool>,
    discount: Vec<f32>,
    values: Inputs,
    bootstraps: Inputs,
}

/// Agent i's slice of a joint observation row.
fn agent_obs<'a>(row: &'a [f32], offsets: &[usize], sizes: &[usize], i: usize) -> &'a [f32] {
    &row[offsets[i]..offsets[i] + sizes[i]]
}

/// The history-critic inputs of a squeeze: values over the rows at `ends`, bootstraps over
/// [row at the first end, next rows at every end], each sequence one episode.
fn history_inputs<'a>(
    batch: &'a [Episode],
    ends: impl Fn(usize) -> &'a [usize],
    row: impl Fn(&'a Episode, usize) -> &'a [f32],
    width: usize,
) -> (Rows, Rows) {
    let mut values = Rows::new(width);
    let mut boot = Rows::new(width);
    for (b, e) in batch.iter().enumerate() {
        let ends = ends(b);
        values.push_seq(ends.iter().map(|&t| row(e, t)));
        boot.push_seq(
            ends.first()
                .map(|&t| row(e, t))
                .into_iter()
                .chain(ends.iter().map(|&t| row(e, t + 1))),
        );
    }
    (values, boot)
}

/// Flat positions 1..=L of each bootstrap sequence (the outputs after each macro-action).
fn shifted_positions(boot: &Rows) -> Vec<usize> {
    boot.offsets()
        .iter()
        .zip(&boot.lengths)
        .flat_map(|(&o, &l)| (1..l).map(move |k| o + k))
        .collect()
}

/// Each critic's data (`docs/MACROMARL.md` §2.7): the one place the critics differ.
fn critic_inputs(p: &UpdateParams, batch: &[Episode], sq: &[Squeezed]) -> Vec<CriticData> {
    let n = p.obs_sizes.len();
    let offsets: Vec<usize> = p
        .obs_sizes
        .iter()
        .scan(0, |at, &s| {
            let o = *at;
            *at += s;
            Some(o)
        })
        .collect();
    let joint = p.obs_sizes.iter().sum::<usize>();
    let state_size = batch.first().map_or(0, |e| e.state_size);
    let g = p.gamma;
    // The returns' side: each episode's macro-actions ending at `ends`, with `reward`.
    let returns_over = |ends: &dyn Fn(&Squeezed) -> &[usize],
                        reward: &dyn Fn(&Episode, usize) -> f32| {
        let mut d = CriticData {
            lengths: Vec::new(),
            reward: Vec::new(),
            terminate: Vec::new(),
            discount: Vec::new(),
            values: Inputs::State(Rows::new(0)),
            bootstraps: Inputs::State(Rows::new(0)),
        };
        for (e, s) in batch.iter().zip(sq) {
            let ends = ends(s);
            d.lengths.push(ends.len());
            d.reward.extend(ends.iter().map(|&t| reward(e, t)));
            d.terminate.extend(ends.iter().map(|&t| e.terminate[t]));
            d.discount.extend(ends.iter().map(|&t| discount_at(g, t)));
        }
        d
    };
    // An agent's own macro-actions and rewards, or the team's joint macro-steps and reward.
    let agent_returns = |i: usize| returns_over(&|s| &s.agent_ends[i], &|e, t| e.reward(t, i));
    let joint_returns = || returns_over(&|s| &s.joint_ends, &|e, t| e.joint_reward[t]);
    let state_rows = |steps: &dyn Fn(usize) -> Vec<usize>| {
        let mut r = Rows::new(state_size);
        for (b, e) in batch.iter().enumerate() {
            r.push_seq(steps(b).into_iter().map(|t| e.state_row(t)));
        }
        r
    };
    let with = |mut d: CriticData, values: Inputs, bootstraps: Inputs| {
        d.values = values;
        d.bootstraps = bootstraps;
        d
    };
    match p.design.critic {
        AcCritic::OwnHistory => (0..n)
            .map(|i| {
                let (v, b) = history_inputs(
                    batch,
                    |k| &sq[k].agent_ends[i],
                    |e, t| agent_obs(e.obs_row(t), &offsets, &p.obs_sizes, i),
                    p.obs_sizes[i],
                );
                let values = Inputs::History {
                    positions: (0..v.total()).collect(),
                    seqs: v,
                };
                let bootstraps = Inputs::History {
                    positions: shifted_positions(&b),
                    seqs: b,
                };
                with(agent_returns(i), values, bootstraps)
            })
            .collect(),
        AcCritic::JointHistory => {
            let (v, b) = history_inputs(batch, |k| &sq[k].joint_ends, |e, t| e.obs_row(t), joint);
            let values = Inputs::History {
                positions: (0..v.total()).collect(),
                seqs: v,
            };
            let bootstraps = Inputs::History {
                positions: shifted_positions(&b),
                seqs: b,
            };
            vec![with(joint_returns(), values, bootstraps)]
        }
        AcCritic::JointState => {
            let values = state_rows(&|b| sq[b].joint_starts.clone());
            let boot = state_rows(&|b| sq[b].joint_ends.iter().map(|t| t + 1).collect());
            vec![with(
                joint_returns(),
                Inputs::State(values),
                Inputs::State(boot),
            )]
        }
        AcCritic::AgentJointHistory => (0..n)
            .map(|i| {
                let (v, b) =
                    history_inputs(batch, |k| &sq[k].joint_ends, |e, t| e.obs_row(t), joint);
                let value_positions = v
                    .offsets()
                    .iter()
                    .zip(sq)
                    .flat_map(|(&o, s)| s.agent_start_positions(i).into_iter().map(move |j| o + j))
                    .collect();
                let boot_positions = b
                    .offsets()
                    .iter()
                    .zip(sq)
                    .flat_map(|(&o, s)| {
                        s.agent_end_positions(i).into_iter().map(move |j| o + j + 1)
                    })
                    .collect();
                let values = Inputs::History {
                    seqs: v,
                    positions: value_positions,
                };
                let bootstraps = Inputs::History {
                    seqs: b,
                    positions: boot_positions,
                };
                with(agent_returns(i), values, bootstraps)
            })
            .collect(),
        AcCritic::AgentState => (0..n)
            .map(|i| {
                let values = state_rows(&|b| sq[b].agent_starts[i].clone());
                let boot = state_rows(&|b| sq[b].agent_ends[i].iter().map(|t| t + 1).collect());
                with(agent_returns(i), Inputs::State(values), Inputs::State(boot))
            })
            .collect(),
    }
}

/// The rows of `seqs` in the packing's order, as a tape constant.
fn packed_input(tape: &mut Tape, seqs: &Rows, packing: &SeqPacking) -> Var {
    // Every array put on the tape comes from its pool (and goes back at reset), so the pool
    // stays as small as one update's arrays.
    let mut x = tape.pool().array(packing.total(), seqs.width);
    for (p, &f) in packing.packed_to_flat().iter().enumerate() {
        x.row_mut(p).assign(&ndarray::ArrayView1::from(
            &seqs.data[f * seqs.width..(f + 1) * seqs.width],
        ));
    }
    tape.constant_owned(x)
}

/// `values` as a tape constant of `width` columns, in a buffer of the tape's pool.
fn column_constant(tape: &mut Tape, values: &[f32], width: usize) -> Var {
    let mut a = tape.pool().array(values.len() / width, width);
    a.as_slice_mut()
        .expect("a fresh array is contiguous")
        .copy_from_slice(values);
    tape.constant_owned(a)
}

/// A recurrent net's outputs over `seqs`, in flat (sequence-major) row order.
fn history_outputs(
    tape: &mut Tape,
    net: &GruActor,
    vars: &crate::nn::GruActorVars,
    seqs: &Rows,
) -> Var {
    let packing = SeqPacking::new(&seqs.lengths);
    let x = packed_input(tape, seqs, &packing);
    let out = net.forward(tape, vars, x, &packing);
    tape.gather_rows(out, packing.flat_to_packed())
}

/// A critic's values at `inputs` on `tape`, with the bound parameters for its gradients.
fn critic_values(tape: &mut Tape, net: &CriticNet, inputs: &Inputs) -> (Var, BoundCritic) {
    match (net, inputs) {
        (CriticNet::History(n), Inputs::History { seqs, positions }) => {
            let vars = n.bind(tape);
            let out = history_outputs(tape, n, &vars, seqs);
            (tape.gather_rows(out, positions), BoundCritic::History(vars))
        }
        (CriticNet::State(n), Inputs::State(rows)) => {
            let vars = n.bind(tape);
            let x = column_constant(tape, &rows.data, rows.width);
            (n.forward(tape, &vars, x), BoundCritic::State(vars))
        }
        _ => unreachable!("a critic's inputs match its kind"),
    }
}

enum BoundCritic {
    History(crate::nn::GruActorVars),
    State(crate::nn::StateCriticVars),
}

/// A critic's values at `inputs`, without gradients.
fn critic_values_nograd(tape: &mut Tape, net: &CriticNet, inputs: &Inputs) -> Vec<f32> {
    let (v, _) = critic_values(tape, net, inputs);
    let out = tape.value(v).iter().copied().collect();
    tape.reset();
    out
}

/// One update of every net on `batch` (the reference's `learner.train`), in the reference's
/// order: each critic's step, then the actors' (the nets are independent, so the interleaving
/// of agents does not matter).
pub fn update(
    nets: &mut AcNets,
    p: &UpdateParams,
    batch: &[Episode],
    tape: &mut Tape,
) -> UpdateTrace {
    let sq: Vec<Squeezed> = batch.iter().map(Squeezed::of).collect();
    let joint_empty = sq.iter().all(|s| s.joint_ends.is_empty());
    let shared_critic = matches!(
        p.design.critic,
        AcCritic::JointHistory | AcCritic::JointState
    );
    let mut trace = UpdateTrace {
        critics: vec![None; nets.critics.len()],
        actors: vec![None; nets.actors.len()],
    };
    if shared_critic && joint_empty {
        // `if jobs.shape[1] == 0: return`: nothing of the batch trains.
        return trace;
    }
    let data = critic_inputs(p, batch, &sq);
    for (c, d) in data.iter().enumerate() {
        if d.lengths.iter().all(|&l| l == 0) {
            continue; // this agent's critic and actor skip (`obs.shape[1] == 0`)
        }
        trace.critics[c] = Some(critic_step(&mut nets.critics[c], p, d, tape));
    }
    for (a, actor) in nets.actors.iter_mut().enumerate() {
        let Some(inputs) = actor_inputs(p, batch, &sq, a, &trace) else {
            continue;
        };
        trace.actors[a] = Some(actor_step(actor, p, inputs, tape));
    }
    trace
}

/// The critic's step: returns from the target critic (before the step, P7), one Adam step on
/// the mean squared error, then the advantages G - V with the updated critic.
fn critic_step(
    critic: &mut super::nets::Critic,
    p: &UpdateParams,
    d: &CriticData,
    tape: &mut Tape,
) -> CriticTrace {
    let bootstraps = critic_values_nograd(tape, &critic.target, &d.bootstraps);
    let mut returns = vec![0.0f32; bootstraps.len()];
    let mut at = 0;
    for &len in &d.lengths {
        let r = at..at + len;
        let seq = MacroSequence {
            reward: &d.reward[r.clone()],
            terminate: &d.terminate[r.clone()],
            discount: &d.discount[r.clone()],
            bootstrap: &bootstraps[r.clone()],
        };
        macro_returns(seq, p.gamma, p.n_step, &mut returns[r]);
        at += len;
    }
    let k = returns.len();
    let (v, bound) = critic_values(tape, &critic.net, &d.values);
    let values: Vec<f32> = tape.value(v).iter().copied().collect();
    let g = column_constant(tape, &returns, 1);
    let td = tape.sub(g, v);
    let sq = tape.square(td);
    let total = tape.sum(sq);
    let loss = tape.scale(total, 1.0 / k as f32);
    let loss_value = tape.scalar(loss);
    tape.backward(loss);
    let grads = match (&critic.net, bound) {
        (CriticNet::History(n), BoundCritic::History(vars)) => {
            let mut g = GruActor::zeros(n.config());
            vars.grads_into(tape, &mut g);
            CriticNet::History(g)
        }
        (CriticNet::State(n), BoundCritic::State(vars)) => {
            let mut g = StateCritic::zeros_like(n);
            vars.grads_into(tape, &mut g);
            CriticNet::State(g)
        }
        _ => unreachable!("bound as its kind"),
    };
    tape.reset();
    match (&mut critic.net, &grads) {
        (CriticNet::History(n), CriticNet::History(g)) => critic.adam.step(n, g),
        (CriticNet::State(n), CriticNet::State(g)) => critic.adam.step(n, g),
        _ => unreachable!("gradients of the same kind"),
    }
    let after = critic_values_nograd(tape, &critic.net, &d.values);
    let advantages = returns.iter().zip(&after).map(|(g, v)| g - v).collect();
    CriticTrace {
        lengths: d.lengths.clone(),
        bootstraps,
        returns,
        values,
        loss: loss_value,
        grads,
        advantages,
    }
}

/// One actor's training rows.
struct ActorInputs {
    seqs: Rows,
    actions: Vec<usize>,
    discounts: Vec<f32>,
    advantages: Vec<f32>,
}

/// Actor `a`'s inputs, with the advantage its method gives each macro-action; `None` when none
/// of its macro-actions ended in the batch (or its critic was skipped).
fn actor_inputs(
    p: &UpdateParams,
    batch: &[Episode],
    sq: &[Squeezed],
    a: usize,
    trace: &UpdateTrace,
) -> Option<ActorInputs> {
    let g = p.gamma;
    let offsets: Vec<usize> = p
        .obs_sizes
        .iter()
        .scan(0, |at, &s| {
            let o = *at;
            *at += s;
            Some(o)
        })
        .collect();
    let weight_step = |ends: &[usize], starts: &[usize], k: usize| {
        if p.pg_discount_at_start {
            starts[k]
        } else {
            ends[k]
        }
    };
    match p.design.actor {
        AcActor::Centralized => {
            let critic = trace.critics[0].as_ref()?;
            let joint = p.obs_sizes.iter().sum();
            let mut seqs = Rows::new(joint);
            let (mut actions, mut discounts) = (Vec::new(), Vec::new());
            for (e, s) in batch.iter().zip(sq) {
                seqs.push_seq(s.joint_ends.iter().map(|&t| e.obs_row(t)));
                for (k, &t) in s.joint_ends.iter().enumerate() {
                    // np.ravel_multi_index in C order: agent 0 most significant.
                    let idx = (0..p.n_actions.len())
                        .fold(0, |acc, i| acc * p.n_actions[i] + e.action(t, i));
                    actions.push(idx);
                    let w = weight_step(&s.joint_ends, &s.joint_starts, k);
                    discounts.push(discount_at(g, w));
                }
            }
            Some(ActorInputs {
                seqs,
                actions,
                discounts,
                advantages: critic.advantages.clone(),
            })
        }
        AcActor::Decentralized => {
            let i = a;
            let mut seqs = Rows::new(p.obs_sizes[i]);
            let (mut actions, mut discounts) = (Vec::new(), Vec::new());
            for (e, s) in batch.iter().zip(sq) {
                let ends = &s.agent_ends[i];
                seqs.push_seq(
                    ends.iter()
                        .map(|&t| agent_obs(e.obs_row(t), &offsets, &p.obs_sizes, i)),
                );
                for (k, &t) in ends.iter().enumerate() {
                    actions.push(e.action(t, i));
                    let w = weight_step(ends, &s.agent_starts[i], k);
                    discounts.push(discount_at(g, w));
                }
            }
            if seqs.total() == 0 {
                return None;
            }
            let advantages = actor_advantages(p, sq, i, trace)?;
            Some(ActorInputs {
                seqs,
                actions,
                discounts,
                advantages,
            })
        }
    }
}

/// The advantage of each of agent i's macro-actions: its own critic's (Mac-IAC, Mac-IAICC,
/// Mac-IAISC), or the shared critic's joint advantage at the joint macro-step where agent i's
/// macro-action ended (Naive Mac-IACC / IASC: the "naive" mismatch).
fn actor_advantages(
    p: &UpdateParams,
    sq: &[Squeezed],
    i: usize,
    trace: &UpdateTrace,
) -> Option<Vec<f32>> {
    match p.design.critic {
        AcCritic::OwnHistory | AcCritic::AgentJointHistory | AcCritic::AgentState => {
            Some(trace.critics[i].as_ref()?.advantages.clone())
        }
        AcCritic::JointHistory | AcCritic::JointState => {
            let critic = trace.critics[0].as_ref()?;
            let mut out = Vec::new();
            let mut at = 0;
            for (s, &len) in sq.iter().zip(&critic.lengths) {
                out.extend(
                    s.agent_end_positions(i)
                        .into_iter()
                        .map(|j| critic.advantages[at + j]),
                );
                at += len;
            }
            Some(out)
        }
    }
}

/// The actor's step on -sum(gamma^t A log pi~(a|h)) / N, with pi~ the eps-mixture
/// (1 - eps) pi + eps / |A| of the batch's eps (P3) unless `pg_plain_log_prob`.
fn actor_step(
    actor: &mut super::nets::Actor,
    p: &UpdateParams,
    inputs: ActorInputs,
    tape: &mut Tape,
) -> ActorTrace {
    let k = inputs.actions.len();
    let net = &actor.net;
    let vars = net.bind(tape);
    let out = history_outputs(tape, net, &vars, &inputs.seqs);
    let n_actions = net.config().output;
    // log pi(a|h) of the taken macro-actions only (the bits of gathering them from the whole
    // log-softmax; nothing else reads the other entries).
    let taken_logp = tape.log_softmax_at(out, &inputs.actions);
    // The mixture of the taken macro-actions only: the loss reads no other entry, and each
    // entry's arithmetic is its own, so these are the whole mixture's taken entries bit for bit
    // (Mac-CAC's joint actor has 3 375 entries a row on 3-agent Overcooked).
    let taken = if p.pg_plain_log_prob || p.eps == 0.0 {
        taken_logp
    } else {
        let probs = tape.exp(taken_logp);
        let kept = tape.scale(probs, (1.0 - p.eps) as f32);
        let mut floor = tape.pool().array(k, 1);
        floor.fill((p.eps / n_actions as f64) as f32);
        let floor = tape.constant_owned(floor);
        let mix = tape.add(kept, floor);
        tape.log(mix)
    };
    let log_probs: Vec<f32> = tape.value(taken).iter().copied().collect();
    let weights: Vec<f32> = inputs
        .discounts
        .iter()
        .zip(&inputs.advantages)
        .map(|(d, a)| d * a)
        .collect();
    let w = column_constant(tape, &weights, 1);
    let weighted = tape.mul(taken, w);
    let total = tape.sum(weighted);
    let loss = tape.scale(total, -1.0 / k as f32);
    let loss_value = tape.scalar(loss);
    tape.backward(loss);
    let mut grads = GruActor::zeros(net.config());
    vars.grads_into(tape, &mut grads);
    tape.reset();
    actor.adam.step(&mut actor.net, &grads);
    ActorTrace {
        lengths: inputs.seqs.lengths,
        actions: inputs.actions,
        discounts: inputs.discounts,
        advantages: inputs.advantages,
        log_probs,
        loss: loss_value,
        grads,
    }
}
