//! The LSTM over a packed batch of sequences (forward and backward), PyTorch's equations and gate
//! order (`docs/ALGORITHMS.md` §2.1):
//!
//! ```text
//! [i f g o] = x W_ih^T + b_ih + h_prev W_hh^T + b_hh
//! i, f, o = sigmoid(.), g = tanh(.)
//! c = f * c_prev + i * g,   h = o * tanh(c)
//! ```
//!
//! Rows are in packed order (see [`SeqPacking`]): step t is the contiguous block of rows
//! `offset(t) .. offset(t) + batch_size(t)`, and row j of it continues row j of step t-1.
//!
//! Speed: the input projection of all steps is one matrix product; each step adds only its
//! recurrent product over the sequences still running, then one fused, vectorized pass computes
//! the cells. The backward mirrors this: per step, one fused pass for the gate gradients (and
//! the bias gradient) and the recurrent product; all weight and input gradients are one product
//! each over all steps (see `ops/lstm.rs`).

use ndarray::{s, Array2, ArrayView2};

use super::activations::{sigmoid_approx, simd_dispatch, tanh_approx};
use super::gemm::{gemm, transposed, Mode};
use crate::autograd::SeqPacking;

/// The four LSTM parameter tensors. w_ih: [4H, in], w_hh: [4H, H], biases: \[4H\].
#[derive(Debug, Clone, Copy)]
pub struct LstmWeights<'a> {
    /// Input weights [4H, in].
    pub w_ih: ArrayView2<'a, f32>,
    /// Recurrent weights [4H, H].
    pub w_hh: ArrayView2<'a, f32>,
    /// Input bias \[4H\].
    pub b_ih: &'a [f32],
    /// Recurrent bias \[4H\].
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

    /// Panics unless the shapes are consistent ([4H, in], [4H, H], \[4H\], \[4H\]).
    pub fn check(&self) {
        let h = self.hidden();
        assert_eq!(self.w_hh.nrows(), 4 * h, "w_hh must be [4H, H]");
        assert_eq!(self.w_ih.nrows(), 4 * h, "w_ih must be [4H, in]");
        assert_eq!(self.b_ih.len(), 4 * h, "b_ih must be [4H]");
        assert_eq!(self.b_hh.len(), 4 * h, "b_hh must be [4H]");
    }
}

/// What the forward keeps for the backward, in packed row order.
#[derive(Debug)]
pub struct LstmCache {
    /// [K, H]: each row's predecessor h (zero at step 0): the recurrent input, and the left
    /// factor of W_hh's gradient.
    pub h_prev: Array2<f32>,
    /// [K, 4H]: activated gates i, f, g, o.
    pub gates: Array2<f32>,
    /// [K, H]: cell states.
    pub c: Array2<f32>,
    /// [K, H]: tanh of the cell states.
    pub tanh_c: Array2<f32>,
}

impl LstmCache {
    /// Required shapes for K rows and hidden size `h`.
    pub fn shapes(k: usize, h: usize) -> [(usize, usize); 4] {
        [(k, h), (k, 4 * h), (k, h), (k, h)]
    }
}

/// Run the LSTM from zero states over every sequence of `packing`.
/// x: [K, in] and y: [K, H] (receives h) in packed order; `cache` buffers of
/// [`LstmCache::shapes`] (contents overwritten). Panics on inconsistent shapes.
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
    for (buf, shape) in [&cache.h_prev, &cache.gates, &cache.c, &cache.tanh_c]
        .into_iter()
        .zip(LstmCache::shapes(k, h))
    {
        assert_eq!(buf.dim(), shape, "lstm: cache buffer shape");
    }
    if k == 0 {
        return;
    }
    let n0 = packing.batch_size(0);
    cache.h_prev.slice_mut(s![..n0, ..]).fill(0.0);

    // Right operands in unit-stride layout once, not once per product.
    let w_ih_t = transposed(w.w_ih);
    let w_hh_t = transposed(w.w_hh);

    let bias: Vec<f32> = w.b_ih.iter().zip(w.b_hh).map(|(a, b)| a + b).collect();
    let zeros = vec![0.0f32; n0 * h];

    let y = y.as_slice_mut().expect("lstm: y must be contiguous");
    for t in 0..packing.n_steps() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        // The step's gate pre-activations, computed just before use so they are still in
        // cache for the cell kernel (the biases are added there).
        gemm(
            x.slice(s![o..o + n, ..]),
            w_ih_t.view(),
            cache.gates.slice_mut(s![o..o + n, ..]),
            Mode::Overwrite,
        );
        if t > 0 {
            gemm(
                cache.h_prev.slice(s![o..o + n, ..]),
                w_hh_t.view(),
                cache.gates.slice_mut(s![o..o + n, ..]),
                Mode::Accumulate,
            );
        }
        let gates =
            &mut cache.gates.as_slice_mut().expect("contiguous")[o * 4 * h..(o + n) * 4 * h];
        let (c_before, c_now) = cache
            .c
            .as_slice_mut()
            .expect("contiguous")
            .split_at_mut(o * h);
        let c_prev: &[f32] = if t > 0 {
            let po = packing.offset(t - 1);
            &c_before[po * h..(po + n) * h]
        } else {
            &zeros[..n * h]
        };
        let tc = &mut cache.tanh_c.as_slice_mut().expect("contiguous")[o * h..(o + n) * h];
        let hs = &mut y[o * h..(o + n) * h];
        forward_cells(gates, &bias, c_prev, &mut c_now[..n * h], tc, hs, h);
        // The sequences that go on take this h as their next recurrent input.
        let next_n = packing.batch_size(t + 1);
        if next_n > 0 {
            let next_o = packing.offset(t + 1);
            let hp = cache.h_prev.as_slice_mut().expect("contiguous");
            hp[next_o * h..(next_o + next_n) * h].copy_from_slice(&hs[..next_n * h]);
        }
    }
}

/// Lanes per chunk of the pointwise kernels. A row of H values is processed as H / LANES
/// chunks copied into fixed-size local arrays (so the compiler sees no aliasing and emits plain
/// vector code), then the H % LANES rest one lane at a time through the same function, so
/// every lane gets bit-identical arithmetic.
pub(super) const LANES: usize = 16;

/// The cell update for L lanes: gate pre-activations (with their bias) in, activated gates,
/// c, tanh(c) and h out.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn cell_lanes<const L: usize>(
    z: [[f32; L]; 4],
    b: [[f32; L]; 4],
    cp: [f32; L],
) -> ([[f32; L]; 4], [f32; L], [f32; L], [f32; L]) {
    let mut gates = [[0.0; L]; 4];
    let (mut c, mut tc, mut h) = ([0.0; L], [0.0; L], [0.0; L]);
    for l in 0..L {
        let i = sigmoid_approx(z[0][l] + b[0][l]);
        let f = sigmoid_approx(z[1][l] + b[1][l]);
        let g = tanh_approx(z[2][l] + b[2][l]);
        let o = sigmoid_approx(z[3][l] + b[3][l]);
        c[l] = f * cp[l] + i * g;
        tc[l] = tanh_approx(c[l]);
        h[l] = o * tc[l];
        (gates[0][l], gates[1][l], gates[2][l], gates[3][l]) = (i, f, g, o);
    }
    (gates, c, tc, h)
}

/// Read L values at `at`.
#[inline(always)]
pub(super) fn rd<const L: usize>(src: &[f32], at: usize) -> [f32; L] {
    src[at..at + L].try_into().expect("slice of length L")
}

/// Write L values at `at`.
#[inline(always)]
pub(super) fn wr<const L: usize>(dst: &mut [f32], at: usize, v: &[f32; L]) {
    dst[at..at + L].copy_from_slice(v);
}

/// One row's cells over lanes q0, q0 + L, ... (see [`forward_cells`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn forward_row<const L: usize>(
    q: std::ops::Range<usize>,
    h: usize,
    gates: &mut [f32],
    bias: &[f32],
    c_prev: &[f32],
    c: &mut [f32],
    tanh_c: &mut [f32],
    h_out: &mut [f32],
) {
    let mut q0 = q.start;
    while q0 + L <= q.end {
        let z = [
            rd(gates, q0),
            rd(gates, h + q0),
            rd(gates, 2 * h + q0),
            rd(gates, 3 * h + q0),
        ];
        let b = [
            rd(bias, q0),
            rd(bias, h + q0),
            rd(bias, 2 * h + q0),
            rd(bias, 3 * h + q0),
        ];
        let (g, cv, tc, hv) = cell_lanes::<L>(z, b, rd(c_prev, q0));
        for (blk, gv) in g.iter().enumerate() {
            wr(gates, blk * h + q0, gv);
        }
        wr(c, q0, &cv);
        wr(tanh_c, q0, &tc);
        wr(h_out, q0, &hv);
        q0 += L;
    }
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
        let full = h - h % LANES;
        for j in 0..c.len() / h {
            let g = &mut gates[j * 4 * h..(j + 1) * 4 * h];
            let cell = j * h..(j + 1) * h;
            let (cp, cj) = (&c_prev[cell.clone()], &mut c[cell.clone()]);
            let (tj, hj) = (&mut tanh_c[cell.clone()], &mut h_out[cell]);
            forward_row::<LANES>(0..full, h, g, bias, cp, cj, tj, hj);
            forward_row::<1>(full..h, h, g, bias, cp, cj, tj, hj);
        }
    }
}

/// Scratch for [`lstm_backward`]: two [batch_size(0), H] buffers.
pub fn lstm_backward_scratch_rows(packing: &SeqPacking) -> usize {
    packing.batch_size(0)
}

/// Packed rows of gate gradients handed to [`lstm_backward`]'s callback at once: enough for
/// efficient products, few enough (256 x 4H floats) to still be in L2 when the callback reads
/// them.
pub const BACKWARD_CHUNK_ROWS: usize = 256;

/// Gradients of the gate pre-activations given dy = dL/dh, all in packed order, and the
/// forward's activated `gates` [K, 4H], cell states `c` and `tanh_c` [K, H] (see
/// [`LstmCache`]). `dgates`: [K, 4H] (overwritten); `dh_rec`, `dc`: [batch_size(0), H] scratch;
/// `db` \[4H\] receives the column sums of dgates (the gradient of either bias).
/// Steps are processed last to first; whenever at least [`BACKWARD_CHUNK_ROWS`] rows of dgates
/// are complete (and at the end), `on_rows(rows, dgates)` is called with their packed row range
/// (descending, disjoint, covering 0..K), so the caller can use them while they are in cache.
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
    mut on_rows: impl FnMut(std::ops::Range<usize>, &Array2<f32>),
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
    let mut chunk_end = k;

    for t in (0..packing.n_steps()).rev() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        let c_prev: &[f32] = if t > 0 {
            let po = packing.offset(t - 1);
            &c_all[po * h..(po + n) * h]
        } else {
            &zeros[..n * h]
        };
        backward_cells(
            &dy[o * h..(o + n) * h],
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
        if chunk_end - o >= BACKWARD_CHUNK_ROWS || t == 0 {
            on_rows(o..chunk_end, dgates);
            chunk_end = o;
        }
    }
}

/// The backward of the cell for L lanes: dL/dh (output plus recurrent part), the carried
/// dL/dc, and the forward's activated gates, c_prev and tanh(c) in; the gate pre-activation
/// gradients and dL/dc_prev out.
#[inline(always)]
fn cell_grad_lanes<const L: usize>(
    dh: [f32; L],
    dc_next: [f32; L],
    gates: [[f32; L]; 4],
    cp: [f32; L],
    tc: [f32; L],
) -> ([[f32; L]; 4], [f32; L]) {
    let [i, f, g, o] = gates;
    let mut d = [[0.0; L]; 4];
    let mut dc_prev = [0.0; L];
    for l in 0..L {
        let dct = dh[l] * o[l] * (1.0 - tc[l] * tc[l]) + dc_next[l];
        d[0][l] = dct * g[l] * i[l] * (1.0 - i[l]);
        d[1][l] = dct * cp[l] * f[l] * (1.0 - f[l]);
        d[2][l] = dct * i[l] * (1.0 - g[l] * g[l]);
        d[3][l] = dh[l] * tc[l] * o[l] * (1.0 - o[l]);
        dc_prev[l] = dct * f[l];
    }
    (d, dc_prev)
}

/// One row's gate gradients over lanes q0, q0 + L, ... (see [`backward_cells`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn backward_row<const L: usize>(
    q: std::ops::Range<usize>,
    h: usize,
    dy: &[f32],
    dh_rec: &[f32],
    dc: &mut [f32],
    gates: &[f32],
    c_prev: &[f32],
    tanh_c: &[f32],
    dgates: &mut [f32],
    db: &mut [f32],
) {
    let mut q0 = q.start;
    while q0 + L <= q.end {
        let (dyv, dhr): ([f32; L], [f32; L]) = (rd(dy, q0), rd(dh_rec, q0));
        let mut dh = [0.0; L];
        for l in 0..L {
            dh[l] = dyv[l] + dhr[l];
        }
        let g = [
            rd(gates, q0),
            rd(gates, h + q0),
            rd(gates, 2 * h + q0),
            rd(gates, 3 * h + q0),
        ];
        let (d, dcp) = cell_grad_lanes::<L>(dh, rd(dc, q0), g, rd(c_prev, q0), rd(tanh_c, q0));
        for (blk, dv) in d.iter().enumerate() {
            wr(dgates, blk * h + q0, dv);
            let mut sum: [f32; L] = rd(db, blk * h + q0);
            for l in 0..L {
                sum[l] += dv[l];
            }
            wr(db, blk * h + q0, &sum);
        }
        wr(dc, q0, &dcp);
        q0 += L;
    }
}

simd_dispatch! {
    /// The pointwise part of one backward step for its n rows. dL/dh of row j is its output
    /// gradient dy\[j\] plus dh_rec\[j\], the part through the next step (zero for sequences that
    /// ended here); dc\[j\] likewise carries dL/dc from the next step. Writes the pre-activation
    /// gradients dgates \[n, 4H\], adds their column sums to db \[4H\] (the bias gradient), and
    /// leaves dL/dc_prev in dc. c_prev: \[n, H\] (zeros at step 0).
    pub fn backward_cells(
        dy: &[f32],
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
        let full = h - h % LANES;
        for j in 0..dc.len() / h {
            let cell = j * h..(j + 1) * h;
            let row4 = j * 4 * h..(j + 1) * 4 * h;
            let (dyj, dhj, cpj, tcj) = (&dy[cell.clone()], &dh_rec[cell.clone()], &c_prev[cell.clone()], &tanh_c[cell.clone()]);
            let (gj, dgj, dcj) = (&gates[row4.clone()], &mut dgates[row4], &mut dc[cell]);
            backward_row::<LANES>(0..full, h, dyj, dhj, dcj, gj, cpj, tcj, dgj, db);
            backward_row::<1>(full..h, h, dyj, dhj, dcj, gj, cpj, tcj, dgj, db);
        }
    }
}
