//! The fully connected layer: initialization, binding to a tape, and the single-row forward used
//! when acting.

use ndarray::{ArrayViewD, Axis};
use rand_chacha::ChaCha8Rng;

use super::init::xavier_uniform;
use super::params::{copy_grad, flat, flat_mut, LinearParams};
use crate::autograd::kernels::dense::matvec_act;
use crate::autograd::{Activation, Tape, Var};

impl LinearParams {
    /// Xavier-uniform weight with `gain`, zero bias: the reference's `Linear` helper (`docs/ALGORITHMS.md` §2.2).
    pub fn xavier(input: usize, output: usize, gain: f64, rng: &mut ChaCha8Rng) -> Self {
        let mut p = LinearParams::zeros(input, output);
        p.weight = xavier_uniform(output, input, gain, rng);
        p
    }

    /// The tensors under `prefix`: `weight`, `bias`.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        vec![
            (format!("{prefix}weight"), self.weight.view().into_dyn()),
            (format!("{prefix}bias"), self.bias.view().into_dyn()),
        ]
    }

    /// Input size.
    pub fn input(&self) -> usize {
        self.weight.ncols()
    }

    /// Output size.
    pub fn output(&self) -> usize {
        self.weight.nrows()
    }

    /// Put the parameters on a tape as trainable leaves (bias as a [1, out] row).
    pub fn bind(&self, tape: &mut Tape) -> LinearVars {
        LinearVars {
            weight: tape.param(self.weight.view()),
            bias: tape.param(self.bias.view().insert_axis(Axis(0))),
        }
    }

    /// out = act(W x + b) for one input row (acting: no tape, no allocation).
    /// Panics if the lengths do not match the layer.
    pub fn forward_row(&self, x: &[f32], act: Activation, out: &mut [f32]) {
        assert_eq!(x.len(), self.input(), "linear: input length");
        assert_eq!(out.len(), self.output(), "linear: output length");
        let slope = match act {
            Activation::Identity => 1.0,
            Activation::LeakyRelu(s) => s,
        };
        matvec_act(flat(&self.weight), x, flat(&self.bias), slope, out);
    }
}

/// A linear layer's parameters on a tape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinearVars {
    /// The weight [out, in].
    pub weight: Var,
    /// The bias \[out\].
    pub bias: Var,
}

impl LinearVars {
    /// y = act(x W^T + b) for x: [rows, in].
    pub fn forward(&self, tape: &mut Tape, x: Var, act: Activation) -> Var {
        tape.linear(x, self.weight, self.bias, act)
    }

    /// Copy this layer's gradients from the tape into `into` (zero where none reached it).
    pub fn grads_into(&self, tape: &Tape, into: &mut LinearParams) {
        copy_grad(tape, self.weight, flat_mut(&mut into.weight));
        copy_grad(tape, self.bias, flat_mut(&mut into.bias));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn forward_row_matches_the_taped_layer() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut p = LinearParams::xavier(11, 5, 1.0, &mut rng);
        p.bias = ndarray::Array1::from_shape_fn(5, |i| i as f32 * 0.1 - 0.2);
        let x = ndarray::Array2::from_shape_fn((1, 11), |(_, j)| (j as f32 * 0.7).sin());
        let mut tape = Tape::new();
        let v = p.bind(&mut tape);
        let xv = tape.constant(x.view());
        let y = v.forward(&mut tape, xv, Activation::LEAKY_001);
        let mut out = [0.0; 5];
        p.forward_row(x.as_slice().unwrap(), Activation::LEAKY_001, &mut out);
        for (a, b) in out.iter().zip(tape.value(y).iter()) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }
}
