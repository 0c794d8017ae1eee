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

use super::activations::{sigmoid_approx, simd_dispatch, tanh_approx};
use super::gemm::{gemm, transpose_into, Mode};
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
    cache.xh.slice_mut(s![..packing.batch_size(0), input..]).fill(0.0);

    // Right operands in unit-stride layout once, not once per product.
    let mut w_ih_t = Array2::zeros((input, 4 * h));
    transpose_into(w.w_ih, &mut w_ih_t);
    let mut w_hh_t = Array2::zeros((h, 4 * h));
    transpose_into(w.w_hh, &mut w_hh_t);

    // Input projection of every step at once (the biases are added in the cell kernel).
    gemm(cache.xh.slice(s![.., ..input]), w_ih_t.view(), cache.gates.view_mut(), Mode::Overwrite);
    let bias: Vec<f32> = w.b_ih.iter().zip(w.b_hh).map(|(a, b)| a + b).collect();

    let y = y.as_slice_mut().expect("lstm: y must be contiguous");
    let mut h_step = vec![0.0f32; packing.batch_size(0) * h];
    let zeros = vec![0.0f32; packing.batch_size(0) * h];
    for t in 0..packing.n_steps() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        if t > 0 {
            gemm(
                cache.xh.slice(s![o..o + n, input..]),
                w_hh_t.view(),
                cache.gates.slice_mut(s![o..o + n, ..]),
                Mode::Accumulate,
            );
        }
        let gates = &mut cache.gates.as_slice_mut().expect("contiguous")[o * 4 * h..(o + n) * 4 * h];
        let (c_before, c_now) = cache.c.as_slice_mut().expect("contiguous").split_at_mut(o * h);
        let c_prev: &[f32] = if t > 0 {
            let po = packing.offset(t - 1);
            &c_before[po * h..(po + n) * h]
        } else {
            &zeros[..n * h]
        };
        let tc = &mut cache.tanh_c.as_slice_mut().expect("contiguous")[o * h..(o + n) * h];
        let hs = &mut h_step[..n * h];
        forward_cells(gates, &bias, c_prev, &mut c_now[..n * h], tc, hs, h);

        // h goes to the output (flat order) and, for sequences that go on, to the next step's
        // recurrent input.
        let next_n = packing.batch_size(t + 1);
        let next_o = if next_n > 0 { packing.offset(t + 1) } else { 0 };
        let xh = cache.xh.as_slice_mut().expect("contiguous");
        for (j, hr) in hs.chunks_exact(h).enumerate() {
            let f = p2f[o + j];
            y[f * h..(f + 1) * h].copy_from_slice(hr);
            if j < next_n {
                let at = (next_o + j) * xw + input;
                xh[at..at + h].copy_from_slice(hr);
            }
        }
    }
}

/// Lanes per chunk of the pointwise kernels: they copy up to this many values of each operand
/// into local arrays, so the compiler sees no aliasing and vectorizes; a short last chunk is
/// padded (its extra lanes compute on zeros and are never stored).
const LANES: usize = 16;

/// Copy `src` (at most LANES values) into the first lanes of a zeroed chunk. The full-chunk
/// case is a fixed-size copy (a register load, not a `memcpy` call).
#[inline(always)]
fn load(src: &[f32]) -> [f32; LANES] {
    if let Ok(full) = <[f32; LANES]>::try_from(src) {
        return full;
    }
    let mut a = [0.0; LANES];
    a[..src.len()].copy_from_slice(src);
    a
}

/// Store the first dst.len() lanes of `v` (see [`load`]).
#[inline(always)]
fn store(dst: &mut [f32], v: &[f32; LANES]) {
    if let Ok(full) = <&mut [f32; LANES]>::try_from(&mut *dst) {
        *full = *v;
        return;
    }
    let n = dst.len();
    dst.copy_from_slice(&v[..n]);
}

simd_dispatch! {
    /// The pointwise part of one step for its n rows: activate the gates (pre-activations from
    /// the products, plus `bias`), then c = f c_prev + i g, tanh(c), h = o tanh(c).
    /// gates: [n, 4H] (activated in place), c_prev: [n, H] (zeros at step 0), c, tanh_c,
    /// h_out: [n, H].
    pub fn forward_cells(
        gates: &mut [f32],
        bias: &[f32],
        c_prev: &[f32],
        c: &mut [f32],
        tanh_c: &mut [f32],
        h_out: &mut [f32],
        hidden: usize,
    ) {
        let h = hidden;
        for j in 0..c.len() / h {
            let row = j * 4 * h;
            let mut q0 = 0;
            while q0 < h {
                let len = LANES.min(h - q0);
                let at = |block: usize| row + block * h + q0..row + block * h + q0 + len;
                let bat = |block: usize| block * h + q0..block * h + q0 + len;
                let cell = j * h + q0..j * h + q0 + len;
                let (zi, zf, zg, zo) = (load(&gates[at(0)]), load(&gates[at(1)]), load(&gates[at(2)]), load(&gates[at(3)]));
                let (bi, bf, bg, bo) = (load(&bias[bat(0)]), load(&bias[bat(1)]), load(&bias[bat(2)]), load(&bias[bat(3)]));
                let cp = load(&c_prev[cell.clone()]);
                let (mut i, mut f, mut g, mut o) = ([0.0; LANES], [0.0; LANES], [0.0; LANES], [0.0; LANES]);
                let (mut cv, mut tc, mut hv) = ([0.0; LANES], [0.0; LANES], [0.0; LANES]);
                for l in 0..LANES {
                    i[l] = sigmoid_approx(zi[l] + bi[l]);
                    f[l] = sigmoid_approx(zf[l] + bf[l]);
                    g[l] = tanh_approx(zg[l] + bg[l]);
                    o[l] = sigmoid_approx(zo[l] + bo[l]);
                    cv[l] = f[l] * cp[l] + i[l] * g[l];
                    tc[l] = tanh_approx(cv[l]);
                    hv[l] = o[l] * tc[l];
                }
                store(&mut gates[at(0)], &i);
                store(&mut gates[at(1)], &f);
                store(&mut gates[at(2)], &g);
                store(&mut gates[at(3)], &o);
                store(&mut c[cell.clone()], &cv);
                store(&mut tanh_c[cell.clone()], &tc);
                store(&mut h_out[cell], &hv);
                q0 += len;
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
/// [`LstmCache`]). `dgates`: [K, 4H] (overwritten); `dh_rec`, `dc`: [batch_size(0), H] scratch;
/// `db` [4H] receives the column sums of dgates (the gradient of either bias).
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
    db: &mut [f32],
) {
    let (k, h) = (packing.total(), w_hh.ncols());
    assert_eq!(dy.dim(), (k, h), "lstm backward: dy must be [K, H]");
    assert_eq!(dgates.dim(), (k, 4 * h), "lstm backward: dgates must be [K, 4H]");
    let n0 = packing.batch_size(0);
    assert_eq!(dh_rec.dim(), (n0, h));
    assert_eq!(dc.dim(), (n0, h));
    let p2f = packing.packed_to_flat();
    let dy = dy.as_standard_layout();
    let dy = dy.as_slice().expect("standard layout");
    let gates = gates.as_slice().expect("contiguous");
    let c_all = c.as_slice().expect("contiguous");
    let tc_all = tanh_c.as_slice().expect("contiguous");
    db.fill(0.0);
    // Rows of dh_rec and dc past a step's continuing sequences are never written by later
    // steps (batch sizes only shrink with t), so zeroing them once makes them "nothing
    // carried" for the rows whose sequence ends at that step.
    dh_rec.fill(0.0);
    dc.fill(0.0);
    let zeros = vec![0.0f32; n0 * h];

    for t in (0..packing.n_steps()).rev() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        let c_prev: &[f32] = if t > 0 {
            let po = packing.offset(t - 1);
            &c_all[po * h..(po + n) * h]
        } else {
            &zeros[..n * h]
        };
        backward_cells(
            dy,
            &p2f[o..o + n],
            &dh_rec.as_slice().expect("contiguous")[..n * h],
            &mut dc.as_slice_mut().expect("contiguous")[..n * h],
            &gates[o * 4 * h..(o + n) * 4 * h],
            c_prev,
            &tc_all[o * h..(o + n) * h],
            &mut dgates.as_slice_mut().expect("contiguous")[o * 4 * h..(o + n) * 4 * h],
            db,
            h,
        );
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

simd_dispatch! {
    /// The pointwise part of one backward step for its n rows. dL/dh of row j is its output
    /// gradient dy[rows[j]] plus dh_rec[j], the part through the next step (zero for sequences
    /// that ended here); dc[j] likewise carries dL/dc from the next step. Writes the
    /// pre-activation gradients dgates [n, 4H], adds their column sums to db [4H] (the bias
    /// gradient), and leaves dL/dc_prev in dc. c_prev: [n, H] (zeros at step 0).
    pub fn backward_cells(
        dy: &[f32],
        rows: &[usize],
        dh_rec: &[f32],
        dc: &mut [f32],
        gates: &[f32],
        c_prev: &[f32],
        tanh_c: &[f32],
        dgates: &mut [f32],
        db: &mut [f32],
        hidden: usize,
    ) {
        let h = hidden;
        for (j, &row) in rows.iter().enumerate() {
            let mut q0 = 0;
            while q0 < h {
                let len = LANES.min(h - q0);
                let at = |block: usize| j * 4 * h + block * h + q0..j * 4 * h + block * h + q0 + len;
                let cell = j * h + q0..j * h + q0 + len;
                let dyr = load(&dy[row * h + q0..row * h + q0 + len]);
                let dhr = load(&dh_rec[cell.clone()]);
                let cp = load(&c_prev[cell.clone()]);
                let tc = load(&tanh_c[cell.clone()]);
                let dcn = load(&dc[cell.clone()]);
                let (i, f, g, o) = (load(&gates[at(0)]), load(&gates[at(1)]), load(&gates[at(2)]), load(&gates[at(3)]));
                let (mut di, mut df, mut dg, mut dov, mut dcp) = ([0.0; LANES], [0.0; LANES], [0.0; LANES], [0.0; LANES], [0.0; LANES]);
                for l in 0..LANES {
                    let dh = dyr[l] + dhr[l];
                    let dct = dh * o[l] * (1.0 - tc[l] * tc[l]) + dcn[l];
                    di[l] = dct * g[l] * i[l] * (1.0 - i[l]);
                    df[l] = dct * cp[l] * f[l] * (1.0 - f[l]);
                    dg[l] = dct * i[l] * (1.0 - g[l] * g[l]);
                    dov[l] = dh * tc[l] * o[l] * (1.0 - o[l]);
                    dcp[l] = dct * f[l];
                }
                for (block, d) in [di, df, dg, dov].iter().enumerate() {
                    store(&mut dgates[at(block)], d);
                    let sums = &mut db[block * h + q0..block * h + q0 + len];
                    let mut acc = load(sums);
                    for l in 0..LANES {
                        acc[l] += d[l];
                    }
                    store(sums, &acc);
                }
                store(&mut dc[cell], &dcp);
                q0 += len;
            }
        }
    }
}
