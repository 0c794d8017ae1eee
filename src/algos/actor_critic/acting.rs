//! How actor-critic policies pick macro-actions (`docs/MACROMARL.md` §2.5, `controller.py:
//! select_action`): free agents sample from their actor's distribution with the GRU state
//! carried (P13); while training the distribution is the eps-mixture (1 - eps) pi + eps / |A|,
//! when evaluated the plain pi (P8, sampled, not greedy). Mac-CAC's one actor samples a joint
//! macro-action among those that keep every busy agent's running macro-action (P4).

use rand_chacha::ChaCha8Rng;

use crate::nn::sampling::{conditioned_joint, mixture, sample_weighted, Pick};
use crate::nn::{GruActor, GruActorState};

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
    conditioned_joint(
        logp,
        eps,
        free,
        running,
        n_actions,
        Pick::Sample(rng),
        &mut probs,
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
            &mut actions,
        );
        assert_eq!(
            (actions, &state),
            ([1, 3], &before),
            "nobody free: nothing runs"
        );
    }
}
