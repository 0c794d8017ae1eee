//! The fully connected layer: initialization, binding to a tape, and the single-row forward used
//! when acting.

use ndarray::Axis;
use rand_chacha::ChaCha8Rng;

use super::init::xavier_uniform;
use super::params::{flat, flat_mut, LinearParams};
use crate::autograd::{Activation, Tape, Var};

impl LinearParams {
    /// Xavier-uniform weight with `gain`, zero bias: the reference's `Linear` helper (spec 2.2).
    pub fn xavier(input: usize, output: usize, gain: f64, rng: &mut ChaCha8Rng) -> Self {
        let mut p = LinearParams::zeros(input, output);
        p.weight = xavier_uniform(output, input, gain, rng);
        p
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
        let w = flat(&self.weight);
        let b = flat(&self.bias);
        for (o, (row, &b)) in out.iter_mut().zip(w.chunks_exact(x.len()).zip(b)) {
            *o = act.apply(dot(row, x) + b);
        }
    }
}

/// A linear layer's parameters on a tape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LinearVars {
    pub weight: Var,
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

/// dst = the gradient of `v` (flattened), or zeros if none reached it.
pub(crate) fn copy_grad(tape: &Tape, v: Var, dst: &mut [f32]) {
    match tape.grad(v) {
        Some(g) => {
            assert_eq!(
                g.len(),
                dst.len(),
                "gradient size differs from the parameter's"
            );
            for (d, &g) in dst.iter_mut().zip(g.iter()) {
                *d = g;
            }
        }
        None => dst.fill(0.0),
    }
}

/// Dot product with 8 independent partial sums, so it vectorizes (a fixed order: deterministic).
#[inline]
pub(crate) fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0.0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for i in 0..8 {
            acc[i] += x[i] * y[i];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
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

    #[test]
    fn dot_handles_lengths_that_are_not_multiples_of_eight() {
        let a: Vec<f32> = (0..13).map(|i| i as f32).collect();
        let b = vec![1.0f32; 13];
        assert_eq!(dot(&a, &b), 78.0);
    }
}
