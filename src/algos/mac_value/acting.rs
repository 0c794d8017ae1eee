//! How MacroMARL's value-based teams pick macro-actions (`team.py: get_next_actions`,
//! `team_cen_condi.py: get_next_actions`, `docs/MACROMARL.md` §8.2): only when an agent (MacDec-Q)
//! or any agent (MacCen-Q) is free; greedy on the masked (MacCen-Q: conditional) argmax of the
//! Q-values; while training, with probability epsilon a uniformly random available macro-action
//! (MacCen-Q: joint macro-action) instead. The recurrent state advances only when the net is
//! queried; whether it is carried between decisions is the caller's (`h_explore`).

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::choice::{conditional_argmax, masked_argmax, Dims};
use super::episode::{all_available, joint_obs};
use super::update::QNet;
use crate::envs::MacroEnv;
use crate::nn::joint_index::{for_each_allowed, unravel};
use crate::nn::GruActorState;

/// Exploration while training: epsilon and its random stream.
pub struct Explore<'a> {
    /// The probability of a random macro-action.
    pub epsilon: f64,
    /// The draws.
    pub rng: &'a mut ChaCha8Rng,
}

/// A uniformly random index among those `avail` marks available (`np.random.choice(p=avail /
/// sum)`); 0 if none is.
fn random_available(avail: &[f32], rng: &mut ChaCha8Rng) -> usize {
    let open: Vec<usize> = (0..avail.len()).filter(|&a| avail[a] != 0.0).collect();
    if open.is_empty() {
        return 0;
    }
    open[rng.gen_range(0..open.len())]
}

/// MacDec-Q: each free agent's macro-action into `actions` (busy agents' entries are left).
/// `states[i]` is agent i's recurrent state, advanced when it is queried.
pub fn act_dec<E: MacroEnv>(
    nets: &[QNet],
    states: &mut [GruActorState],
    env: &E,
    dims: &Dims,
    mut explore: Option<Explore<'_>>,
    actions: &mut [usize],
) {
    let avail = all_available(env);
    let mut offset = 0;
    for (i, (q, state)) in nets.iter().zip(states.iter_mut()).enumerate() {
        let mask = &avail[offset..offset + dims.n_actions[i]];
        offset += dims.n_actions[i];
        if !env.is_free(i) {
            continue;
        }
        let mut a = masked_argmax(q.net.q_step(env.obs(i), state), mask);
        if let Some(e) = explore.as_mut() {
            if e.rng.gen::<f64>() < e.epsilon {
                a = random_available(mask, e.rng);
            }
        }
        actions[i] = a;
    }
}

/// MacCen-Q: when any agent is free, the joint macro-action conditioned on the busy agents'
/// running ones, unravelled into `actions` (busy agents' entries are ignored by the env).
pub fn act_cen<E: MacroEnv>(
    q: &QNet,
    state: &mut GruActorState,
    env: &E,
    dims: &Dims,
    mut explore: Option<Explore<'_>>,
    actions: &mut [usize],
) {
    let n = env.n_agents();
    if !(0..n).any(|i| env.is_free(i)) {
        return;
    }
    let running: Vec<Option<usize>> = (0..n)
        .map(|i| (!env.is_free(i)).then(|| env.executed()[i]))
        .collect();
    let avail = all_available(env);
    let values = q.net.q_step(&joint_obs(env), state);
    let mut joint = conditional_argmax(values, &running, &avail, dims);
    if let Some(e) = explore.as_mut() {
        if e.rng.gen::<f64>() < e.epsilon {
            // Uniform over every available joint macro-action, not conditioned (the reference's
            // exploration; the env then ignores the busy agents' components).
            let mut joint_avail = vec![0.0f32; dims.n_joint()];
            for_each_allowed(&dims.n_actions, |_| None, Some(&avail), &mut |j| {
                joint_avail[j] = 1.0
            });
            joint = random_available(&joint_avail, e.rng);
        }
    }
    unravel(joint, &dims.n_actions, actions);
}
