//! One training iteration of any of the five methods (`docs/ALGORITHMS.md` §5 and 12).
//!
//! Every method runs the same steps; the [`ValueMethod`] value decides which of them exist:
//! A, the centralized TD step (Cen-DDRQN, Our-1, Our-1-R, Our-2); B, the conditional joint argmax
//! with the just-updated centralized net (Our-1, Our-2; quirk Q2); C, one TD step per agent, whose
//! target action comes from B or from the agent's own double-Q selection.

use crate::algos::value::cond_argmax::{cond_argmax_rows, CondArgmaxError};
use crate::algos::value::method::{DecTargetAction, ValueMethod};
use crate::algos::value::record::Layout;
use crate::algos::value::replay::Batch;
use crate::algos::value::squeeze::{
    joint_rows_of_agent, squeeze_agent_min, squeeze_joint, AgentView, JointView,
};
use crate::algos::value::ReplayError;
use crate::autograd::SeqPacking;
use crate::nn::joint_index::unravel_component;
use crate::nn::{flatten_padded, Adam, AdamConfig, QNet, QNetParams, TdBatch, Updater};
use ndarray::{Array1, Array2, Array3};
use serde::{Deserialize, Serialize};

/// A policy net, its target copy and its optimizer.
#[derive(Debug, Serialize, Deserialize)]
pub struct Nets {
    /// The net trained.
    pub policy: QNet,
    /// Its target copy, which computes the TD targets.
    pub target: QNet,
    /// The optimizer state of `policy`.
    pub adam: Adam,
    /// Reusable tape and gradient buffers (rebuilt after a resume).
    #[serde(skip)]
    updater: Option<Updater>,
}

impl Clone for Nets {
    fn clone(&self) -> Self {
        Nets {
            policy: self.policy.clone(),
            target: self.target.clone(),
            adam: self.adam.clone(),
            updater: None,
        }
    }
}

impl Nets {
    /// Target = policy at the start (`docs/ALGORITHMS.md` §2.2).
    pub fn new(policy: QNet, l_rate: f64) -> Self {
        let adam = Adam::new(AdamConfig::with_lr(l_rate), &policy.params);
        Nets {
            target: policy.clone(),
            policy,
            adam,
            updater: None,
        }
    }

    /// Hard target update (`docs/ALGORITHMS.md` §2.4).
    pub fn sync_target(&mut self) {
        self.target.copy_from(&self.policy);
    }

    /// The gradient of the last [`train_iteration`] step of this net, if it took one since it
    /// was built or resumed (for differential tests against the reference, `tests/golden.rs`).
    #[doc(hidden)]
    pub fn last_gradient(&self) -> Option<&QNetParams> {
        self.updater.as_ref().map(|u| &u.grads)
    }

    /// Whether every parameter is a finite number.
    pub fn is_finite(&self) -> bool {
        use crate::nn::Params;
        self.policy
            .params
            .slices()
            .iter()
            .all(|s| s.iter().all(|v| v.is_finite()))
    }
}

/// The knobs of one iteration that change during training or differ by config.
#[derive(Debug, Clone, Copy)]
pub struct IterationParams {
    /// The method, which decides targets and losses.
    pub method: ValueMethod,
    /// Discount per macro-transition in the targets (quirk Q5).
    pub discount: f32,
    /// Current hysteresis h (`docs/ALGORITHMS.md` §5.6), applied where the method says.
    pub h: f32,
    /// Quirk Q9: an empty agent view skips every decentralized step of this iteration.
    pub early_return_skips_all: bool,
    /// `sub_trace_len`: an agent's sequence with fewer kept records is dropped from its view
    /// (`docs/ALGORITHMS.md` §3.3; the paper's 1 drops only sequences without any).
    pub sub_trace_len: usize,
}

/// What one iteration did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct IterationLoss {
    /// Sum of the losses of the nets that took a step.
    pub total: f64,
    /// Number of nets that took a step.
    pub steps: usize,
}

/// What one iteration computed, net by net: the numbers a differential test compares with the
/// reference's learner (`tests/golden.rs`). Filled only by [`train_iteration_traced`].
#[doc(hidden)]
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IterationTrace {
    /// The centralized net's step (Step A), if it took one.
    pub cen: Option<NetTrace>,
    /// Step B's joint indices (Our-1, Our-2): the conditional argmax of the just-updated
    /// centralized net over the joint view of the decentralized batch, one per joint record.
    pub joint_star: Option<Vec<usize>>,
    /// Agent i's step (Step C), `None` where it took none; empty if Step C was not reached.
    pub dec: Vec<Option<NetTrace>>,
}

/// One net's TD step inside an iteration.
#[doc(hidden)]
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NetTrace {
    /// The action each kept record bootstraps from (joint index for the centralized net).
    pub target_actions: Vec<usize>,
    /// The detached targets y_k, in flat (sequence, time) order.
    pub targets: Vec<f32>,
    /// The loss before the step.
    pub loss: f64,
}

/// One training iteration. `dec_batch` feeds the decentralized nets; `cen_batch` the centralized
/// net (the same batch except in Our-2, `docs/ALGORITHMS.md` §5.5).
pub fn train_iteration(
    p: IterationParams,
    layout: &Layout,
    dec: &mut [Nets],
    cen: Option<&mut Nets>,
    dec_batch: &Batch<'_>,
    cen_batch: &Batch<'_>,
) -> Result<IterationLoss, UpdateError> {
    run_iteration(p, layout, dec, cen, dec_batch, cen_batch, None)
}

/// [`train_iteration`], also returning what each net's step computed. The same arithmetic in
/// the same order: the trace only copies values out.
#[doc(hidden)]
pub fn train_iteration_traced(
    p: IterationParams,
    layout: &Layout,
    dec: &mut [Nets],
    cen: Option<&mut Nets>,
    dec_batch: &Batch<'_>,
    cen_batch: &Batch<'_>,
) -> Result<(IterationLoss, IterationTrace), UpdateError> {
    let mut trace = IterationTrace::default();
    let loss = run_iteration(p, layout, dec, cen, dec_batch, cen_batch, Some(&mut trace))?;
    Ok((loss, trace))
}

fn run_iteration(
    p: IterationParams,
    layout: &Layout,
    dec: &mut [Nets],
    cen: Option<&mut Nets>,
    dec_batch: &Batch<'_>,
    cen_batch: &Batch<'_>,
    mut trace: Option<&mut IterationTrace>,
) -> Result<IterationLoss, UpdateError> {
    let mut loss = IterationLoss::default();
    let n_actions = layout.n_actions();
    // Step A and B.
    let mut joint_star: Option<(JointView, Vec<usize>)> = None;
    if let Some(cen) = cen {
        let joint = squeeze_joint(cen_batch, layout)?;
        if joint.is_empty() {
            return Ok(loss); // Q9: the learner returns at once.
        }
        let qn = cen
            .policy
            .forward_nograd_padded(joint.next_inputs.view(), &joint.lengths);
        let qt = cen
            .target
            .forward_nograd_padded(joint.next_inputs.view(), &joint.lengths);
        let y = cen_targets(&joint, &qn, &qt, n_actions, p.discount)?;
        let h = if p.method.cen_loss_is_hysteretic() {
            p.h
        } else {
            1.0
        };
        let cen_loss = step_nets(
            cen,
            &joint.inputs,
            &joint.lengths,
            &joint.joint_actions,
            &y,
            h,
        );
        loss.total += cen_loss;
        loss.steps += 1;
        if let Some(t) = trace.as_deref_mut() {
            t.cen = Some(NetTrace {
                // The same pure selection `cen_targets` made.
                target_actions: cond_argmax_rows(qn.view(), n_actions, &joint.cond)?,
                targets: y,
                loss: cen_loss,
            });
        }
        if p.method.dec_target_action() == Some(DecTargetAction::CenCondArgmax) {
            let view = if p.method.dec_batch_is_separate() {
                squeeze_joint(dec_batch, layout)?
            } else {
                joint
            };
            if view.is_empty() {
                return Ok(loss);
            }
            // Q2: the selection uses the centralized net right after its own step.
            let qn2 = cen
                .policy
                .forward_nograd_padded(view.next_inputs.view(), &view.lengths);
            let star = cond_argmax_rows(qn2.view(), n_actions, &view.cond)?;
            if let Some(t) = trace.as_deref_mut() {
                t.joint_star = Some(star.clone());
            }
            joint_star = Some((view, star));
        }
    }
    // Step C.
    let Some(rule) = p.method.dec_target_action() else {
        return Ok(loss);
    };
    let views: Vec<AgentView> = (0..dec.len())
        .map(|i| squeeze_agent_min(dec_batch, layout, i, p.sub_trace_len))
        .collect::<Result<_, _>>()?;
    if p.early_return_skips_all && views.iter().any(|v| v.is_empty()) {
        return Ok(loss); // Q9 (faithful): one empty view skips every agent's step.
    }
    if let Some(t) = trace.as_deref_mut() {
        t.dec = vec![None; dec.len()];
    }
    for (agent, (nets, view)) in dec.iter_mut().zip(&views).enumerate() {
        if view.is_empty() {
            continue;
        }
        let own_qn = (rule == DecTargetAction::OwnDoubleQ).then(|| {
            nets.policy
                .forward_nograd_padded(view.next_inputs.view(), &view.lengths)
        });
        let a_star =
            dec_target_actions(rule, agent, n_actions, joint_star.as_ref(), own_qn.as_ref());
        let qt = nets
            .target
            .forward_nograd_padded(view.next_inputs.view(), &view.lengths);
        let y = targets(&view.rewards, &view.dones, &qt, &a_star, p.discount);
        let h = if p.method.dec_loss_is_hysteretic() {
            p.h
        } else {
            1.0
        };
        let agent_loss = step_nets(nets, &view.inputs, &view.lengths, &view.actions, &y, h);
        loss.total += agent_loss;
        loss.steps += 1;
        if let Some(t) = trace.as_deref_mut() {
            t.dec[agent] = Some(NetTrace {
                target_actions: a_star,
                targets: y,
                loss: agent_loss,
            });
        }
    }
    Ok(loss)
}

/// Centralized double-Q targets (`docs/ALGORITHMS.md` §5.2): a*_k is the conditional argmax of the online net's
/// next Q-values under the record's conditioning, evaluated by the target net.
pub fn cen_targets(
    joint: &JointView,
    q_next_online: &Array2<f32>,
    q_next_target: &Array2<f32>,
    n_actions: &[usize],
    gamma: f32,
) -> Result<Vec<f32>, CondArgmaxError> {
    let a_star = cond_argmax_rows(q_next_online.view(), n_actions, &joint.cond)?;
    Ok(targets(
        &joint.rewards,
        &joint.dones,
        q_next_target,
        &a_star,
        gamma,
    ))
}

/// The action each of agent `agent`'s records bootstraps from: its component of the centralized
/// conditional argmax `joint_star` (Our-1/Our-2, Eq. 4; rows paired by `joint_rows_of_agent`) or the
/// argmax of its own online net's next Q-values `own_q_next` (Dec-HDDRQN, Our-1-R).
/// Panics if the input its rule needs is missing (a bug in the caller).
pub fn dec_target_actions(
    rule: DecTargetAction,
    agent: usize,
    n_actions: &[usize],
    joint_star: Option<&(JointView, Vec<usize>)>,
    own_q_next: Option<&Array2<f32>>,
) -> Vec<usize> {
    match rule {
        DecTargetAction::CenCondArgmax => {
            let (joint, star) = joint_star.expect("the centralized selection ran for this method");
            joint_rows_of_agent(joint, agent)
                .iter()
                .map(|&k| unravel_component(star[k], n_actions, agent))
                .collect()
        }
        DecTargetAction::OwnDoubleQ => {
            row_argmax(own_q_next.expect("own next Q-values were computed"))
        }
    }
}

/// Double-Q targets y_k = r_k + gamma (1 - done_k) Q_target[k, a*_k] (detached; quirks Q5, Q7).
pub fn targets(
    rewards: &[f32],
    dones: &[f32],
    q_target: &Array2<f32>,
    a_star: &[usize],
    gamma: f32,
) -> Vec<f32> {
    rewards
        .iter()
        .zip(dones)
        .zip(a_star)
        .enumerate()
        .map(|(k, ((&r, &d), &a))| r + gamma * (1.0 - d) * q_target[[k, a]])
        .collect()
}

/// First maximal column of each row (quirk Q14).
pub fn row_argmax(q: &Array2<f32>) -> Vec<usize> {
    q.rows()
        .into_iter()
        .map(|row| {
            crate::algos::value::acting::argmax(
                row.as_slice()
                    .expect("rows of a standard-layout array are contiguous"),
            )
        })
        .collect()
}

/// One Adam step on `nets.policy` for loss = mean_k (max(h d_k, d_k))^2, d_k = y_k - Q(h_k, a_k)
/// (`docs/ALGORITHMS.md` §5, quirk Q4: the hysteretic transform is a leaky ReLU of slope h before squaring, and
/// the mean runs over all kept records of the batch, quirk Q17). Returns the loss.
fn step_nets(
    nets: &mut Nets,
    inputs: &Array3<f32>,
    lengths: &[usize],
    actions: &[usize],
    y: &[f32],
    h: f32,
) -> f64 {
    let updater = nets
        .updater
        .get_or_insert_with(|| Updater::new(&nets.policy));
    let mut pool = crate::autograd::Pool::default();
    let batch = TdBatch {
        x: flatten_padded(inputs.view(), lengths, &mut pool),
        packing: SeqPacking::new(lengths),
        actions: actions.to_vec(),
        targets: Array1::from(y.to_vec()),
    };
    updater.td_step(&mut nets.policy, &mut nets.adam, &batch, h) as f64
}

/// Why a training iteration failed.
#[derive(Debug, thiserror::Error)]
pub enum UpdateError {
    /// The replay buffer refused the sample.
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// The conditional argmax refused its inputs.
    #[error(transparent)]
    CondArgmax(#[from] CondArgmaxError),
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::family::FamilyMethod;
    use crate::algos::value::record::{Episode, RecordRef};
    use crate::algos::value::replay::Sequence;
    use crate::algos::value::squeeze::squeeze_agent;
    use ndarray::array;

    /// Two agents with one observation value and two macro-actions each. Step 0: agent 0 ran
    /// macro-action 1 and finished, agent 1 (running 0) did not; step 1: both finished, terminal.
    fn two_step_episode() -> (Layout, Episode) {
        let layout = Layout::new(&[1, 1], &[2, 2]).unwrap();
        let mut ep = Episode::new(2, 2, 2);
        ep.push(RecordRef {
            obs: &[0.1, 0.2],
            executed: &[1, 0],
            acc_id: &[-1.0, -1.0],
            acc_joint: -1.0,
            next_obs: &[0.3, 0.2],
            done: false,
            valid: &[true, false],
        })
        .unwrap();
        ep.push(RecordRef {
            obs: &[0.3, 0.2],
            executed: &[0, 0],
            acc_id: &[-1.0, -2.0],
            acc_joint: -1.0,
            next_obs: &[0.5, 0.6],
            done: true,
            valid: &[true, true],
        })
        .unwrap();
        (layout, ep)
    }

    fn batch(ep: &Episode) -> Batch<'_> {
        Batch {
            sequences: vec![Sequence {
                episode: ep,
                start: 0,
                end: 2,
                lead_pad: 0,
            }],
            padded_len: 2,
        }
    }

    /// Next-state Q of the centralized online net, joint index = 2 m_0 + m_1.
    fn cen_q_next() -> Array2<f32> {
        // Row 0: agent 1 is still running 0, so only (0,0)=5 and (1,0)=7 are allowed -> a* = 2
        // although (1,1)=9 is larger. Row 1: both free -> plain argmax, (0,1)=3 -> a* = 1.
        array![[5.0, 1.0, 7.0, 9.0], [1.0, 3.0, 2.0, 0.0]]
    }

    #[test]
    fn centralized_target_uses_the_conditional_argmax() {
        let (layout, ep) = two_step_episode();
        let joint = squeeze_joint(&batch(&ep), &layout).unwrap();
        assert_eq!(joint.cond, vec![-1, 0, -1, -1]);
        assert_eq!(joint.joint_actions, vec![2, 0]);
        let q_target = array![[10.0, 20.0, 30.0, 40.0], [1.0, 2.0, 3.0, 4.0]];
        let y = cen_targets(&joint, &cen_q_next(), &q_target, layout.n_actions(), 0.9).unwrap();
        // y_0 = r^c + gamma * Q^-[0, a*=2] = -1 + 0.9 * 30 = 26; y_1 is terminal: r^c = -1.
        assert_eq!(y, vec![-1.0 + 0.9 * 30.0, -1.0]);
    }

    #[test]
    fn our1_decentralized_target_takes_the_agents_component_of_the_joint_argmax() {
        let (layout, ep) = two_step_episode();
        let b = batch(&ep);
        let joint = squeeze_joint(&b, &layout).unwrap();
        let star = cond_argmax_rows(cen_q_next().view(), layout.n_actions(), &joint.cond).unwrap();
        assert_eq!(star, vec![2, 1]);
        let joint_star = (joint, star);
        // Agent 0 finished at both steps: components of (1,0) and (0,1) -> 1 then 0.
        let a0 = dec_target_actions(
            DecTargetAction::CenCondArgmax,
            0,
            &[2, 2],
            Some(&joint_star),
            None,
        );
        assert_eq!(a0, vec![1, 0]);
        // Agent 1 finished only at step 1: component of (0,1) -> 1.
        let a1 = dec_target_actions(
            DecTargetAction::CenCondArgmax,
            1,
            &[2, 2],
            Some(&joint_star),
            None,
        );
        assert_eq!(a1, vec![1]);
        let view0 = squeeze_agent(&b, &layout, 0).unwrap();
        let qt0 = array![[4.0, 8.0], [1.0, 1.0]];
        // y = -1 + 0.9 * Q^-_0[0, 1] = 6.2; terminal -> -1.
        assert_eq!(
            targets(&view0.rewards, &view0.dones, &qt0, &a0, 0.9),
            vec![-1.0 + 0.9 * 8.0, -1.0]
        );
        let view1 = squeeze_agent(&b, &layout, 1).unwrap();
        // Agent 1's macro-reward sums both primitive steps (-2) and its only record is terminal.
        assert_eq!(
            targets(&view1.rewards, &view1.dones, &array![[5.0, 6.0]], &a1, 0.9),
            vec![-2.0]
        );
    }

    #[test]
    fn dec_hddrqn_and_our1_r_targets_use_the_agents_own_double_q() {
        let (layout, ep) = two_step_episode();
        let view0 = squeeze_agent(&batch(&ep), &layout, 0).unwrap();
        let own_next = array![[3.0, 1.0], [0.0, 2.0]];
        let a0 = dec_target_actions(
            DecTargetAction::OwnDoubleQ,
            0,
            &[2, 2],
            None,
            Some(&own_next),
        );
        assert_eq!(a0, vec![0, 1]);
        let qt0 = array![[4.0, 8.0], [1.0, 1.0]];
        // y = -1 + 0.9 * Q^-_0[0, 0] = 2.6 (Our-1 would bootstrap from 8 instead).
        assert_eq!(
            targets(&view0.rewards, &view0.dones, &qt0, &a0, 0.9),
            vec![-1.0 + 0.9 * 4.0, -1.0]
        );
        assert_eq!(
            ValueMethod::DecHddrqn.dec_target_action(),
            Some(DecTargetAction::OwnDoubleQ)
        );
        assert_eq!(
            ValueMethod::Our1R.dec_target_action(),
            Some(DecTargetAction::OwnDoubleQ)
        );
        assert_eq!(
            ValueMethod::Our2.dec_target_action(),
            Some(DecTargetAction::CenCondArgmax)
        );
    }

    #[test]
    fn the_traced_iteration_changes_no_number() {
        use crate::nn::{QNetConfig, TENSOR_NAMES};
        use rand::SeedableRng;
        let (layout, ep) = two_step_episode();
        let b = batch(&ep);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let net = |input, output, rng: &mut rand_chacha::ChaCha8Rng| {
            let cfg = QNetConfig {
                input,
                mlp: 4,
                hidden: 3,
                output,
            };
            Nets::new(QNet::new(cfg, rng), 0.01)
        };
        let dec: Vec<Nets> = (0..2).map(|_| net(1, 2, &mut rng)).collect();
        let cen = net(2, 4, &mut rng);
        for &method in ValueMethod::ALL {
            let p = IterationParams {
                method,
                discount: 0.9,
                h: 0.5,
                early_return_skips_all: true,
                sub_trace_len: 1,
            };
            let (mut d1, mut c1) = (dec.clone(), cen.clone());
            let (mut d2, mut c2) = (dec.clone(), cen.clone());
            let use_cen = method.has_cen_net();
            let plain =
                train_iteration(p, &layout, &mut d1, use_cen.then_some(&mut c1), &b, &b).unwrap();
            let (traced, trace) =
                train_iteration_traced(p, &layout, &mut d2, use_cen.then_some(&mut c2), &b, &b)
                    .unwrap();
            assert_eq!(plain, traced, "{method:?}");
            assert_eq!(trace.cen.is_some(), use_cen, "{method:?}");
            for (x, y) in d1.iter().chain([&c1]).zip(d2.iter().chain([&c2])) {
                for name in TENSOR_NAMES {
                    let (a, b) = (x.policy.params.get(name), y.policy.params.get(name));
                    assert_eq!(a, b, "{method:?} {name}");
                }
            }
            let stepped = trace.dec.iter().flatten().count() + usize::from(trace.cen.is_some());
            assert_eq!(stepped, plain.steps, "{method:?}");
        }
    }

    #[test]
    fn argmax_rows_take_the_first_maximum() {
        assert_eq!(row_argmax(&array![[1.0, 1.0], [0.0, 2.0]]), vec![0, 1]);
    }
}
