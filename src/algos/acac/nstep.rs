//! `acac-vanilla`'s critic targets: n-step bootstrapped returns over an episode's joint
//! macro-steps (`cores/acac/learner_acac_vanilla.py: _get_bootstrap_return`), one episode at a
//! time, in f32 and in the reference's order of operations.
//!
//! With the joint macro-steps k = 0..L of [`super::gae`] (reward r_k, the target critic's value
//! b_k after step k, discounts D_k = gamma^t_k, d_k = D_k / D_(k-1) with D_(-1) = 1 / gamma) and
//! n = `n_step_TD`, end = L - 1:
//!
//! ```text
//! n <= 1:          G_k = r_k + d_k b_k            (no bootstrap at a terminal end)
//! otherwise:       G_end = r_end + d_end b_end     (r_end alone at a terminal end)
//!   k > end - n:   G_k = r_k + d_k G_(k+1)
//!   else:          G_k = r_k + sum_(m=1..n-1) (D_(k+m-1) / D_(k-1)) r_(k+m)
//!                            + (D_(k+n-1) / D_(k-1)) b_(k+n-1)
//! ```
//!
//! Quirks kept (they are the published method): the recursion near the end weighs G_(k+1) by
//! d_k, gamma to step k's own duration, not to the next step's; the n-step sum weighs reward
//! r_(k+m) by gamma to the primitive steps from step k's start to step (k+m-1)'s end.

use super::gae::macro_discounts;

/// The n-step returns G_k of one episode (see the module docs). `rewards`, `bootstrap` and
/// `discounts` have one entry per joint macro-step; an empty episode has no returns.
pub fn episode_n_step_returns(
    rewards: &[f32],
    bootstrap: &[f32],
    discounts: &[f32],
    terminated: bool,
    gamma: f64,
    n_step: usize,
) -> Vec<f32> {
    let l = rewards.len();
    assert!(
        bootstrap.len() == l && discounts.len() == l,
        "n-step returns: {l} rewards, {} bootstrap values, {} discounts",
        bootstrap.len(),
        discounts.len()
    );
    if l == 0 {
        return Vec::new();
    }
    let d = macro_discounts(discounts, gamma);
    let end = l - 1;
    if n_step <= 1 {
        return (0..l)
            .map(|k| {
                let live = if k == end && terminated { 0.0 } else { 1.0 };
                rewards[k] + d[k] * bootstrap[k] * live
            })
            .collect();
    }
    let first = (1.0 / gamma) as f32;
    let mut g = rewards.to_vec();
    if !terminated {
        g[end] += d[end] * bootstrap[end];
    }
    for k in (0..end).rev() {
        if k + n_step > end {
            g[k] = rewards[k] + d[k] * g[k + 1];
        } else {
            // [1, D_k / D_(k-1), ..., D_(k+n-1) / D_(k-1)] . [r_k, ..., r_(k+n-1), b_(k+n-1)]
            let before = if k == 0 { first } else { discounts[k - 1] };
            let mut sum = rewards[k];
            for m in 1..n_step {
                sum += (discounts[k + m - 1] / before) * rewards[k + m];
            }
            sum += (discounts[k + n_step - 1] / before) * bootstrap[k + n_step - 1];
            g[k] = sum;
        }
    }
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    const GAMMA: f64 = 0.9;

    fn pow(t: i32) -> f32 {
        (GAMMA as f32).powi(t)
    }

    #[test]
    fn one_step_returns_bootstrap_every_step_but_a_terminal_end() {
        // Ends at primitive steps 1, 2, 5: durations 2, 1, 3.
        let (r, b, disc) = (
            [1.0, 2.0, 3.0],
            [10.0, 20.0, 30.0],
            [pow(1), pow(2), pow(5)],
        );
        let g = episode_n_step_returns(&r, &b, &disc, true, GAMMA, 1);
        let want = [1.0 + pow(2) * 10.0, 2.0 + pow(1) * 20.0, 3.0];
        for (a, w) in g.iter().zip(want) {
            assert!((a - w).abs() < 1e-5, "{g:?} vs {want:?}");
        }
        let cut = episode_n_step_returns(&r, &b, &disc, false, GAMMA, 0);
        assert!((cut[2] - (3.0 + pow(3) * 30.0)).abs() < 1e-4);
    }

    #[test]
    fn n_step_returns_follow_the_reference_by_hand() {
        // Six joint macro-steps ending at primitive steps 0, 2, 3, 6, 7, 9; n = 3.
        let ends = [0, 2, 3, 6, 7, 9];
        let disc: Vec<f32> = ends.iter().map(|&t| pow(t)).collect();
        let r = [1.0, -2.0, 0.5, 4.0, -1.0, 3.0];
        let b = [5.0, 6.0, 7.0, 8.0, 9.0, 10.0];
        let g = episode_n_step_returns(&r, &b, &disc, false, GAMMA, 3);
        let dur = |k: usize| if k == 0 { 1 } else { ends[k] - ends[k - 1] };
        let mut want = [0f32; 6];
        want[5] = r[5] + pow(dur(5)) * b[5];
        // end - n = 2: k = 4, 3 recurse with their own duration.
        want[4] = r[4] + pow(dur(4)) * want[5];
        want[3] = r[3] + pow(dur(3)) * want[4];
        // k = 2, 1, 0: three terms from step k's start (D_(k-1), D_(-1) = 1 / gamma).
        for k in [2usize, 1, 0] {
            let start = if k == 0 { -1 } else { ends[k - 1] };
            let w = |j: usize| pow(ends[j] - start);
            want[k] = r[k] + w(k) * r[k + 1] + w(k + 1) * r[k + 2] + w(k + 2) * b[k + 2];
        }
        for (k, (a, w)) in g.iter().zip(want).enumerate() {
            assert!((a - w).abs() < 1e-4, "G_{k}: {a} vs {w}");
        }
        // A terminal end drops the last bootstrap, and with it every recursion's share.
        let t = episode_n_step_returns(&r, &b, &disc, true, GAMMA, 3);
        assert!((t[5] - r[5]).abs() < 1e-6);
        assert!(
            (t[0] - g[0]).abs() < 1e-6,
            "the n-step sum at k = 0 ignores the end"
        );
        assert!((t[4] - (r[4] + pow(dur(4)) * r[5])).abs() < 1e-5);
    }

    #[test]
    fn short_episodes_recurse_without_the_n_step_sum() {
        let g = episode_n_step_returns(&[1.0], &[4.0], &[pow(3)], false, GAMMA, 5);
        assert!((g[0] - (1.0 + pow(4) * 4.0)).abs() < 1e-5);
        assert!(episode_n_step_returns(&[], &[], &[], true, GAMMA, 5).is_empty());
    }
}
