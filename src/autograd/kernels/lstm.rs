//! The LSTM over a packed batch of sequences (forward and backward), PyTorch's equations and gate
//! order (spec `algorithms.md` 2.1):
//!
//! ```text
//! [i f g o] = x W_ih^T + b_ih + h_prev W_hh^T + b_hh
//! i, f, o = sigmoid(.), g = tanh(.)
//! c = f * c_prev + i * g,   h = o * tanh(c)
//! ```
//!
//! Speed: the input projection of all steps is one matrix product; each step adds only its
//! recurrent product over the sequences still running. The backward mirrors this: the per-step
//! work is the recurrent product of the gate gradients, and all weight gradients are one product
//! each over all steps (see `ops/lstm.rs`).

use ndarray::{s, Array2, ArrayView2};

use super::activations::{sigmoid_inplace, tanh_inplace, tanh_into};
use super::gemm::{gemm, Mode};
use crate::autograd::SeqPacking;

/// The four LSTM parameter tensors. w_ih: [4H, in], w_hh: [4H, H], biases: [4H].
#[derive(Debug, Clone, Copy)]
pub struct LstmWeights<'a> {
    pub w_ih: ArrayView2<'a, f32>,
    pub w_hh: ArrayView2<'a, f32>,
    pub b_ih: &'a [f32],
    pub b_hh: &'a [f32],
}

impl LstmWeights<'_> {
    /// Hidden size H.
    pub fn hidden(&self) -> usize {
        self.w_hh.ncols()
    }

    /// Input size.
    pub fn input(&self) -> usize {
        self.w_ih.ncols()
    }

    /// Panics unless the shapes are consistent ([4H, in], [4H, H], [4H], [4H]).
    pub fn check(&self) {
        let h = self.hidden();
        assert_eq!(self.w_hh.nrows(), 4 * h, "w_hh must be [4H, H]");
        assert_eq!(self.w_ih.nrows(), 4 * h, "w_ih must be [4H, in]");
        assert_eq!(self.b_ih.len(), 4 * h, "b_ih must be [4H]");
        assert_eq!(self.b_hh.len(), 4 * h, "b_hh must be [4H]");
    }
}

/// What the forward keeps for the backward, in packed row order (see [`SeqPacking`]).
#[derive(Debug)]
pub struct LstmCache {
    /// [K, in + H]: each row's input, then its predecessor's h (zero at step 0). Also the left
    /// factor of the weight gradients.
    pub xh: Array2<f32>,
    /// [K, 4H]: activated gates i, f, g, o.
    pub gates: Array2<f32>,
    /// [K, H]: cell states.
    pub c: Array2<f32>,
    /// [K, H]: tanh of the cell states.
    pub tanh_c: Array2<f32>,
}

impl LstmCache {
    /// Required shapes for K rows, `input` features and hidden size `h`.
    pub fn shapes(k: usize, input: usize, h: usize) -> [(usize, usize); 4] {
        [(k, input + h), (k, 4 * h), (k, h), (k, h)]
    }
}

/// Run the LSTM from zero states over every sequence of `packing`.
/// x: [K, in] in flat order; `cache` buffers of [`LstmCache::shapes`] (contents overwritten);
/// y: [K, H] receives h in flat order. Panics on inconsistent shapes.
pub fn lstm_forward(
    x: ArrayView2<f32>,
    w: &LstmWeights,
    packing: &SeqPacking,
    cache: &mut LstmCache,
    y: &mut Array2<f32>,
) {
    w.check();
    let (k, input, h) = (packing.total(), w.input(), w.hidden());
    assert_eq!(x.dim(), (k, input), "lstm: x must be [K, in]");
    assert_eq!(y.dim(), (k, h), "lstm: y must be [K, H]");
    for (buf, shape) in [&cache.xh, &cache.gates, &cache.c, &cache.tanh_c]
        .into_iter()
        .zip(LstmCache::shapes(k, input, h))
    {
        assert_eq!(buf.dim(), shape, "lstm: cache buffer shape");
    }
    if k == 0 {
        return;
    }
    let p2f = packing.packed_to_flat();
    let xw = input + h;

    // Inputs into packed order; step 0's predecessor h is zero.
    for (p, mut row) in cache.xh.rows_mut().into_iter().enumerate() {
        row.slice_mut(s![..input]).assign(&x.row(p2f[p]));
    }
    cache
        .xh
        .slice_mut(s![..packing.batch_size(0), input..])
        .fill(0.0);

    // Input projection of every step at once, plus both biases.
    gemm(
        cache.xh.slice(s![.., ..input]),
        w.w_ih.t(),
        cache.gates.view_mut(),
        Mode::Overwrite,
    );
    let bias: Vec<f32> = w.b_ih.iter().zip(w.b_hh).map(|(a, b)| a + b).collect();
    for mut row in cache.gates.rows_mut() {
        row += &ndarray::aview1(&bias);
    }

    let y = y.as_slice_mut().expect("lstm: y must be contiguous");
    for t in 0..packing.n_steps() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        if t > 0 {
            gemm(
                cache.xh.slice(s![o..o + n, input..]),
                w.w_hh.t(),
                cache.gates.slice_mut(s![o..o + n, ..]),
                Mode::Accumulate,
            );
        }
        let gates =
            &mut cache.gates.as_slice_mut().expect("contiguous")[o * 4 * h..(o + n) * 4 * h];
        for row in gates.chunks_exact_mut(4 * h) {
            sigmoid_inplace(&mut row[..2 * h]);
            tanh_inplace(&mut row[2 * h..3 * h]);
            sigmoid_inplace(&mut row[3 * h..]);
        }
        let c_all = cache.c.as_slice_mut().expect("contiguous");
        let (c_before, c_now) = c_all.split_at_mut(o * h);
        let c_now = &mut c_now[..n * h];
        let prev_o = if t > 0 { packing.offset(t - 1) } else { 0 };
        for j in 0..n {
            let gr = &gates[j * 4 * h..(j + 1) * 4 * h];
            let (gi, gf, gg) = (&gr[..h], &gr[h..2 * h], &gr[2 * h..3 * h]);
            let c = &mut c_now[j * h..(j + 1) * h];
            if t > 0 {
                let cp = &c_before[(prev_o + j) * h..(prev_o + j + 1) * h];
                for q in 0..h {
                    c[q] = gf[q] * cp[q] + gi[q] * gg[q];
                }
            } else {
                for q in 0..h {
                    c[q] = gi[q] * gg[q];
                }
            }
        }
        let tc = &mut cache.tanh_c.as_slice_mut().expect("contiguous")[o * h..(o + n) * h];
        tanh_into(c_now, tc);
        let next_n = packing.batch_size(t + 1);
        let next_o = if next_n > 0 { packing.offset(t + 1) } else { 0 };
        let xh = cache.xh.as_slice_mut().expect("contiguous");
        for j in 0..n {
            let go = &gates[j * 4 * h + 3 * h..(j + 1) * 4 * h];
            let tcj = &tc[j * h..(j + 1) * h];
            let f = p2f[o + j];
            let yr = &mut y[f * h..(f + 1) * h];
            for q in 0..h {
                yr[q] = go[q] * tcj[q];
            }
            if j < next_n {
                let at = (next_o + j) * xw + input;
                xh[at..at + h].copy_from_slice(yr);
            }
        }
    }
}

/// Scratch for [`lstm_backward`]: two [batch_size(0), H] buffers.
pub fn lstm_backward_scratch_rows(packing: &SeqPacking) -> usize {
    packing.batch_size(0)
}

/// Gradients of the gate pre-activations, in packed order, given dy = dL/dh in flat order and
/// the forward's activated `gates` [K, 4H], cell states `c` and `tanh_c` [K, H] (see
/// [`LstmCache`]). `dgates`: [K, 4H] (overwritten); `dh_rec`, `dc`: [batch_size(0), H] scratch.
#[allow(clippy::too_many_arguments)]
pub fn lstm_backward(
    dy: ArrayView2<f32>,
    w_hh: ArrayView2<f32>,
    packing: &SeqPacking,
    gates: &Array2<f32>,
    c: &Array2<f32>,
    tanh_c: &Array2<f32>,
    dgates: &mut Array2<f32>,
    dh_rec: &mut Array2<f32>,
    dc: &mut Array2<f32>,
) {
    let (k, h) = (packing.total(), w_hh.ncols());
    assert_eq!(dy.dim(), (k, h), "lstm backward: dy must be [K, H]");
    assert_eq!(
        dgates.dim(),
        (k, 4 * h),
        "lstm backward: dgates must be [K, 4H]"
    );
    let n0 = packing.batch_size(0);
    assert_eq!(dh_rec.dim(), (n0, h));
    assert_eq!(dc.dim(), (n0, h));
    let p2f = packing.packed_to_flat();
    let dy = dy.as_standard_layout();
    let dy = dy.as_slice().expect("standard layout");
    let gates = gates.as_slice().expect("contiguous");
    let c_all = c.as_slice().expect("contiguous");
    let tc_all = tanh_c.as_slice().expect("contiguous");
    let mut dh = vec![0.0f32; h];

    for t in (0..packing.n_steps()).rev() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        let n_next = packing.batch_size(t + 1);
        let prev_o = if t > 0 { packing.offset(t - 1) } else { 0 };
        {
            let dg_all = dgates.as_slice_mut().expect("contiguous");
            let dh_rec = dh_rec.as_slice().expect("contiguous");
            let dc = dc.as_slice_mut().expect("contiguous");
            for j in 0..n {
                let p = o + j;
                let f = p2f[p];
                let dyr = &dy[f * h..(f + 1) * h];
                if j < n_next {
                    let r = &dh_rec[j * h..(j + 1) * h];
                    for q in 0..h {
                        dh[q] = dyr[q] + r[q];
                    }
                } else {
                    dh.copy_from_slice(dyr);
                }
                let gr = &gates[p * 4 * h..(p + 1) * 4 * h];
                let (gi, gf, gg, go) = (&gr[..h], &gr[h..2 * h], &gr[2 * h..3 * h], &gr[3 * h..]);
                let tc = &tc_all[p * h..(p + 1) * h];
                let dcj = &mut dc[j * h..(j + 1) * h];
                let dgr = &mut dg_all[p * 4 * h..(p + 1) * 4 * h];
                let carried = j < n_next;
                for q in 0..h {
                    let c_prev = if t > 0 {
                        c_all[(prev_o + j) * h + q]
                    } else {
                        0.0
                    };
                    let mut dct = dh[q] * go[q] * (1.0 - tc[q] * tc[q]);
                    if carried {
                        dct += dcj[q];
                    }
                    let (i, fg, g, og) = (gi[q], gf[q], gg[q], go[q]);
                    dgr[q] = dct * g * i * (1.0 - i);
                    dgr[h + q] = dct * c_prev * fg * (1.0 - fg);
                    dgr[2 * h + q] = dct * i * (1.0 - g * g);
                    dgr[3 * h + q] = dh[q] * tc[q] * og * (1.0 - og);
                    dcj[q] = dct * fg;
                }
            }
        }
        if t > 0 {
            gemm(
                dgates.slice(s![o..o + n, ..]),
                w_hh,
                dh_rec.slice_mut(s![..n, ..]),
                Mode::Overwrite,
            );
        }
    }
}
