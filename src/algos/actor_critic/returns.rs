//! The macro-level returns every actor-critic learner trains its critic on (`docs/MACROMARL.md`
//! 2.6, `learner.py: _get_bootstrap_return`), in f32 with the reference's operation order.
//!
//! A squeezed sequence is one agent's (or the team's) macro-actions in an episode, k = 0..L-1,
//! each with its discounted macro-reward r_k, the environment's terminal flag at its end, and
//! gamma^(t_k) with t_k the primitive step it ended at. Its duration factor is
//! gamma^(t_k - t_(k-1)) (with t_(-1) = -1), and B_k is the target critic's value after it.

/// One squeezed sequence's inputs to the return.
#[derive(Debug, Clone, Copy)]
pub struct MacroSequence<'a> {
    /// r_k: macro-action k's discounted macro-reward.
    pub reward: &'a [f32],
    /// The environment's terminal flag at the end of macro-action k.
    pub terminate: &'a [bool],
    /// gamma^(t_k) as the reference's f32 `discount_b` holds it.
    pub discount: &'a [f32],
    /// The target critic's value after macro-action k.
    pub bootstrap: &'a [f32],
}

/// gamma^t in f32, as `torch.pow(ones * gamma, arange(T))` computes it.
pub fn discount_at(gamma: f64, t: usize) -> f32 {
    (gamma as f32).powf(t as f32)
}

/// The returns G_k of one squeezed sequence with `n_step` (`n_step_TD`; 0 and 1 are the
/// one-step return), written to `out` (same length as the sequence).
///
/// One-step: G_k = r_k + gamma^(d_k) B_k (1 - term_k). n-step: the last macro-action bootstraps
/// unless terminal; each of the last n - 1 before it takes the full return to the end,
/// r_k + gamma^(d_k) G_(k+1); every earlier one the SMDP n-step return
/// sum_(j<n) gamma^(t_(k+j-1) - t_(k-1)) r_(k+j) + gamma^(t_(k+n-1) - t_(k-1)) B_(k+n-1).
pub fn macro_returns(seq: MacroSequence<'_>, gamma: f64, n_step: usize, out: &mut [f32]) {
    let len = seq.reward.len();
    assert!(
        seq.terminate.len() == len
            && seq.discount.len() == len
            && seq.bootstrap.len() == len
            && out.len() == len,
        "macro_returns: every field has one entry per macro-action"
    );
    if len == 0 {
        return;
    }
    let inv_gamma = (1.0 / gamma) as f32;
    let before = |k: usize| {
        if k == 0 {
            inv_gamma
        } else {
            seq.discount[k - 1]
        }
    };
    // gamma^(d_k): a 0 / 0 (padding) is never formed here, so no NaN to clear.
    let mac_discount = |k: usize| seq.discount[k] / before(k);
    if n_step <= 1 {
        for (k, g) in out.iter_mut().enumerate() {
            let not_term = if seq.terminate[k] { 0.0 } else { 1.0 };
            *g = seq.reward[k] + mac_discount(k) * seq.bootstrap[k] * not_term;
        }
        return;
    }
    let end = len - 1;
    out.copy_from_slice(seq.reward);
    if !seq.terminate[end] {
        out[end] += mac_discount(end) * seq.bootstrap[end];
    }
    for k in (0..end).rev() {
        if k as i64 > end as i64 - n_step as i64 {
            out[k] += mac_discount(k) * out[k + 1];
        } else {
            let base = before(k);
            let mut g = seq.reward[k];
            for j in 1..n_step {
                g += seq.discount[k + j - 1] / base * seq.reward[k + j];
            }
            g += seq.discount[k + n_step - 1] / base * seq.bootstrap[k + n_step - 1];
            out[k] = g;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seq<'a>(
        reward: &'a [f32],
        terminate: &'a [bool],
        discount: &'a [f32],
        bootstrap: &'a [f32],
    ) -> MacroSequence<'a> {
        MacroSequence {
            reward,
            terminate,
            discount,
            bootstrap,
        }
    }

    #[test]
    fn one_step_returns_discount_by_each_duration_and_stop_at_a_terminal() {
        let g = 0.5f64;
        // Macro-actions ending at steps 1, 2 and 5: durations 2, 1, 3.
        let d: Vec<f32> = [1, 2, 5].iter().map(|&t| discount_at(g, t)).collect();
        let mut out = [0.0; 3];
        let s = seq(
            &[1.0, 2.0, 3.0],
            &[false, false, true],
            &d,
            &[10.0, 20.0, 30.0],
        );
        macro_returns(s, g, 0, &mut out);
        assert_eq!(out, [1.0 + 0.25 * 10.0, 2.0 + 0.5 * 20.0, 3.0]);
        let mut same = [0.0; 3];
        macro_returns(s, g, 1, &mut same);
        assert_eq!(out, same);
    }

    #[test]
    fn n_step_returns_are_smdp_returns_and_full_returns_near_the_end() {
        let g = 0.5f64;
        let t = [0usize, 2, 3, 6, 7];
        let d: Vec<f32> = t.iter().map(|&t| discount_at(g, t)).collect();
        let r = [1.0f32, 2.0, 3.0, 4.0, 5.0];
        let b = [10.0f32, 20.0, 30.0, 40.0, 50.0];
        let term = [false; 5];
        let mut out = [0.0; 5];
        macro_returns(seq(&r, &term, &d, &b), g, 3, &mut out);
        // Last: bootstraps over its duration 1.
        let g4 = 5.0 + 0.5 * 50.0;
        // k = 3, 2 (> end - n = 1): full returns.
        let g3 = 4.0 + 0.125 * g4;
        let g2 = 3.0 + 0.5 * g3;
        // k = 1: rewards 2, 3, 4 discounted from t_0 = 0, bootstrap B_3 after t_3 = 6.
        let g1 = 2.0 + 0.25 * 3.0 + 0.125 * 4.0 + 0.015625 * 40.0;
        // k = 0: from t_(-1) = -1.
        let g0 = 1.0 + 0.5 * 2.0 + 0.125 * 3.0 + 0.0625 * 30.0;
        let want = [g0, g1, g2, g3, g4];
        for (a, b) in out.iter().zip(want) {
            assert!((a - b).abs() < 1e-5, "{out:?} vs {want:?}");
        }
    }

    #[test]
    fn a_terminal_last_macro_action_does_not_bootstrap() {
        let d = [discount_at(0.9, 3)];
        let mut out = [0.0];
        macro_returns(seq(&[7.0], &[true], &d, &[100.0]), 0.9, 5, &mut out);
        assert_eq!(out, [7.0]);
    }
}
