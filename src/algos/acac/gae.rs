//! ACAC's macro-level GAE (`cores/acac/learner_acac.py: _get_gae`), one episode at a time, in
//! f32 and in the reference's order of operations.
//!
//! An episode's joint macro-steps k = 0..L (squeezed where any agent's macro-action ended):
//! reward r_k, the target critic's value b_k of the joint history after step k (`bootstrap`) and
//! v_init of the first one (`initial_value`), and the discount gamma^t_k of the primitive step t_k
//! that ends step k. The discount of step k is d_k = gamma^t_k / gamma^t_(k-1) (t_(-1) = -1), i.e.
//! gamma to its duration. With the value before step k, V_0 = v_init and V_k = b_(k-1):
//!
//! ```text
//! A_(L-1) = r + d b_(L-1) - V_(L-1)    (only r - V_(L-1) when the episode terminated)
//! A_k     = r_k + d_k b_k - V_k + d_k lambda A_(k+1)
//! G_k     = A_k + V_k  for k < L-1;   G_(L-1) = A_(L-1)   (quirk below)
//! ```
//!
//! Quirk kept (ACAC-GAE-1): the reference fills the values it adds back with
//! `value[:end_step_idx] = ...`, leaving the last step's value 0, so the critic's target at an
//! episode's last joint macro-step is the advantage alone, not advantage + value.

/// Why an episode's GAE cannot be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GaeError {
    /// Inputs of different lengths.
    #[error("GAE inputs differ in length: {rewards} rewards, {bootstrap} bootstrap values, {discounts} discounts")]
    Lengths {
        /// Joint macro-steps by the rewards.
        rewards: usize,
        /// By the bootstrap values.
        bootstrap: usize,
        /// By the discounts.
        discounts: usize,
    },
    /// An episode of fewer than two joint macro-steps: the reference indexes `bootstrap[-1]`
    /// (another row's padding) and fails to assign the values unless every episode of the batch
    /// is that short; macdec refuses it instead of guessing.
    #[error("an episode of {0} joint macro-steps: ACAC's _get_gae needs at least 2")]
    TooShort(usize),
}

/// One episode's GAE inputs (see the module docs).
#[derive(Debug, Clone, Copy)]
pub struct GaeEpisode<'a> {
    /// r_k, the joint reward of each joint macro-step.
    pub rewards: &'a [f32],
    /// The target critic's (denormalised) value of the first joint history.
    pub initial_value: f32,
    /// b_k, its value after each joint macro-step.
    pub bootstrap: &'a [f32],
    /// gamma^t_k, t_k the primitive step (from 0) that ends joint macro-step k.
    pub discounts: &'a [f32],
    /// Whether the episode ended in a terminal state (otherwise cut at the horizon).
    pub terminated: bool,
}

/// The advantages A_k and critic targets G_k of one episode, before PopArt.
#[derive(Debug, Clone, PartialEq)]
pub struct Gae {
    /// A_k.
    pub advantages: Vec<f32>,
    /// G_k (the last one is A_(L-1), quirk ACAC-GAE-1).
    pub returns: Vec<f32>,
}

/// Per-step discounts d_k = gamma^t_k / gamma^t_(k-1) from the discounts gamma^t_k, with
/// gamma^t_(-1) = 1 / gamma computed as the reference does (`self.gamma**-1` in f64, as f32).
pub fn macro_discounts(discounts: &[f32], gamma: f64) -> Vec<f32> {
    let first = (1.0 / gamma) as f32;
    discounts
        .iter()
        .enumerate()
        .map(|(k, &g)| {
            let prev = if k == 0 { first } else { discounts[k - 1] };
            let d = g / prev;
            // `mac_discount[mask] = 0.0` where 0 / 0 is NaN (padding).
            if d.is_nan() {
                0.0
            } else {
                d
            }
        })
        .collect()
}

/// `_get_gae` for one episode with discount `gamma` and GAE's `lambda`.
pub fn episode_gae(e: GaeEpisode<'_>, gamma: f64, lambda: f64) -> Result<Gae, GaeError> {
    episode_gae_lambdas(e, gamma, &vec![lambda as f32; e.rewards.len()])
}

/// `_get_gae` with a lambda per joint macro-step: `acac`'s constant lambda, or
/// `acac_micro_gae`'s (`_get_gae_old`) lambda to each macro-step's duration in primitive steps,
/// lambda_k = lambda^t_k / lambda^t_(k-1), which makes the recursion per primitive step.
pub fn episode_gae_lambdas(
    e: GaeEpisode<'_>,
    gamma: f64,
    lambdas: &[f32],
) -> Result<Gae, GaeError> {
    let len = e.rewards.len();
    if e.bootstrap.len() != len || e.discounts.len() != len || lambdas.len() != len {
        return Err(GaeError::Lengths {
            rewards: len,
            bootstrap: e.bootstrap.len(),
            discounts: e.discounts.len().min(lambdas.len()),
        });
    }
    if len < 2 {
        return Err(GaeError::TooShort(len));
    }
    let d = macro_discounts(e.discounts, gamma);
    let (r, b) = (e.rewards, e.bootstrap);
    let value_before = |k: usize| if k == 0 { e.initial_value } else { b[k - 1] };
    let end = len - 1;
    let mut adv = vec![0f32; len];
    adv[end] = if e.terminated {
        r[end] - b[end - 1]
    } else {
        r[end] + d[end] * b[end] - b[end - 1]
    };
    for k in (0..end).rev() {
        let delta = r[k] + d[k] * b[k] - value_before(k);
        adv[k] = delta + d[k] * lambdas[k] * adv[k + 1];
    }
    let returns = (0..len)
        .map(|k| {
            // spec quirk ACAC-GAE-1: the last step's value is left 0.
            let v = if k < end { value_before(k) } else { 0.0 };
            adv[k] + v
        })
        .collect();
    Ok(Gae {
        advantages: adv,
        returns,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn macro_discounts_are_gamma_to_each_steps_duration() {
        // Joint steps ending at primitive steps 1, 2, 5: durations 2, 1, 3.
        let g = 0.5f64;
        let disc: Vec<f32> = [1, 2, 5].iter().map(|&t| 0.5f32.powi(t)).collect();
        assert_eq!(macro_discounts(&disc, g), vec![0.25, 0.5, 0.125]);
        // Padding (0 / 0) becomes 0, not NaN.
        assert_eq!(macro_discounts(&[0.5, 0.0, 0.0], g), vec![0.25, 0.0, 0.0]);
    }

    #[test]
    fn a_hand_computed_episode() {
        // gamma 0.5, lambda 0.5; steps end at primitive steps 0, 1, 3 -> d = 0.5, 0.5, 0.25.
        // v_init 1, b = [2, 4, 8], r = [1, 2, 3], cut at the horizon (bootstrap at the end).
        // A_2 = 3 + 0.25 * 8 - 4 = 1
        // A_1 = 2 + 0.5 * 4 - 2 + 0.5 * 0.5 * 1 = 2.25
        // A_0 = 1 + 0.5 * 2 - 1 + 0.25 * 2.25 = 1.5625
        // G = [A_0 + 1, A_1 + 2, A_2 + 0 (quirk)] = [2.5625, 4.25, 1]
        let e = GaeEpisode {
            rewards: &[1.0, 2.0, 3.0],
            initial_value: 1.0,
            bootstrap: &[2.0, 4.0, 8.0],
            discounts: &[1.0, 0.5, 0.125],
            terminated: false,
        };
        let g = episode_gae(e, 0.5, 0.5).unwrap();
        assert_eq!(g.advantages, vec![1.5625, 2.25, 1.0]);
        assert_eq!(g.returns, vec![2.5625, 4.25, 1.0]);
        // Terminated: A_2 = 3 - 4 = -1; A_1 = 2 - 0.25 = 1.75; A_0 = 1 + 0.4375 = 1.4375.
        let t = episode_gae(
            GaeEpisode {
                terminated: true,
                ..e
            },
            0.5,
            0.5,
        )
        .unwrap();
        assert_eq!(t.advantages, vec![1.4375, 1.75, -1.0]);
        assert_eq!(t.returns, vec![2.4375, 3.75, -1.0]);
    }

    #[test]
    fn advantages_are_discounted_sums_of_td_errors() {
        // The unfused definition as oracle: A_k = sum_j>=k (prod_(k<=i<j) d_i lambda) delta_j.
        let (gamma, lambda) = (0.95, 0.9);
        let ends = [2, 3, 7, 8, 12, 19];
        let disc: Vec<f32> = ends.iter().map(|&t| (gamma as f32).powi(t)).collect();
        let rewards = [0.5f32, -1.0, 2.0, 0.0, 3.0, -0.5];
        let boot = [0.3f32, 0.1, -0.4, 0.9, 1.1, 0.2];
        let v0 = 0.7f32;
        let e = GaeEpisode {
            rewards: &rewards,
            initial_value: v0,
            bootstrap: &boot,
            discounts: &disc,
            terminated: false,
        };
        let got = episode_gae(e, gamma, lambda).unwrap();
        let d = macro_discounts(&disc, gamma);
        let n = rewards.len();
        let delta: Vec<f64> = (0..n)
            .map(|k| {
                let before = if k == 0 { v0 } else { boot[k - 1] };
                rewards[k] as f64 + d[k] as f64 * boot[k] as f64 - before as f64
            })
            .collect();
        for k in 0..n {
            let (mut want, mut w) = (0.0f64, 1.0f64);
            for j in k..n {
                want += w * delta[j];
                w *= d[j] as f64 * lambda;
            }
            assert!(
                (got.advantages[k] as f64 - want).abs() < 1e-5,
                "A_{k}: {} vs {want}",
                got.advantages[k]
            );
        }
    }

    #[test]
    fn micro_gae_raises_lambda_to_each_steps_duration() {
        // gamma 0.5, lambda 0.5; steps end at primitive steps 0, 1, 3 -> d = 0.5, 0.5, 0.25 and
        // micro lambdas 0.5, 0.5, 0.25 (durations 1, 1, 2). v_init 1, b = [2, 4, 8], r = [1, 2, 3].
        // A_2 = 3 + 0.25 * 8 - 4 = 1
        // A_1 = 2 + 0.5 * 4 - 2 + 0.5 * 0.5 * 1 = 2.25
        // A_0 = 1 + 0.5 * 2 - 1 + 0.5 * 0.5 * 2.25 = 1.5625
        // With durations 1 the micro form equals the macro one; make step 1 last 2 steps:
        // ends 0, 2, 3 -> d = 0.5, 0.25, 0.5, lambdas 0.5, 0.25, 0.5.
        // A_2 = 3 + 0.5 * 8 - 4 = 3
        // A_1 = 2 + 0.25 * 4 - 2 + 0.25 * 0.25 * 3 = 1.1875
        // A_0 = 1 + 0.5 * 2 - 1 + 0.5 * 0.5 * 1.1875 = 1.296875
        let e = GaeEpisode {
            rewards: &[1.0, 2.0, 3.0],
            initial_value: 1.0,
            bootstrap: &[2.0, 4.0, 8.0],
            discounts: &[1.0, 0.25, 0.125],
            terminated: false,
        };
        let g = episode_gae_lambdas(e, 0.5, &[0.5, 0.25, 0.5]).unwrap();
        assert_eq!(g.advantages, vec![1.296875, 1.1875, 3.0]);
        // The macro form on the same episode uses 0.5 at step 1: A_1 = 1 + 0.125 * 3 = 1.375.
        let m = episode_gae(e, 0.5, 0.5).unwrap();
        assert_eq!(m.advantages[1], 1.375);
        assert!(matches!(
            episode_gae_lambdas(e, 0.5, &[0.5]),
            Err(GaeError::Lengths { .. })
        ));
    }

    #[test]
    fn short_or_mismatched_episodes_are_refused() {
        let one = GaeEpisode {
            rewards: &[1.0],
            initial_value: 0.0,
            bootstrap: &[0.0],
            discounts: &[1.0],
            terminated: true,
        };
        assert_eq!(episode_gae(one, 0.9, 0.9), Err(GaeError::TooShort(1)));
        let bad = GaeEpisode {
            bootstrap: &[0.0, 1.0],
            ..one
        };
        assert!(matches!(
            episode_gae(bad, 0.9, 0.9),
            Err(GaeError::Lengths { .. })
        ));
    }
}
