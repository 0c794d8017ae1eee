//! How actor-critic policies pick macro-actions (spec `macromarl.md` 2.5, `controller.py:
//! select_action`): free agents sample from their actor's distribution with the GRU state
//! carried (P13); while training the distribution is the eps-mixture (1 - eps) pi + eps / |A|,
//! when evaluated the plain pi (P8, sampled, not greedy). Mac-CAC's one actor samples a joint
//! macro-action among those that keep every busy agent's running macro-action (P4).

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::nn::{GruActor, GruActorState};

/// Sample index a from weights p_a (not necessarily normalized; zero weights never drawn).
pub fn sample_weighted(weights: &[f64], rng: &mut ChaCha8Rng) -> usize {
    let total: f64 = weights.iter().sum();
    let u = rng.gen::<f64>() * total;
    let mut acc = 0.0;
    let mut last = 0;
    for (a, &w) in weights.iter().enumerate() {
        if w > 0.0 {
            acc += w;
            last = a;
            if u < acc {
                return a;
            }
        }
    }
    last
}

/// The probabilities of the actor's log-probabilities `logp` under exploration weight `eps`
/// (`None` when evaluated), into `out`.
pub fn mixture(logp: &[f32], eps: Option<f64>, out: &mut Vec<f64>) {
    out.clear();
    let n = logp.len() as f64;
    match eps {
        Some(eps) => out.extend(
            logp.iter()
                .map(|&l| (1.0 - eps) * f64::from(l).exp() + eps / n),
        ),
        None => out.extend(logp.iter().map(|&l| f64::from(l).exp())),
    }
}

/// Decentralized actors: each free agent, in index order, samples from its actor on its own
/// observation; busy agents keep their running macro-action (`running[i]`).
#[allow(clippy::too_many_arguments)]
pub fn act_decentralized(
    actors: &[&GruActor],
    states: &mut [GruActorState],
    obs: &dyn Fn(usize) -> Vec<f32>,
    free: &[bool],
    running: &[usize],
    eps: Option<f64>,
    rng: &mut ChaCha8Rng,
    actions: &mut [usize],
) {
    let mut probs = Vec::new();
    for (i, actor) in actors.iter().enumerate() {
        if free[i] {
            let logp = actor.act_step(&obs(i), &mut states[i]);
            mixture(logp, eps, &mut probs);
            actions[i] = sample_weighted(&probs, rng);
        } else {
            actions[i] = running[i];
        }
    }
}

/// Mac-CAC's centralized actor: when some agent is free, one step on the joint observation and
/// a joint macro-action sampled among those whose busy agents' parts equal their running
/// macro-actions, unravelled in C order (agent 0 most significant). Nothing runs when every
/// agent is busy.
#[allow(clippy::too_many_arguments)]
pub fn act_centralized(
    actor: &GruActor,
    state: &mut GruActorState,
    joint_obs: &[f32],
    free: &[bool],
    running: &[usize],
    n_actions: &[usize],
    eps: Option<f64>,
    rng: &mut ChaCha8Rng,
    actions: &mut [usize],
) {
    if !free.iter().any(|&f| f) {
        actions.copy_from_slice(running);
        return;
    }
    let logp = actor.act_step(joint_obs, state);
    let mut probs = Vec::new();
    mixture(logp, eps, &mut probs);
    for (j, p) in probs.iter_mut().enumerate() {
        let mut rest = j;
        for i in (0..n_actions.len()).rev() {
            let a = rest % n_actions[i];
            rest /= n_actions[i];
            if !free[i] && a != running[i] {
                *p = 0.0;
                break;
            }
        }
    }
    let mut j = sample_weighted(&probs, rng);
    for i in (0..n_actions.len()).rev() {
        actions[i] = j % n_actions[i];
        j /= n_actions[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn sampling_follows_the_weights_and_never_draws_a_zero() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let w = [0.0, 3.0, 0.0, 1.0];
        let mut counts = [0usize; 4];
        for _ in 0..4000 {
            counts[sample_weighted(&w, &mut rng)] += 1;
        }
        assert_eq!((counts[0], counts[2]), (0, 0));
        assert!((2800..3200).contains(&counts[1]), "{counts:?}");
    }

    #[test]
    fn the_mixture_is_eps_uniform_plus_the_rest_of_pi() {
        let logp = [0.5f32.ln(), 0.25f32.ln(), 0.25f32.ln()];
        let mut p = Vec::new();
        mixture(&logp, Some(0.3), &mut p);
        let want = [0.7 * 0.5 + 0.1, 0.7 * 0.25 + 0.1, 0.7 * 0.25 + 0.1];
        for (a, b) in p.iter().zip(want) {
            assert!((a - b).abs() < 1e-6);
        }
        mixture(&logp, None, &mut p);
        assert!((p[0] - 0.5).abs() < 1e-6);
    }
}
