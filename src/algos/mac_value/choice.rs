//! Greedy macro-action choices over the records' layout: an agent's best available
//! macro-action ([`masked_argmax`], MacDec-Q's a' and acting) and the centralized net's best joint
//! macro-action given the agents still running theirs ([`conditional_argmax`], MacCen-Q's), with
//! the sizes the records are laid out by ([`Dims`]). Acting, squeezing and the update all read
//! these, so they live apart from each of them.

use serde::{Deserialize, Serialize};

use crate::nn::argmax::{first_argmax, FirstArgmax};
use crate::nn::joint_index::for_each_allowed;

/// The sizes the records are laid out by.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Dims {
    /// Each agent's observation length.
    pub obs_sizes: Vec<usize>,
    /// Each agent's macro-action count.
    pub n_actions: Vec<usize>,
}

impl Dims {
    pub(super) fn obs_range(&self, agent: usize) -> std::ops::Range<usize> {
        let lo: usize = self.obs_sizes[..agent].iter().sum();
        lo..lo + self.obs_sizes[agent]
    }

    pub(super) fn action_range(&self, agent: usize) -> std::ops::Range<usize> {
        let lo: usize = self.n_actions[..agent].iter().sum();
        lo..lo + self.n_actions[agent]
    }

    /// Joint macro-actions (C order, agent 0 most significant).
    pub fn n_joint(&self) -> usize {
        self.n_actions.iter().product()
    }
}

/// The joint macro-action maximizing `q` among those whose every component is available in
/// `avail` (per-agent masks, concatenated) and equals `running[i]` where that is `Some` (an agent
/// still executing its macro-action): the reference's `get_conditional_argmax`, first maximal
/// index in C order; 0 when none qualifies (all -inf in the reference).
///
/// The last agent's actions are consecutive indices, so each choice of the other agents'
/// components gives one contiguous block of `q`; each block's winner (`block_argmax`) is offered
/// in order. That is the choice offering every allowed index in order makes (a block's winner is
/// its first largest non-NaN value, or its first entry when all are NaN), with no branch per
/// index.
pub fn conditional_argmax(
    q: &[f32],
    running: &[Option<usize>],
    avail: &[f32],
    dims: &Dims,
) -> usize {
    let Some(last) = dims.n_actions.len().checked_sub(1) else {
        // One joint macro-action, of no components.
        return 0;
    };
    let n = dims.n_actions[last];
    let mask = &avail[dims.action_range(last)];
    let mut best = FirstArgmax::default();
    // Every allowed choice of the agents before the last, then the last one's block at once.
    for_each_allowed(
        &dims.n_actions[..last],
        |i| running[i],
        Some(avail),
        &mut |prefix| {
            let block = &q[prefix * n..(prefix + 1) * n];
            let winner = match running[last] {
                Some(r) => (r < n && mask[r] != 0.0).then_some(r),
                None => block_argmax(block, mask),
            };
            if let Some(a) = winner {
                best.offer(prefix * n + a, block[a]);
            }
        },
    );
    best.index().unwrap_or(0)
}

/// The first index of the largest value of `q` among those where `mask` is nonzero, a NaN losing
/// to any number, or the first such index when all are NaN; `None` when the mask allows none.
/// The choice of offering the allowed entries to [`FirstArgmax`] in order, found as the maximum
/// (`f32::max` skips NaN) and then its first position (`==` also equates -0 and +0, which the
/// strict `>` never lets replace each other).
fn block_argmax(q: &[f32], mask: &[f32]) -> Option<usize> {
    let mut top = f32::NAN;
    for (&v, &ok) in q.iter().zip(mask) {
        top = top.max(if ok != 0.0 { v } else { f32::NAN });
    }
    if top.is_nan() {
        return mask.iter().position(|&ok| ok != 0.0);
    }
    q.iter()
        .zip(mask)
        .position(|(&v, &ok)| ok != 0.0 && v == top)
}

/// The available macro-action with the largest value (`get_masked_Q` then `max`); 0 when none is.
pub fn masked_argmax(q: &[f32], avail: &[f32]) -> usize {
    first_argmax(
        q.iter()
            .copied()
            .enumerate()
            .filter(|&(a, _)| avail[a] != 0.0),
    )
    .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::joint_index::unravel_component;

    #[test]
    fn joint_indices_are_c_order_and_the_conditional_argmax_keeps_running_actions() {
        let dims = Dims {
            obs_sizes: vec![1, 1],
            n_actions: vec![2, 3],
        };
        let q = [0.0, 9.0, 1.0, 2.0, 3.0, 8.0];
        let all = [1.0; 5];
        assert_eq!(conditional_argmax(&q, &[None, None], &all, &dims), 1);
        // Agent 0 still runs action 1: only joint 3, 4, 5 qualify.
        assert_eq!(conditional_argmax(&q, &[Some(1), None], &all, &dims), 5);
        // Agent 1's action 2 unavailable.
        let avail = [1.0, 1.0, 1.0, 1.0, 0.0];
        assert_eq!(conditional_argmax(&q, &[Some(1), None], &avail, &dims), 4);
        assert_eq!(masked_argmax(&[1.0, 5.0, 3.0], &[1.0, 0.0, 1.0]), 2);
    }

    #[test]
    fn the_conditional_argmax_is_the_first_maximum_over_the_allowed_joint_indices() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let dims = Dims {
            obs_sizes: vec![1, 1, 1],
            n_actions: vec![3, 2, 4],
        };
        for _ in 0..2000 {
            // Few distinct values (ties, zeros of both signs, infinities), some NaN, masks and
            // running actions at random.
            let q: Vec<f32> = (0..dims.n_joint())
                .map(|_| match rng.gen_range(0..11) {
                    0 => f32::NAN,
                    1 => -0.0,
                    2 => 0.0,
                    3 => f32::NEG_INFINITY,
                    4 => f32::INFINITY,
                    k => k as f32,
                })
                .collect();
            let avail: Vec<f32> = (0..9).map(|_| rng.gen_range(0..4).min(1) as f32).collect();
            let running: Vec<Option<usize>> = dims
                .n_actions
                .iter()
                .map(|&n| rng.gen_bool(0.3).then(|| rng.gen_range(0..n)))
                .collect();
            // The definition: every joint index, filtered, in order.
            let allowed = |j: usize| {
                (0..3)
                    .map(|i| unravel_component(j, &dims.n_actions, i))
                    .enumerate()
                    .all(|(i, a)| {
                        avail[dims.action_range(i)][a] != 0.0 && running[i].is_none_or(|r| r == a)
                    })
            };
            let want = first_argmax(q.iter().copied().enumerate().filter(|&(j, _)| allowed(j)))
                .unwrap_or(0);
            assert_eq!(conditional_argmax(&q, &running, &avail, &dims), want);
        }
    }
}
