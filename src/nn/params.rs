//! Parameter containers: named tensors with PyTorch's state_dict names, and the [`Params`] view
//! Adam and the checkpoint code work through.

use ndarray::{Array1, Array2};
use serde::{Deserialize, Serialize};

/// A set of parameter tensors seen as flat slices in a fixed order (Adam steps over them; a
/// gradient set of the same type lines up entry by entry).
pub trait Params {
    /// Every tensor's elements, in the fixed order.
    fn slices(&self) -> Vec<&[f32]>;
    /// The same, mutable.
    fn slices_mut(&mut self) -> Vec<&mut [f32]>;
}

/// A fully connected layer's parameters (PyTorch `nn.Linear`): weight [out, in], bias [out].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearParams {
    pub weight: Array2<f32>,
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

/// A one-layer LSTM's parameters (PyTorch `nn.LSTM`, gate order i, f, g, o):
/// weight_ih [4H, in], weight_hh [4H, H], bias_ih [4H], bias_hh [4H].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LstmParams {
    pub weight_ih: Array2<f32>,
    pub weight_hh: Array2<f32>,
    pub bias_ih: Array1<f32>,
    pub bias_hh: Array1<f32>,
}

impl LstmParams {
    /// All-zero parameters for `input` features and hidden size `hidden`.
    pub fn zeros(input: usize, hidden: usize) -> Self {
        LstmParams {
            weight_ih: Array2::zeros((4 * hidden, input)),
            weight_hh: Array2::zeros((4 * hidden, hidden)),
            bias_ih: Array1::zeros(4 * hidden),
            bias_hh: Array1::zeros(4 * hidden),
        }
    }

    /// Hidden size H.
    pub fn hidden(&self) -> usize {
        self.weight_hh.ncols()
    }
}

/// A one-layer GRU's parameters (PyTorch `nn.GRU`, gate order r, z, n):
/// weight_ih [3H, in], weight_hh [3H, H], bias_ih [3H], bias_hh [3H].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GruParams {
    pub weight_ih: Array2<f32>,
    pub weight_hh: Array2<f32>,
    pub bias_ih: Array1<f32>,
    pub bias_hh: Array1<f32>,
}

impl GruParams {
    /// All-zero parameters for `input` features and hidden size `hidden` (a gradient buffer).
    pub fn zeros(input: usize, hidden: usize) -> Self {
        GruParams {
            weight_ih: Array2::zeros((3 * hidden, input)),
            weight_hh: Array2::zeros((3 * hidden, hidden)),
            bias_ih: Array1::zeros(3 * hidden),
            bias_hh: Array1::zeros(3 * hidden),
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
}

impl Params for GruParams {
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
