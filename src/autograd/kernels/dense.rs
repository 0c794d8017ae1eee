//! The fully connected layer's forward, y = act(x · W^T + b), shared by the taped op and the
//! no-tape paths (target values, acting).

use ndarray::{ArrayView2, ArrayViewMut2};
use serde::{Deserialize, Serialize};

use super::activations::simd_dispatch;
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
    /// The Q-net's hidden activation: PyTorch's `F.leaky_relu` default slope (`docs/ALGORITHMS.md` §2.1).
    pub const LEAKY_001: Activation = Activation::LeakyRelu(0.01);

    /// The activation of one pre-activation value `z`.
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
}

/// out = act(x · w^T + b) with x: [m, k], w: [n, k], b: \[n\], out: [m, n] (overwritten).
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
    let slope = match act {
        Activation::Identity => 1.0,
        Activation::LeakyRelu(s) => s,
    };
    let out = out
        .as_slice_mut()
        .expect("linear output must be contiguous");
    bias_act_rows(out, b, slope);
}

simd_dispatch! {
    /// Each row of `rows` (rows of b.len() values): z = row + b, then z for z > 0, slope * z
    /// otherwise (slope 1 is the identity).
    pub fn bias_act_rows(rows: &mut [f32], b: &[f32], slope: f32) {
        for row in rows.chunks_exact_mut(b.len()) {
            for (y, &bv) in row.iter_mut().zip(b) {
                let z = *y + bv;
                *y = if z > 0.0 { z } else { slope * z };
            }
        }
    }
}

simd_dispatch! {
    /// The backward of [`bias_act_rows`] from its output y (slope >= 0, so y > 0 exactly when
    /// z > 0): dz = g for y > 0, slope * g otherwise; adds the column sums of dz (the bias
    /// gradient) to `sums` (one per column). All slices are rows of sums.len() values.
    pub fn act_backward_rows(g: &[f32], y: &[f32], slope: f32, dz: &mut [f32], sums: &mut [f32]) {
        let n = sums.len();
        for ((gr, yr), dr) in g.chunks_exact(n).zip(y.chunks_exact(n)).zip(dz.chunks_exact_mut(n)) {
            for j in 0..n {
                let d = if yr[j] > 0.0 { gr[j] } else { slope * gr[j] };
                dr[j] = d;
                sums[j] += d;
            }
        }
    }
}

simd_dispatch! {
    /// Adds the column sums of `g` (rows of sums.len() values) to `sums`.
    pub fn add_column_sums(g: &[f32], sums: &mut [f32]) {
        let n = sums.len();
        for gr in g.chunks_exact(n) {
            for j in 0..n {
                sums[j] += gr[j];
            }
        }
    }
}

/// Dot product with 8 independent partial sums, so it vectorizes (a fixed order: deterministic).
#[inline(always)]
pub fn dot(a: &[f32], b: &[f32]) -> f32 {
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

simd_dispatch! {
    /// out\[o\] = act(w[o, :] . x + b\[o\]) for w: [out.len(), x.len()] row-major, act a leaky ReLU
    /// with `slope` (1 = identity): one layer for one input row (acting).
    pub fn matvec_act(w: &[f32], x: &[f32], b: &[f32], slope: f32, out: &mut [f32]) {
        for (o, (row, &bv)) in out.iter_mut().zip(w.chunks_exact(x.len()).zip(b)) {
            let z = dot(row, x) + bv;
            *o = if z > 0.0 { z } else { slope * z };
        }
    }
}

simd_dispatch! {
    /// gates\[r\] = w_ih[r, :] . x + b_ih\[r\] + w_hh[r, :] . h + b_hh\[r\]: the LSTM's gate
    /// pre-activations for one input row (acting).
    pub fn lstm_gates_row(
        w_ih: &[f32],
        x: &[f32],
        w_hh: &[f32],
        h: &[f32],
        b_ih: &[f32],
        b_hh: &[f32],
        gates: &mut [f32],
    ) {
        let rows_ih = w_ih.chunks_exact(x.len());
        let rows_hh = w_hh.chunks_exact(h.len());
        for (r, (ri, rh)) in rows_ih.zip(rows_hh).enumerate() {
            gates[r] = dot(ri, x) + b_ih[r] + dot(rh, h) + b_hh[r];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_handles_lengths_that_are_not_multiples_of_eight() {
        let a: Vec<f32> = (0..13).map(|i| i as f32).collect();
        let b = vec![1.0f32; 13];
        assert_eq!(dot(&a, &b), 78.0);
    }
}
