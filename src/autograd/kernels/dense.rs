//! The fully connected layer's forward, y = act(x · W^T + b), shared by the taped op and the
//! no-tape paths (target values, acting).

use ndarray::{ArrayView2, ArrayViewMut2};
use serde::{Deserialize, Serialize};

use super::gemm::{gemm, Mode};

/// The nonlinearity fused after a linear layer.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Activation {
    /// No nonlinearity (the Q-net's output layer fc4).
    Identity,
    /// x for x > 0, slope * x otherwise (slope >= 0, so the sign of the output tells which
    /// branch was taken; the backward relies on that).
    LeakyRelu(f32),
}

impl Activation {
    /// The Q-net's hidden activation: PyTorch's `F.leaky_relu` default slope (spec 2.1).
    pub const LEAKY_001: Activation = Activation::LeakyRelu(0.01);

    #[inline(always)]
    pub fn apply(self, z: f32) -> f32 {
        match self {
            Activation::Identity => z,
            Activation::LeakyRelu(s) => {
                if z > 0.0 {
                    z
                } else {
                    s * z
                }
            }
        }
    }

    /// dy/dz expressed through the output y.
    #[inline(always)]
    pub fn slope_at_output(self, y: f32) -> f32 {
        match self {
            Activation::Identity => 1.0,
            Activation::LeakyRelu(s) => {
                if y > 0.0 {
                    1.0
                } else {
                    s
                }
            }
        }
    }
}

/// out = act(x · w^T + b) with x: [m, k], w: [n, k], b: [n], out: [m, n] (overwritten).
/// Panics on mismatched shapes.
pub fn linear_forward(
    x: ArrayView2<f32>,
    w: ArrayView2<f32>,
    b: &[f32],
    act: Activation,
    mut out: ArrayViewMut2<f32>,
) {
    assert_eq!(b.len(), w.nrows(), "linear: bias length");
    gemm(x, w.t(), out.view_mut(), Mode::Overwrite);
    for mut row in out.rows_mut() {
        let row = row
            .as_slice_mut()
            .expect("linear output rows are contiguous");
        match act {
            Activation::Identity => row.iter_mut().zip(b).for_each(|(y, &b)| *y += b),
            Activation::LeakyRelu(s) => row.iter_mut().zip(b).for_each(|(y, &b)| {
                let z = *y + b;
                *y = if z > 0.0 { z } else { s * z };
            }),
        }
    }
}
