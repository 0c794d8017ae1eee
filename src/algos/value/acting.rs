//! Choosing macro-actions: decentralized and centralized epsilon-greedy (`docs/ALGORITHMS.md` §4.2,
//! 4.3), and the greedy policies evaluation and deployment run (epsilon = 0, state carried).

use crate::algos::value::cond_argmax::cond_argmax;
use crate::envs::MacroEnv;
use crate::nn::joint_index::unravel;
use crate::nn::{LstmState, QNet};
use ndarray::ArrayView1;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Epsilon-greedy parameters of one selection; `None` in [`select_dec`] / [`select_cen`] means
/// greedy (evaluation, deployment).
pub struct Explore<'a> {
    /// The exploration stream.
    pub rng: &'a mut ChaCha8Rng,
    /// Probability of a uniformly random macro-action, in [0, 1].
    pub epsilon: f64,
    /// Keep the advanced hidden state (`h_explore`); without it every query starts from the
    /// episode-start zero state (`docs/ALGORITHMS.md` §4.4, quirk Q1).
    pub carry_state: bool,
}

/// Index of the first maximal value (quirk Q14: ties go to the lowest index): the crate's one
/// rule, [`crate::nn::argmax()`].
pub use crate::nn::argmax;

/// Scratch space for one acting lane, so selection allocates nothing per step.
#[derive(Debug, Clone)]
pub struct ActScratch {
    joint_obs: Vec<f32>,
    cond: Vec<i32>,
}

impl ActScratch {
    /// Scratch sized for `env`'s agents and joint observation.
    pub fn new<E: MacroEnv + ?Sized>(env: &E) -> Self {
        ActScratch {
            joint_obs: vec![0.0; env.joint_obs_size()],
            cond: vec![-1; env.n_agents()],
        }
    }
}

/// Decentralized selection (`docs/ALGORITHMS.md` §4.2): each free agent, in index order, queries its own net on its
/// own observation; busy agents keep `actions[i]` (ignored by the env) and draw nothing.
pub fn select_dec<E: MacroEnv + ?Sized>(
    env: &E,
    nets: &[&QNet],
    states: &mut [LstmState],
    mut explore: Option<Explore<'_>>,
    actions: &mut [usize],
) {
    for agent in 0..env.n_agents() {
        if !env.is_free(agent) {
            continue;
        }
        let n = env.n_actions()[agent];
        let state = &mut states[agent];
        if matches!(
            explore,
            Some(Explore {
                carry_state: false,
                ..
            })
        ) {
            state.reset();
        }
        let mut a = argmax(nets[agent].act_step(env.obs(agent), state));
        if let Some(e) = explore.as_mut() {
            if e.rng.gen::<f64>() < e.epsilon {
                a = e.rng.gen_range(0..n);
            }
        }
        actions[agent] = a;
    }
}

/// Centralized selection with the conditional argmax (`docs/ALGORITHMS.md` §4.3): if any agent is free, query the
/// centralized net on the joint observation; the greedy joint action keeps busy agents' ongoing
/// macro-actions (read from the env's executed actions); a random joint action is uniform
/// over all joint actions (quirk Q11). No agent free: nothing is queried or drawn.
pub fn select_cen<E: MacroEnv + ?Sized>(
    env: &E,
    net: &QNet,
    state: &mut LstmState,
    mut explore: Option<Explore<'_>>,
    scratch: &mut ActScratch,
    actions: &mut [usize],
) {
    let n_agents = env.n_agents();
    if !(0..n_agents).any(|i| env.is_free(i)) {
        return;
    }
    env.write_joint_obs(&mut scratch.joint_obs);
    if matches!(
        explore,
        Some(Explore {
            carry_state: false,
            ..
        })
    ) {
        state.reset();
    }
    let n_joint = env.n_joint_actions();
    for (i, c) in scratch.cond.iter_mut().enumerate() {
        *c = if env.is_free(i) {
            -1
        } else {
            env.executed()[i] as i32
        };
    }
    let q = net.act_step(&scratch.joint_obs, state);
    let mut joint = cond_argmax(ArrayView1::from(q), env.n_actions(), &scratch.cond)
        .expect("the centralized net's output matches the env's joint action space");
    if let Some(e) = explore.as_mut() {
        if e.rng.gen::<f64>() < e.epsilon {
            joint = e.rng.gen_range(0..n_joint);
        }
    }
    unravel(joint, env.n_actions(), actions);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn argmax_takes_the_first_of_equal_maxima() {
        assert_eq!(argmax(&[1.0, 3.0, 3.0, -1.0]), 1);
        assert_eq!(argmax(&[2.0]), 0);
    }
}
