//! The TD loss every learner minimizes (`docs/ALGORITHMS.md` §5), built on the tape.

use ndarray::{ArrayView1, Axis};

use crate::autograd::{Tape, Var};

/// mean_k ( max(h d_k, d_k) )^2 with d_k = y_k - Q[k, a_k] (`docs/ALGORITHMS.md` §5, quirk Q4); h = 1 gives the
/// plain MSE. q: [K, n_actions] on the tape, `actions` and the constant targets `y`: K entries.
/// The transform max(h d, d) for h <= 1 is a leaky ReLU with slope h.
/// Panics if the lengths differ from q's rows or an action is out of range.
pub fn hysteretic_td_loss(
    tape: &mut Tape,
    q: Var,
    actions: &[usize],
    y: ArrayView1<f32>,
    h: f32,
) -> Var {
    let q_taken = tape.gather_cols(q, actions);
    hysteretic_td_loss_taken(tape, q_taken, y, h)
}

/// [`hysteretic_td_loss`] given the values of the actions taken, q_taken: [K, 1].
pub fn hysteretic_td_loss_taken(tape: &mut Tape, q_taken: Var, y: ArrayView1<f32>, h: f32) -> Var {
    let y = tape.constant(y.insert_axis(Axis(1)));
    let delta = tape.sub(y, q_taken);
    let delta = if h == 1.0 {
        delta
    } else {
        tape.leaky_relu(delta, h)
    };
    let sq = tape.square(delta);
    tape.mean(sq)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_errors_are_scaled_by_h_before_squaring() {
        let mut t = Tape::new();
        let q = t.param(ndarray::arr2(&[[1.0f32, 5.0], [2.0, 0.0]]).view());
        let y = ndarray::arr1(&[3.0f32, 1.0]);
        let loss = hysteretic_td_loss(&mut t, q, &[1, 0], y.view(), 0.5);
        // d = [3 - 5, 1 - 2] = [-2, -1] -> [-1, -0.5]; mean of squares = (1 + 0.25) / 2
        assert_eq!(t.scalar(loss), 0.625);
        t.backward(loss);
        // dL/dQ[k, a_k] = -2 h d'_k / K = [-2 * 0.5 * -1 / 2, -2 * 0.5 * -0.5 / 2] = [0.5, 0.25]
        assert_eq!(
            t.grad(q).unwrap(),
            ndarray::arr2(&[[0.0f32, 0.5], [0.25, 0.0]])
        );
    }
}
