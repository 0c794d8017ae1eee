//! Parameter containers: named tensors with PyTorch's state_dict names, and the [`Params`] view
//! Adam and the checkpoint code work through.

use ndarray::{Array1, Array2, Axis};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::init::{uniform1, uniform2};
use crate::autograd::{Tape, Var};

/// A set of parameter tensors seen as flat slices in a fixed order (Adam steps over them; a
/// gradient set of the same type lines up entry by entry).
pub trait Params {
    /// Every tensor's elements, in the fixed order.
    fn slices(&self) -> Vec<&[f32]>;
    /// The same, mutable.
    fn slices_mut(&mut self) -> Vec<&mut [f32]>;

    /// Overwrite with `other`'s values (the same sizes): a hard target copy, no allocation.
    /// Panics if a tensor's size differs.
    fn copy_values_from(&mut self, other: &Self) {
        for (d, s) in self.slices_mut().into_iter().zip(other.slices()) {
            d.copy_from_slice(s);
        }
    }

    /// Whether every element is finite.
    fn all_finite(&self) -> bool {
        self.slices()
            .iter()
            .all(|s| s.iter().all(|v| v.is_finite()))
    }
}

/// A fully connected layer's parameters (PyTorch `nn.Linear`): weight [out, in], bias \[out\].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearParams {
    /// [out, in].
    pub weight: Array2<f32>,
    /// \[out\].
    pub bias: Array1<f32>,
}

impl LinearParams {
    /// All-zero parameters of a layer from `input` to `output` features.
    pub fn zeros(input: usize, output: usize) -> Self {
        LinearParams {
            weight: Array2::zeros((output, input)),
            bias: Array1::zeros(output),
        }
    }
}

/// A one-layer recurrent layer's parameters in PyTorch's layout, with `GATES` gate blocks
/// stacked along the first axis: weight_ih [GATES·H, in], weight_hh [GATES·H, H], bias_ih and
/// bias_hh [GATES·H]. [`LstmParams`] and [`GruParams`] are its two instances; what differs
/// between them (the cell, the tape op, the state_dict names) lives in `nn/lstm.rs` and
/// `nn/gru.rs`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecurrentParams<const GATES: usize> {
    pub weight_ih: Array2<f32>,
    pub weight_hh: Array2<f32>,
    pub bias_ih: Array1<f32>,
    pub bias_hh: Array1<f32>,
}

/// A one-layer LSTM's parameters (PyTorch `nn.LSTM`, gate order i, f, g, o):
/// weight_ih [4H, in], weight_hh [4H, H], bias_ih \[4H\], bias_hh \[4H\].
pub type LstmParams = RecurrentParams<4>;

/// A one-layer GRU's parameters (PyTorch `nn.GRU`, gate order r, z, n):
/// weight_ih [3H, in], weight_hh [3H, H], bias_ih \[3H\], bias_hh \[3H\].
pub type GruParams = RecurrentParams<3>;

impl<const GATES: usize> RecurrentParams<GATES> {
    /// All-zero parameters for `input` features and hidden size `hidden` (a gradient buffer).
    pub fn zeros(input: usize, hidden: usize) -> Self {
        RecurrentParams {
            weight_ih: Array2::zeros((GATES * hidden, input)),
            weight_hh: Array2::zeros((GATES * hidden, hidden)),
            bias_ih: Array1::zeros(GATES * hidden),
            bias_hh: Array1::zeros(GATES * hidden),
        }
    }

    /// PyTorch's default: every weight and both biases U(-1/sqrt(H), 1/sqrt(H)), drawn in the
    /// order weight_ih, weight_hh, bias_ih, bias_hh (the module's parameter order; `docs/ALGORITHMS.md` §2.2).
    pub fn pytorch_default(input: usize, hidden: usize, rng: &mut ChaCha8Rng) -> Self {
        let k = 1.0 / (hidden as f32).sqrt();
        RecurrentParams {
            weight_ih: uniform2(GATES * hidden, input, k, rng),
            weight_hh: uniform2(GATES * hidden, hidden, k, rng),
            bias_ih: uniform1(GATES * hidden, k, rng),
            bias_hh: uniform1(GATES * hidden, k, rng),
        }
    }

    /// Hidden size H.
    pub fn hidden(&self) -> usize {
        self.weight_hh.ncols()
    }

    /// Input size.
    pub fn input(&self) -> usize {
        self.weight_ih.ncols()
    }

    /// The four tensors on a tape as trainable leaves, biases as [1, GATES·H] rows:
    /// `[w_ih, w_hh, b_ih, b_hh]`.
    pub(crate) fn leaves(&self, tape: &mut Tape) -> [Var; 4] {
        [
            tape.param(self.weight_ih.view()),
            tape.param(self.weight_hh.view()),
            tape.param(self.bias_ih.view().insert_axis(Axis(0))),
            tape.param(self.bias_hh.view().insert_axis(Axis(0))),
        ]
    }

    /// Copy the gradients of the leaves `[w_ih, w_hh, b_ih, b_hh]` from the tape into `self`
    /// (zero where none reached them).
    pub(crate) fn copy_grads(&mut self, tape: &Tape, [w_ih, w_hh, b_ih, b_hh]: [Var; 4]) {
        copy_grad(tape, w_ih, flat_mut(&mut self.weight_ih));
        copy_grad(tape, w_hh, flat_mut(&mut self.weight_hh));
        copy_grad(tape, b_ih, flat_mut(&mut self.bias_ih));
        copy_grad(tape, b_hh, flat_mut(&mut self.bias_hh));
    }
}

impl<const GATES: usize> Params for RecurrentParams<GATES> {
    fn slices(&self) -> Vec<&[f32]> {
        vec![
            flat(&self.weight_ih),
            flat(&self.weight_hh),
            flat(&self.bias_ih),
            flat(&self.bias_hh),
        ]
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        vec![
            flat_mut(&mut self.weight_ih),
            flat_mut(&mut self.weight_hh),
            flat_mut(&mut self.bias_ih),
            flat_mut(&mut self.bias_hh),
        ]
    }
}

/// Flat, contiguous view of an owned array (ours are always in standard layout).
pub(crate) fn flat<D: ndarray::Dimension>(a: &ndarray::Array<f32, D>) -> &[f32] {
    a.as_slice_memory_order()
        .expect("owned parameter arrays are contiguous")
}

/// Mutable flat view (see [`flat`]).
pub(crate) fn flat_mut<D: ndarray::Dimension>(a: &mut ndarray::Array<f32, D>) -> &mut [f32] {
    a.as_slice_memory_order_mut()
        .expect("owned parameter arrays are contiguous")
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
            match g.as_slice() {
                // Tape gradients are contiguous: one memcpy, not ndarray's element iterator.
                Some(g) => dst.copy_from_slice(g),
                None => {
                    for (d, &g) in dst.iter_mut().zip(g.iter()) {
                        *d = g;
                    }
                }
            }
        }
        None => dst.fill(0.0),
    }
}
