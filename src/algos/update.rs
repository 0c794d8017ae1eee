//! One training iteration of any of the five methods (spec `algorithms.md` 5 and 12).
//!
//! Every method runs the same steps; the [`Method`] value decides which of them exist:
//! A, the centralized TD step (Cen-DDRQN, Our-1, Our-1-R, Our-2); B, the conditional joint argmax
//! with the just-updated centralized net (Our-1, Our-2; quirk Q2); C, one TD step per agent, whose
//! target action comes from B or from the agent's own double-Q selection.

use crate::algos::cond_argmax::{cond_argmax_rows, unravel_component, CondArgmaxError};
use crate::algos::method::{DecTargetAction, Method};
use crate::algos::record::Layout;
use crate::algos::replay::Batch;
use crate::algos::squeeze::{
    joint_rows_of_agent, squeeze_agent, squeeze_joint, AgentView, JointView,
};
use crate::algos::ReplayError;
use crate::autograd::SeqPacking;
use crate::nn::{flatten_padded, Adam, AdamConfig, QNet, TdBatch, Updater};
use ndarray::{Array1, Array2, Array3};
use serde::{Deserialize, Serialize};

/// A policy net, its target copy and its optimizer.
#[derive(Debug, Serialize, Deserialize)]
pub struct Nets {
    pub policy: QNet,
    pub target: QNet,
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
    /// Target = policy at the start (spec 2.2).
    pub fn new(policy: QNet, l_rate: f64) -> Self {
        let adam = Adam::new(AdamConfig::with_lr(l_rate), &policy.params);
        Nets {
            target: policy.clone(),
            policy,
            adam,
            updater: None,
        }
    }

    /// Hard target update (spec 2.4).
    pub fn sync_target(&mut self) {
        self.target.copy_from(&self.policy);
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
    pub method: Method,
    pub discount: f32,
    /// Current hysteresis h (spec 5.6), applied where the method says.
    pub h: f32,
    /// Quirk Q9: an empty agent view skips every decentralized step of this iteration.
    pub early_return_skips_all: bool,
}

/// What one iteration did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct IterationLoss {
    /// Sum of the losses of the nets that took a step.
    pub total: f64,
    /// Number of nets that took a step.
    pub steps: usize,
}

/// One training iteration. `dec_batch` feeds the decentralized nets; `cen_batch` the centralized
/// net (the same batch except in Our-2, spec 5.5).
pub fn train_iteration(
    p: IterationParams,
    layout: &Layout,
    dec: &mut [Nets],
    cen: Option<&mut Nets>,
    dec_batch: &Batch<'_>,
    cen_batch: &Batch<'_>,
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
        loss.total += td_step(
            cen,
            &joint.inputs,
            &joint.lengths,
            &joint.joint_actions,
            &y,
            h,
        );
        loss.steps += 1;
        if p.method.dec_target_action() == Some(DecTargetAction::CenCondArgmax) {
            let view = if p.method == Method::Our2 {
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
            joint_star = Some((view, star));
        }
    }
    // Step C.
    let Some(rule) = p.method.dec_target_action() else {
        return Ok(loss);
    };
    let views: Vec<AgentView> = (0..dec.len())
        .map(|i| squeeze_agent(dec_batch, layout, i))
        .collect::<Result<_, _>>()?;
    if p.early_return_skips_all && views.iter().any(|v| v.is_empty()) {
        return Ok(loss); // Q9 (faithful): one empty view skips every agent's step.
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
        loss.total += td_step(nets, &view.inputs, &view.lengths, &view.actions, &y, p.h);
        loss.steps += 1;
    }
    Ok(loss)
}

/// Centralized double-Q targets (spec 5.2): a*_k is the conditional argmax of the online net's
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
            crate::algos::acting::argmax(
                row.as_slice()
                    .expect("rows of a standard-layout array are contiguous"),
            )
        })
        .collect()
}

/// One Adam step on `nets.policy` for loss = mean_k (max(h d_k, d_k))^2, d_k = y_k - Q(h_k, a_k)
/// (spec 5, quirk Q4: the hysteretic transform is a leaky ReLU of slope h before squaring, and
/// the mean runs over all kept records of the batch, quirk Q17). Returns the loss.
fn td_step(
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
    #[error(transparent)]
    Replay(#[from] ReplayError),
    #[error(transparent)]
    CondArgmax(#[from] CondArgmaxError),
}
