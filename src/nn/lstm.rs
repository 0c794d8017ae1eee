//! The LSTM layer: PyTorch's default initialization, binding to a tape, and the one-step update
//! with a carried (h, c) used when acting.

use serde::{Deserialize, Serialize};

use super::params::{flat, LstmParams};
use crate::autograd::kernels::activations::{sigmoid_inplace, tanh_inplace, tanh_into};
use crate::autograd::kernels::dense::lstm_gates_row;
use crate::autograd::{LstmVars, Tape};

impl LstmParams {
    /// Put the parameters on a tape as trainable leaves.
    pub fn bind(&self, tape: &mut Tape) -> LstmVars {
        let [w_ih, w_hh, b_ih, b_hh] = self.leaves(tape);
        LstmVars {
            w_ih,
            w_hh,
            b_ih,
            b_hh,
        }
    }

    /// Advance `state` by one input row x (acting: no tape, no allocation); the new h is in
    /// `state.h()`. Panics if the sizes do not match.
    pub fn step(&self, x: &[f32], state: &mut LstmState) {
        let h = self.hidden();
        assert_eq!(x.len(), self.weight_ih.ncols(), "lstm step: input length");
        assert_eq!(
            state.h.len(),
            h,
            "lstm step: state was made for another hidden size"
        );
        state.gates.resize(4 * h, 0.0);
        let (w_ih, w_hh) = (flat(&self.weight_ih), flat(&self.weight_hh));
        let (b_ih, b_hh) = (flat(&self.bias_ih), flat(&self.bias_hh));
        lstm_gates_row(w_ih, x, w_hh, &state.h, b_ih, b_hh, &mut state.gates);
        let g = &mut state.gates;
        sigmoid_inplace(&mut g[..2 * h]);
        tanh_inplace(&mut g[2 * h..3 * h]);
        sigmoid_inplace(&mut g[3 * h..]);
        for q in 0..h {
            state.c[q] = g[h + q] * state.c[q] + g[q] * g[2 * h + q];
        }
        tanh_into(&state.c, &mut state.h);
        for q in 0..h {
            state.h[q] *= g[3 * h + q];
        }
    }
}

/// An LSTM's recurrent state (h, c), zero at the start of each episode (`docs/ALGORITHMS.md` §2.3), plus the
/// scratch the acting forward writes into so that acting never allocates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LstmState {
    h: Vec<f32>,
    c: Vec<f32>,
    #[serde(skip)]
    gates: Vec<f32>,
    #[serde(skip)]
    pub(crate) scratch: [Vec<f32>; 4],
}

impl LstmState {
    /// The zero state of an LSTM with hidden size `hidden`.
    pub fn zeros(hidden: usize) -> Self {
        LstmState {
            h: vec![0.0; hidden],
            c: vec![0.0; hidden],
            gates: vec![0.0; 4 * hidden],
            scratch: Default::default(),
        }
    }

    /// Back to the zero state (PyTorch's `None` hidden state).
    pub fn reset(&mut self) {
        self.h.fill(0.0);
        self.c.fill(0.0);
    }

    /// Copy another state of the same size (e.g. keep a candidate state), without allocating.
    pub fn copy_from(&mut self, other: &LstmState) {
        self.h.copy_from_slice(&other.h);
        self.c.copy_from_slice(&other.c);
    }

    /// The hidden output h.
    pub fn h(&self) -> &[f32] {
        &self.h
    }

    /// The cell state c.
    pub fn c(&self) -> &[f32] {
        &self.c
    }
}

impl LstmVars {
    /// Copy the LSTM's gradients from the tape into `into` (zero where none reached it).
    pub fn grads_into(&self, tape: &Tape, into: &mut LstmParams) {
        into.copy_grads(tape, [self.w_ih, self.w_hh, self.b_ih, self.b_hh]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::autograd::SeqPacking;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn stepping_matches_the_sequence_op() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let p = LstmParams::pytorch_default(3, 5, &mut rng);
        let x = super::super::init::uniform2(6, 3, 1.0, &mut rng);
        let mut tape = Tape::new();
        let v = p.bind(&mut tape);
        let xv = tape.constant(x.view());
        let y = tape.lstm(xv, v, &SeqPacking::new(&[6]));
        let mut state = LstmState::zeros(5);
        for t in 0..6 {
            p.step(x.row(t).as_slice().unwrap(), &mut state);
            for (a, b) in state.h().iter().zip(tape.value(y).row(t).iter()) {
                assert!((a - b).abs() < 1e-6, "step {t}: {a} vs {b}");
            }
        }
        state.reset();
        assert!(state.h().iter().chain(state.c()).all(|&v| v == 0.0));
    }

    #[test]
    fn default_init_stays_within_one_over_sqrt_hidden() {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let p = LstmParams::pytorch_default(8, 16, &mut rng);
        let k = 0.25;
        for a in [&p.weight_ih, &p.weight_hh] {
            assert!(a.iter().all(|v| v.abs() <= k));
        }
        assert!(p
            .bias_ih
            .iter()
            .chain(p.bias_hh.iter())
            .all(|v| v.abs() <= k));
        assert!(p.weight_hh.iter().any(|v| v.abs() > 0.9 * k));
    }
}
