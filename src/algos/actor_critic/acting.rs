//! How actor-critic policies pick macro-actions (`docs/MACROMARL.md` §2.5, `controller.py:
//! select_action`): free agents sample from their actor's distribution with the GRU state
//! carried (P13); while training the distribution is the eps-mixture (1 - eps) pi + eps / |A|,
//! when evaluated the plain pi (P8, sampled, not greedy). Mac-CAC's one actor samples a joint
//! macro-action among those that keep every busy agent's running macro-action (P4).

use rand_chacha::ChaCha8Rng;

use crate::nn::sampling::{conditioned_joint, mixture, sample_weighted, Pick};
use crate::nn::{GruActor, GruActorState};

/// The acting path's reusable buffers: once warm, choosing macro-actions allocates nothing per
/// primitive step. Scratch only: a fresh (empty) one acts identically.
#[derive(Debug, Default)]
pub struct ActBuffers {
    /// The sampling distribution of the agent (or the joint action) being decided.
    pub probs: Vec<f64>,
    /// Mac-CAC's joint observation.
    pub joint: Vec<f32>,
}

impl Clone for ActBuffers {
    /// Scratch is not state: a clone starts empty.
    fn clone(&self) -> Self {
        ActBuffers::default()
    }
}

impl ActBuffers {
    /// The joint-observation buffer resized to `len` (its contents are to be overwritten).
    pub fn joint(&mut self, len: usize) -> &mut Vec<f32> {
        self.joint.resize(len, 0.0);
        &mut self.joint
    }
}

/// Decentralized actors: each free agent `i`, in index order, samples from its actor
/// `actor(i)` on its own observation `obs(i)`; busy agents keep their running macro-action
/// (`running[i]`).
#[allow(clippy::too_many_arguments)]
pub fn act_decentralized<'n, 'o>(
    actor: &dyn Fn(usize) -> &'n GruActor,
    states: &mut [GruActorState],
    obs: &dyn Fn(usize) -> &'o [f32],
    free: &[bool],
    running: &[usize],
    eps: Option<f64>,
    rng: &mut ChaCha8Rng,
    probs: &mut Vec<f64>,
    actions: &mut [usize],
) {
    for (i, state) in states.iter_mut().enumerate() {
        if free[i] {
            let logp = actor(i).act_step(obs(i), state);
            mixture(logp, eps, probs);
            actions[i] = sample_weighted(probs, rng);
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
    probs: &mut Vec<f64>,
    actions: &mut [usize],
) {
    if !free.iter().any(|&f| f) {
        actions.copy_from_slice(running);
        return;
    }
    let logp = actor.act_step(joint_obs, state);
    conditioned_joint(
        logp,
        eps,
        free,
        running,
        n_actions,
        Pick::Sample(rng),
        probs,
        actions,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::GruActorConfig;
    use rand::SeedableRng;

    #[test]
    fn the_centralized_actor_keeps_busy_agents_on_their_running_macro_actions() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let cfg = GruActorConfig {
            input: 5,
            mlp: [8, 8],
            hidden: 4,
            output: 12,
        };
        let actor = GruActor::new(cfg, &mut rng);
        let mut state = actor.zero_state();
        let obs = [0.1, -0.4, 0.7, 0.0, 1.0];
        let mut actions = [0, 0];
        let mut probs = Vec::new();
        let mut seen = [false; 3];
        for _ in 0..200 {
            let free = [true, false];
            act_centralized(
                &actor,
                &mut state,
                &obs,
                &free,
                &[9, 2],
                &[3, 4],
                Some(0.5),
                &mut rng,
                &mut probs,
                &mut actions,
            );
            assert_eq!(actions[1], 2, "a busy agent keeps its macro-action");
            seen[actions[0]] = true;
        }
        assert_eq!(
            seen, [true; 3],
            "the free agent samples all of its macro-actions"
        );
        let before = state.clone();
        act_centralized(
            &actor,
            &mut state,
            &obs,
            &[false, false],
            &[1, 3],
            &[3, 4],
            None,
            &mut rng,
            &mut probs,
            &mut actions,
        );
        assert_eq!(
            (actions, &state),
            ([1, 3], &before),
            "nobody free: nothing runs"
        );
    }
}
