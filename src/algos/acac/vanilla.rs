//! One `acac-vanilla` update (`cores/acac/learner_acac_vanilla.py: train`): ACAC's nets without
//! its PPO, GAE and PopArt, as the paper's ablation trains them:
//!
//! 1. the target critic's values b_k after each joint macro-step (dropout live), with the time
//!    indices of that file's quirk below; n-step returns G_k per episode ([`super::nstep`]);
//! 2. `c_train_iteration` times: the critic's squared error to G, its gradient, clipping, an Adam
//!    step;
//! 3. the updated critic's values V_k (a second forward, dropout live), advantages A_k = G_k -
//!    V_k;
//! 4. per agent in order: loss -sum_j gamma^(t_j) (log pi(a_j) A_(k_j) + w H_j) / M over its M
//!    macro-actions (t_j the primitive step where macro-action j ended, k_j the joint step where
//!    it started, log pi and the entropy H of the eps-mixture, w = `etrpy_w`), its gradient,
//!    clipping, an Adam step.
//!
//! ACAC's algorithm class passes `n_train_repeat` 1 to this learner whatever the settings say,
//! so there is one pass.
//!
//! Quirk kept (ACAC-VANILLA-1): the bootstrap forward's time indices are each joint step's end
//! `t + 1` (the first row, the observation before step 0's end, gets e_0 + 1 rather than 1) and
//! the last end + 2, one joint step later than `acac`'s, which gives 1, then e_k + 2.

use std::borrow::Cow;

use ndarray::Array2;

use super::batch::AcacBatch;
use super::nstep::episode_n_step_returns;
use super::update::{
    actor_input, clip, critic_input, critic_loss, end_discounts, mixture_log_prob,
    training_critic_input, AcacNets, ActorInput, ActorTrace, DropoutSource, UpdateError,
    UpdateParams, UpdateTrace,
};
use crate::autograd::{SeqPacking, Tape};
use crate::nn::AcacActor;

/// What only `acac-vanilla` reads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VanillaParams {
    /// `n_step_TD`.
    pub n_step: usize,
    /// `c_train_iteration`.
    pub critic_iterations: usize,
    /// `etrpy_w`.
    pub entropy_weight: f64,
}

/// The bootstrap forward's time indices of one episode (quirk ACAC-VANILLA-1).
fn bootstrap_times(end_steps: &[usize]) -> Vec<usize> {
    let mut t: Vec<usize> = end_steps.iter().map(|&e| e + 1).collect();
    if let Some(&last) = end_steps.last() {
        t.push(last + 2);
    }
    t
}

/// One update (see the module docs); [`super::train_step::update`] checks the batch first.
pub(super) fn update(
    nets: &mut AcacNets,
    batch: &AcacBatch,
    p: &UpdateParams,
    v: &VanillaParams,
    mut dropout: DropoutSource<'_>,
    tape: &mut Tape,
) -> Result<UpdateTrace, UpdateError> {
    let n = nets.actors.len();
    // 1. Targets.
    let times: Vec<Vec<usize>> = batch
        .episodes
        .iter()
        .map(|e| bootstrap_times(&e.end_steps))
        .collect();
    let boot_in = critic_input(
        nets,
        &batch.episodes,
        |k, e| {
            (
                &e.bootstrap_obs,
                Cow::Borrowed(&times[k]),
                &e.bootstrap_steps,
            )
        },
        p.duplicate,
    );
    let boot_rows: usize = boot_in.rows_per_episode.iter().sum();
    let masks = dropout.next(boot_rows, &nets.critic_target)?;
    let values = nets.critic_target.values(tape, &boot_in, masks.as_ref());
    let values = values.as_slice().expect("contiguous");
    let mut returns = Vec::new();
    let mut at = 0;
    for e in &batch.episodes {
        // Row 0 is the first observation; the bootstrap values are the rows after it.
        let b = &values[at + 1..at + e.joint_steps + 1];
        at += e.joint_steps + 1;
        returns.extend(episode_n_step_returns(
            &e.rewards,
            b,
            &end_discounts(&e.end_steps, p.gamma),
            e.terminated,
            p.gamma,
            v.n_step,
        ));
    }

    // 2. The critic.
    let critic_in = training_critic_input(nets, batch, p.duplicate);
    let rows = returns.len();
    let target_col = Array2::from_shape_vec((rows, 1), returns.clone()).expect("a column");
    let mut critic_losses = Vec::with_capacity(v.critic_iterations);
    for _ in 0..v.critic_iterations {
        let masks = dropout.next(rows, &nets.critic)?;
        let (loss, mut grads) =
            critic_loss(&nets.critic, &critic_in, &target_col, masks.as_ref(), tape);
        critic_losses.push(loss);
        clip(&mut grads, p.grad_clip_value, p.grad_clip_norm);
        nets.critic_adam.step(&mut nets.critic, &grads);
    }

    // 3. Advantages from the updated critic.
    let masks = dropout.next(rows, &nets.critic)?;
    let after = nets.critic.values(tape, &critic_in, masks.as_ref());
    let adv: Vec<f32> = returns
        .iter()
        .zip(after.iter())
        .map(|(g, v)| g - v)
        .collect();

    // 4. The actors.
    let mut steps = Vec::with_capacity(n);
    for i in 0..n {
        let input = actor_input(nets, batch, i);
        if input.actions.is_empty() {
            continue;
        }
        let a: Vec<f32> = input.joint.iter().map(|&k| adv[k]).collect();
        let step = actor_loss(
            &nets.actors[i],
            &input,
            &a,
            p.gamma,
            p.eps,
            v.entropy_weight,
            tape,
        );
        let mut grads = step.grads;
        clip(&mut grads, p.grad_clip_value, p.grad_clip_norm);
        nets.actor_adams[i].step(&mut nets.actors[i], &grads);
        steps.push(ActorTrace {
            agent: i,
            loss: step.loss,
            ratios: Vec::new(),
            entropies: step.entropies,
        });
    }
    Ok(UpdateTrace {
        advantages: adv,
        targets: returns.clone(),
        returns,
        old_log_pi: vec![Vec::new(); n],
        critic_losses,
        actors: vec![steps],
    })
}

/// One actor's policy-gradient step.
pub struct VanillaActorStep {
    /// -sum_j gamma^(t_j) (log pi(a_j) A_j + w H_j) / M.
    pub loss: f32,
    /// Its gradient.
    pub grads: AcacActor,
    /// H_j, the eps-mixture's entropy per macro-action.
    pub entropies: Vec<f32>,
}

/// The loss of `actor` on its inputs with advantages `adv` (see the module docs, step 4).
fn actor_loss(
    actor: &AcacActor,
    input: &ActorInput,
    adv: &[f32],
    gamma: f64,
    eps: f64,
    entropy_weight: f64,
    tape: &mut Tape,
) -> VanillaActorStep {
    let m = input.actions.len();
    let discount = end_discounts(&input.end_steps, gamma);
    tape.reset();
    let vars = actor.bind(tape);
    let x = tape.constant(input.x.view());
    let log_pi = vars.forward(tape, x, &SeqPacking::new(&input.lengths));
    let picked = mixture_log_prob(tape, log_pi, &input.actions, eps);
    let pg_weight: Vec<f32> = discount.iter().zip(adv).map(|(d, a)| d * a).collect();
    let pg_weight =
        tape.constant_owned(Array2::from_shape_vec((m, 1), pg_weight).expect("a column"));
    let pg = tape.mul(picked, pg_weight);
    let pg = tape.sum(pg);
    // The whole eps-mixture, as `torch.distributions.Categorical(logits=...)` normalizes it:
    // H = -sum_a p_a log p_a.
    let mixture = full_mixture(tape, log_pi, eps);
    let normalized = tape.log_softmax(mixture);
    let probs = tape.exp(normalized);
    let plogp = tape.mul(probs, normalized);
    let n_actions = tape.shape(log_pi).1;
    let ones = tape.constant_owned(Array2::from_elem((n_actions, 1), -1.0f32));
    let entropy = tape.matmul(plogp, ones);
    let entropies = tape.value(entropy).column(0).to_vec();
    let ent_weight: Vec<f32> = discount.iter().map(|d| d * entropy_weight as f32).collect();
    let ent_weight =
        tape.constant_owned(Array2::from_shape_vec((m, 1), ent_weight).expect("a column"));
    let ent = tape.mul(entropy, ent_weight);
    let ent = tape.sum(ent);
    let total = tape.add(pg, ent);
    let loss = tape.scale(total, -1.0 / m as f32);
    let value = tape.scalar(loss);
    tape.backward(loss);
    let mut grads = actor.zeros_like();
    vars.grads_into(tape, &mut grads);
    VanillaActorStep {
        loss: value,
        grads,
        entropies,
    }
}

/// log((1 - eps) pi + eps / |A|) for every action [M, A], as ACAC's actor forward computes it:
/// an element-wise logsumexp of log pi + ln(1 - eps) and ln(eps) - ln |A|.
fn full_mixture(tape: &mut Tape, log_pi: crate::autograd::Var, eps: f64) -> crate::autograd::Var {
    let (m, a) = tape.shape(log_pi);
    let keep = tape.constant_owned(Array2::from_elem((m, a), (1.0 - eps).ln() as f32));
    let shifted = tape.add(log_pi, keep);
    let shifted = tape.reshape(shifted, m * a, 1);
    let uniform = (eps.ln() - (a as f64).ln()) as f32;
    let uniform = tape.constant_owned(Array2::from_elem((m * a, 1), uniform));
    let pair = tape.concat_cols(&[shifted, uniform]);
    let mixed = tape.logsumexp(pair);
    tape.reshape(mixed, m, a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::acac::update::tests::{check_fd, episodes, small_nets};
    use crate::algos::acac::update::{GaeLambda, Objective};
    use crate::nn::Params;

    #[test]
    fn the_actor_loss_gradient_with_an_entropy_bonus_matches_finite_differences() {
        // ACAC's goldens run at etrpy_w 0: the entropy term's gradient is checked here.
        let (eps, obs, acts) = episodes(3);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let nets = small_nets(&obs, &acts, false);
        let input = actor_input(&nets, &batch, 0);
        let adv: Vec<f32> = (0..input.actions.len())
            .map(|k| (k as f32 * 0.7).sin())
            .collect();
        let loss =
            |a: &AcacActor, w: f64| actor_loss(a, &input, &adv, 0.95, 0.3, w, &mut Tape::new());
        let step = loss(&nets.actors[0], 0.5);
        check_fd(&nets.actors[0], &step.grads, 1, |a| loss(a, 0.5).loss);
        // The bonus enters the loss: -(0.5 / M) sum_j gamma^t_j H_j more.
        let plain = loss(&nets.actors[0], 0.0);
        let d = end_discounts(&input.end_steps, 0.95);
        let bonus: f32 = d
            .iter()
            .zip(&step.entropies)
            .map(|(d, h)| d * h)
            .sum::<f32>()
            * 0.5
            / input.actions.len() as f32;
        assert!(bonus > 1e-3, "{bonus}");
        assert!((plain.loss - step.loss - bonus).abs() < 1e-5);
        // Entropies of a mixture over |A| actions lie in (0, ln |A|].
        let ln_a = (acts[0] as f32).ln();
        assert!(step.entropies.iter().all(|&h| h > 0.0 && h <= ln_a + 1e-6));
    }

    #[test]
    fn a_vanilla_update_runs_one_pass_and_differs_from_ppo() {
        let (eps, obs, acts) = episodes(3);
        let batch = AcacBatch::from_episodes(&eps, &obs).unwrap();
        let params = |objective| UpdateParams {
            gamma: 0.95,
            lambda: 0.9,
            objective,
            clip_ratio: 0.2,
            n_train_repeat: 4,
            eps: 0.3,
            grad_clip_value: 0.0,
            grad_clip_norm: 0.0,
            duplicate: false,
        };
        let vanilla = params(Objective::Vanilla {
            n_step: 5,
            critic_iterations: 2,
            entropy_weight: 0.0,
        });
        let mut a = small_nets(&obs, &acts, false);
        let v = VanillaParams {
            n_step: 5,
            critic_iterations: 2,
            entropy_weight: 0.0,
        };
        let trace = update(
            &mut a,
            &batch,
            &vanilla,
            &v,
            DropoutSource::Off,
            &mut Tape::new(),
        )
        .unwrap();
        // n_train_repeat is not read: two critic steps, one actor pass.
        assert_eq!(trace.critic_losses.len(), 2);
        assert_eq!(trace.actors.len(), 1);
        assert_eq!(trace.actors[0].len(), obs.len());
        assert!(trace.critic_losses[1] < trace.critic_losses[0]);
        let mut b = small_nets(&obs, &acts, false);
        crate::algos::acac::update::ppo_update(
            &mut b,
            &batch,
            &params(Objective::Ppo(GaeLambda::PerMacroStep)),
            GaeLambda::PerMacroStep,
            DropoutSource::Off,
            &mut Tape::new(),
        )
        .unwrap();
        assert_ne!(a.actors[0].slices().concat(), b.actors[0].slices().concat());
    }
}
