//! The GRU over a packed batch of sequences (forward and backward), with PyTorch's equations,
//! gate order (r, z, n) and bias placement (`torch.nn.GRU`):
//!
//! ```text
//! [a_r a_z a_n] = x W_ih^T + b_ih,   [b_r b_z b_n] = h_prev W_hh^T + b_hh
//! r = sigmoid(a_r + b_r),  z = sigmoid(a_z + b_z)
//! n = tanh(a_n + r * b_n)          (b_hn sits inside the reset gate's product)
//! h = (1 - z) * n + z * h_prev
//! ```
//!
//! Rows are in packed order (see [`SeqPacking`]), as for the LSTM (`lstm.rs`), and the design is
//! the LSTM's, except that the input product of all steps is one product up front: then per step
//! the recurrent product over the sequences still running and one fused, vectorized pass for the
//! pointwise part. Unlike the LSTM the two products cannot be summed into one buffer (the reset
//! gate multiplies only the recurrent part of n), so the recurrent product goes to a scratch
//! [n, 3H] block, and the forward keeps b_n = W_hn h_prev + b_hn for the backward.
//!
//! The backward mirrors it: per step one fused pass computes the input-side gate gradients
//! dA = [da_r, da_z, da_n] and the recurrent-side ones dB = [da_r, da_z, r * da_n] (they differ
//! only in the n block, so both live in one [K, 4H] buffer, see [`DG_BLOCKS`]), then
//! dh_prev = z * dh + dB W_hh. All weight and input gradients are one product each over all
//! steps (dW_ih = dA^T x, dW_hh = dB^T h_prev, dx = dA W_ih; see `ops/gru.rs`).

use ndarray::{s, Array2, ArrayView2};

use super::activations::{sigmoid_approx, simd_dispatch, tanh_approx};
use super::gemm::{gemm, transposed, Mode};
use super::lstm::{rd, wr, LANES};
use crate::autograd::SeqPacking;

/// The four GRU parameter tensors. w_ih: [3H, in], w_hh: [3H, H], biases: \[3H\], gates stacked
/// r, z, n as in PyTorch's `weight_ih_l0`.
#[derive(Debug, Clone, Copy)]
pub struct GruWeights<'a> {
    /// Input weights [3H, in].
    pub w_ih: ArrayView2<'a, f32>,
    /// Recurrent weights [3H, H].
    pub w_hh: ArrayView2<'a, f32>,
    /// Input bias \[3H\].
    pub b_ih: &'a [f32],
    /// Recurrent bias \[3H\].
    pub b_hh: &'a [f32],
}

impl GruWeights<'_> {
    /// Hidden size H.
    pub fn hidden(&self) -> usize {
        self.w_hh.ncols()
    }

    /// Input size.
    pub fn input(&self) -> usize {
        self.w_ih.ncols()
    }

    /// Panics unless the shapes are consistent ([3H, in], [3H, H], \[3H\], \[3H\]).
    pub fn check(&self) {
        let h = self.hidden();
        assert_eq!(self.w_hh.nrows(), 3 * h, "gru: w_hh must be [3H, H]");
        assert_eq!(self.w_ih.nrows(), 3 * h, "gru: w_ih must be [3H, in]");
        assert_eq!(self.b_ih.len(), 3 * h, "gru: b_ih must be [3H]");
        assert_eq!(self.b_hh.len(), 3 * h, "gru: b_hh must be [3H]");
    }

    /// The biases as the cell kernels read them: [b_ir + b_hr, b_iz + b_hz, b_in, b_hn], [4H].
    fn cell_bias(&self) -> Vec<f32> {
        let h = self.hidden();
        let mut b: Vec<f32> = self.b_ih[..2 * h]
            .iter()
            .zip(&self.b_hh[..2 * h])
            .map(|(a, b)| a + b)
            .collect();
        b.extend_from_slice(&self.b_ih[2 * h..]);
        b.extend_from_slice(&self.b_hh[2 * h..]);
        b
    }
}

/// What the forward keeps for the backward, in packed row order.
#[derive(Debug)]
pub struct GruCache {
    /// [K, H]: each row's predecessor h (zero at step 0): the recurrent input, and the left
    /// factor of W_hh's gradient.
    pub h_prev: Array2<f32>,
    /// [K, 3H]: activated gates r, z, n.
    pub gates: Array2<f32>,
    /// [K, H]: W_hn h_prev + b_hn, the recurrent part of n before the reset gate scales it.
    pub hn: Array2<f32>,
}

impl GruCache {
    /// Required shapes for K rows and hidden size `h`.
    pub fn shapes(k: usize, h: usize) -> [(usize, usize); 3] {
        [(k, h), (k, 3 * h), (k, h)]
    }
}

/// Run the GRU from zero states over every sequence of `packing`.
/// x: [K, in] and y: [K, H] (receives h) in packed order; `cache` buffers of
/// [`GruCache::shapes`] (contents overwritten). Panics on inconsistent shapes.
pub fn gru_forward(
    x: ArrayView2<f32>,
    w: &GruWeights,
    packing: &SeqPacking,
    cache: &mut GruCache,
    y: &mut Array2<f32>,
) {
    w.check();
    let (k, input, h) = (packing.total(), w.input(), w.hidden());
    assert_eq!(x.dim(), (k, input), "gru: x must be [K, in]");
    assert_eq!(y.dim(), (k, h), "gru: y must be [K, H]");
    for (buf, shape) in [&cache.h_prev, &cache.gates, &cache.hn]
        .into_iter()
        .zip(GruCache::shapes(k, h))
    {
        assert_eq!(buf.dim(), shape, "gru: cache buffer shape");
    }
    if k == 0 {
        return;
    }
    let n0 = packing.batch_size(0);
    cache.h_prev.slice_mut(s![..n0, ..]).fill(0.0);

    // Right operands in unit-stride layout once, not once per product.
    let w_ih_t = transposed(w.w_ih);
    let w_hh_t = transposed(w.w_hh);
    let bias = w.cell_bias();
    // The recurrent product of one step; zero at step 0, where h_prev = 0.
    let mut rec = Array2::<f32>::zeros((n0, 3 * h));

    // The input product of every step at once: it does not depend on h, and each output
    // element's arithmetic is the same whatever rows a product covers (see `gemm`), so this is
    // the per-step products' bits with one call instead of one per step.
    gemm(x, w_ih_t.view(), cache.gates.view_mut(), Mode::Overwrite);

    let y = y.as_slice_mut().expect("gru: y must be contiguous");
    for t in 0..packing.n_steps() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        if t > 0 {
            gemm(
                cache.h_prev.slice(s![o..o + n, ..]),
                w_hh_t.view(),
                rec.slice_mut(s![..n, ..]),
                Mode::Overwrite,
            );
        }
        let gates =
            &mut cache.gates.as_slice_mut().expect("contiguous")[o * 3 * h..(o + n) * 3 * h];
        let rec = &rec.as_slice().expect("contiguous")[..n * 3 * h];
        let hp = &cache.h_prev.as_slice().expect("contiguous")[o * h..(o + n) * h];
        let hn = &mut cache.hn.as_slice_mut().expect("contiguous")[o * h..(o + n) * h];
        let hs = &mut y[o * h..(o + n) * h];
        forward_cells(gates, rec, &bias, hp, hn, hs, h);
        // The sequences that go on take this h as their next recurrent input.
        let next_n = packing.batch_size(t + 1);
        if next_n > 0 {
            let next_o = packing.offset(t + 1);
            let hp = cache.h_prev.as_slice_mut().expect("contiguous");
            hp[next_o * h..(next_o + next_n) * h].copy_from_slice(&hs[..next_n * h]);
        }
    }
}

/// One GRU step for n rows from given states, values only (no cache, nothing to differentiate):
/// x: [n, in], h_prev: [n, H], h_out: [n, H] (overwritten). It makes the products and the cell
/// pass [`gru_forward`] makes at every step after a sequence's first, and each row's numbers
/// depend on that row alone, so continuing sequences from their last h with this step gives the
/// bits of unrolling them one step longer. Panics on inconsistent shapes.
pub fn gru_step(
    x: ArrayView2<f32>,
    w: &GruWeights,
    h_prev: ArrayView2<f32>,
    h_out: &mut Array2<f32>,
) {
    w.check();
    let (n, h) = (x.nrows(), w.hidden());
    assert_eq!(x.ncols(), w.input(), "gru step: x must be [n, in]");
    assert_eq!(h_prev.dim(), (n, h), "gru step: h_prev must be [n, H]");
    assert_eq!(h_out.dim(), (n, h), "gru step: h_out must be [n, H]");
    if n == 0 {
        return;
    }
    let mut gates = Array2::<f32>::zeros((n, 3 * h));
    gemm(
        x,
        transposed(w.w_ih).view(),
        gates.view_mut(),
        Mode::Overwrite,
    );
    let mut rec = Array2::<f32>::zeros((n, 3 * h));
    gemm(
        h_prev,
        transposed(w.w_hh).view(),
        rec.view_mut(),
        Mode::Overwrite,
    );
    let h_prev = h_prev.as_standard_layout();
    let mut hn = vec![0.0f32; n * h];
    forward_cells(
        gates.as_slice_mut().expect("fresh arrays are contiguous"),
        rec.as_slice().expect("fresh arrays are contiguous"),
        &w.cell_bias(),
        h_prev.as_slice().expect("standard layout is contiguous"),
        &mut hn,
        h_out
            .as_slice_mut()
            .expect("gru step: h_out must be contiguous"),
        h,
    );
}

/// The GRU cell for L lanes: input-side pre-activations `a` [r, z, n], recurrent-side ones `b`
/// (both without biases), the biases [b_ir + b_hr, b_iz + b_hz, b_in, b_hn] and h_prev in;
/// activated gates [r, z, n], b_n = W_hn h_prev + b_hn and h out.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn gru_cell_lanes<const L: usize>(
    a: [[f32; L]; 3],
    b: [[f32; L]; 3],
    bias: [[f32; L]; 4],
    hp: [f32; L],
) -> ([[f32; L]; 3], [f32; L], [f32; L]) {
    let mut gates = [[0.0; L]; 3];
    let (mut hn, mut h) = ([0.0; L], [0.0; L]);
    for l in 0..L {
        let r = sigmoid_approx(a[0][l] + b[0][l] + bias[0][l]);
        let z = sigmoid_approx(a[1][l] + b[1][l] + bias[1][l]);
        hn[l] = b[2][l] + bias[3][l];
        let n = tanh_approx(a[2][l] + bias[2][l] + r * hn[l]);
        // (1 - z) n + z h_prev, as PyTorch's kernel writes it.
        h[l] = n + z * (hp[l] - n);
        (gates[0][l], gates[1][l], gates[2][l]) = (r, z, n);
    }
    (gates, hn, h)
}

/// One row's cells over lanes q0, q0 + L, ... (see [`forward_cells`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn forward_row<const L: usize>(
    q: std::ops::Range<usize>,
    h: usize,
    gates: &mut [f32],
    rec: &[f32],
    bias: &[f32],
    h_prev: &[f32],
    hn: &mut [f32],
    h_out: &mut [f32],
) {
    let mut q0 = q.start;
    while q0 + L <= q.end {
        let a = [rd(gates, q0), rd(gates, h + q0), rd(gates, 2 * h + q0)];
        let b = [rd(rec, q0), rd(rec, h + q0), rd(rec, 2 * h + q0)];
        let bias = [
            rd(bias, q0),
            rd(bias, h + q0),
            rd(bias, 2 * h + q0),
            rd(bias, 3 * h + q0),
        ];
        let (g, hnv, hv) = gru_cell_lanes::<L>(a, b, bias, rd(h_prev, q0));
        for (blk, gv) in g.iter().enumerate() {
            wr(gates, blk * h + q0, gv);
        }
        wr(hn, q0, &hnv);
        wr(h_out, q0, &hv);
        q0 += L;
    }
}

simd_dispatch! {
    /// The pointwise part of one step for its n rows: gates [n, 3H] holds x W_ih^T (activated
    /// in place into r, z, n), rec [n, 3H] holds h_prev W_hh^T, bias \[4H\] is
    /// [b_ir + b_hr, b_iz + b_hz, b_in, b_hn]; h_prev, hn (receives W_hn h_prev + b_hn) and
    /// h_out: [n, H].
    pub fn forward_cells(
        gates: &mut [f32],
        rec: &[f32],
        bias: &[f32],
        h_prev: &[f32],
        hn: &mut [f32],
        h_out: &mut [f32],
        hidden: usize,
    ) {
        let h = hidden;
        let full = h - h % LANES;
        for j in 0..h_out.len() / h {
            let row3 = j * 3 * h..(j + 1) * 3 * h;
            let (g, r) = (&mut gates[row3.clone()], &rec[row3]);
            let cell = j * h..(j + 1) * h;
            let (hp, hnj, hj) = (&h_prev[cell.clone()], &mut hn[cell.clone()], &mut h_out[cell]);
            forward_row::<LANES>(0..full, h, g, r, bias, hp, hnj, hj);
            forward_row::<1>(full..h, h, g, r, bias, hp, hnj, hj);
        }
    }
}

/// Packed rows of gate gradients handed to [`gru_backward`]'s callback at once (as the LSTM's
/// `BACKWARD_CHUNK_ROWS`): enough for efficient products, few enough to still be in L2.
pub const BACKWARD_CHUNK_ROWS: usize = 256;

/// Column blocks of the backward's gate-gradient buffer `dg` [K, 4H]: [da_n, da_r, da_z, r da_n].
/// The input side's gradients dA are its first three blocks (in the row order n, r, z of
/// [`permute_nrz`]`(W_ih)`), the recurrent side's dB = [da_r, da_z, r da_n] its last three (in
/// W_hh's own order r, z, n). One buffer instead of two saves writing the shared r and z
/// blocks twice, so the GRU's backward moves no more memory per gate than the LSTM's.
pub const DG_BLOCKS: [&str; 4] = ["a_n", "r", "z", "b_n"];

/// The rows of a [3H, c] matrix reordered from (r, z, n) to (n, r, z): the right operand of
/// dx = dA `permute_nrz`(W_ih), and (applied to dA^T x) W_ih's gradient in that order.
pub fn permute_nrz(w: ArrayView2<f32>) -> Array2<f32> {
    let h = w.nrows() / 3;
    assert_eq!(w.nrows(), 3 * h, "permute_nrz: rows must be 3H");
    let mut out = Array2::zeros(w.dim());
    out.slice_mut(s![..h, ..]).assign(&w.slice(s![2 * h.., ..]));
    out.slice_mut(s![h.., ..]).assign(&w.slice(s![..2 * h, ..]));
    out
}

/// Gradients of the gate pre-activations given dy = dL/dh, all in packed order, and the
/// forward's cache (`h_prev`, `gates`, `hn`, see [`GruCache`]). `dg`: [K, 4H] (overwritten,
/// blocks as [`DG_BLOCKS`]); `dh_rec`: [batch_size(0), H] scratch; `dbias` \[4H\] receives the
/// column sums of dg (b_ih's gradient is blocks r, z, a_n; b_hh's is blocks r, z, b_n).
/// Steps are processed last to first; whenever at least [`BACKWARD_CHUNK_ROWS`] rows are
/// complete (and at the end), `on_rows(rows, dg)` is called with their packed row range
/// (descending, disjoint, covering 0..K), so the caller can use them while they are in cache.
#[allow(clippy::too_many_arguments)]
pub fn gru_backward(
    dy: ArrayView2<f32>,
    w_hh: ArrayView2<f32>,
    packing: &SeqPacking,
    h_prev: &Array2<f32>,
    gates: &Array2<f32>,
    hn: &Array2<f32>,
    dg: &mut Array2<f32>,
    dh_rec: &mut Array2<f32>,
    dbias: &mut [f32],
    mut on_rows: impl FnMut(std::ops::Range<usize>, &Array2<f32>),
) {
    let (k, h) = (packing.total(), w_hh.ncols());
    assert_eq!(dy.dim(), (k, h), "gru backward: dy must be [K, H]");
    assert_eq!(dg.dim(), (k, 4 * h), "gru backward: dg must be [K, 4H]");
    assert_eq!(dbias.len(), 4 * h, "gru backward: dbias must be [4H]");
    let n0 = packing.batch_size(0);
    assert_eq!(dh_rec.dim(), (n0, h));
    for (buf, shape) in [h_prev, gates, hn].into_iter().zip(GruCache::shapes(k, h)) {
        assert_eq!(buf.dim(), shape, "gru backward: cache buffer shape");
    }
    let dy = dy.as_standard_layout();
    let dy = dy.as_slice().expect("standard layout");
    let gates = gates.as_slice().expect("contiguous");
    let hp_all = h_prev.as_slice().expect("contiguous");
    let hn_all = hn.as_slice().expect("contiguous");
    dbias.fill(0.0);
    // As in the LSTM: rows past a step's continuing sequences are never written by later
    // steps, so zeroing once makes them "nothing carried" where a sequence ends.
    dh_rec.fill(0.0);
    let mut chunk_end = k;

    for t in (0..packing.n_steps()).rev() {
        let (n, o) = (packing.batch_size(t), packing.offset(t));
        let cell = o * h..(o + n) * h;
        backward_cells(
            &dy[cell.clone()],
            &mut dh_rec.as_slice_mut().expect("contiguous")[..n * h],
            &gates[o * 3 * h..(o + n) * 3 * h],
            &hp_all[cell.clone()],
            &hn_all[cell],
            &mut dg.as_slice_mut().expect("contiguous")[o * 4 * h..(o + n) * 4 * h],
            dbias,
            h,
        );
        if t > 0 {
            // dh_rec holds z dh (the direct path); add the path through the gates, dB W_hh.
            gemm(
                dg.slice(s![o..o + n, h..]),
                w_hh,
                dh_rec.slice_mut(s![..n, ..]),
                Mode::Accumulate,
            );
        }
        if chunk_end - o >= BACKWARD_CHUNK_ROWS || t == 0 {
            on_rows(o..chunk_end, dg);
            chunk_end = o;
        }
    }
}

/// The backward of the cell for L lanes: dL/dh (output plus recurrent part) and the forward's
/// gates [r, z, n], h_prev and b_n in; the gate gradients in [`DG_BLOCKS`] order
/// [da_n, da_r, da_z, r da_n] and the direct part z dh of dL/dh_prev out.
#[inline(always)]
fn cell_grad_lanes<const L: usize>(
    dh: [f32; L],
    gates: [[f32; L]; 3],
    hp: [f32; L],
    hn: [f32; L],
) -> ([[f32; L]; 4], [f32; L]) {
    let [r, z, n] = gates;
    let mut d = [[0.0; L]; 4];
    let mut dhp = [0.0; L];
    for l in 0..L {
        // h = n + z (h_prev - n)
        let dn = dh[l] * (1.0 - z[l]);
        let dz = dh[l] * (hp[l] - n[l]);
        let dan = dn * (1.0 - n[l] * n[l]);
        d[0][l] = dan;
        d[1][l] = dan * hn[l] * r[l] * (1.0 - r[l]);
        d[2][l] = dz * z[l] * (1.0 - z[l]);
        d[3][l] = dan * r[l];
        dhp[l] = dh[l] * z[l];
    }
    (d, dhp)
}

/// One row's gate gradients over lanes q0, q0 + L, ... (see [`backward_cells`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn backward_row<const L: usize>(
    q: std::ops::Range<usize>,
    h: usize,
    dy: &[f32],
    dh_rec: &mut [f32],
    gates: &[f32],
    h_prev: &[f32],
    hn: &[f32],
    dg: &mut [f32],
    dbias: &mut [f32],
) {
    let mut q0 = q.start;
    while q0 + L <= q.end {
        let (dyv, dhr): ([f32; L], [f32; L]) = (rd(dy, q0), rd(dh_rec, q0));
        let mut dh = [0.0; L];
        for l in 0..L {
            dh[l] = dyv[l] + dhr[l];
        }
        let g = [rd(gates, q0), rd(gates, h + q0), rd(gates, 2 * h + q0)];
        let (d, dhp) = cell_grad_lanes::<L>(dh, g, rd(h_prev, q0), rd(hn, q0));
        for (blk, dv) in d.iter().enumerate() {
            wr(dg, blk * h + q0, dv);
            let mut sum: [f32; L] = rd(dbias, blk * h + q0);
            for l in 0..L {
                sum[l] += dv[l];
            }
            wr(dbias, blk * h + q0, &sum);
        }
        wr(dh_rec, q0, &dhp);
        q0 += L;
    }
}

simd_dispatch! {
    /// The pointwise part of one backward step for its n rows. dL/dh of row j is its output
    /// gradient dy\[j\] plus dh_rec\[j\], the part through the next step (zero for sequences that
    /// ended here); dh_rec\[j\] is then overwritten with z dh, the direct part of dL/dh_prev.
    /// Writes dg \[n, 4H\] (see [`DG_BLOCKS`]) and adds its column sums to dbias \[4H\].
    /// gates: \[n, 3H\]; h_prev, hn: \[n, H\].
    pub fn backward_cells(
        dy: &[f32],
        dh_rec: &mut [f32],
        gates: &[f32],
        h_prev: &[f32],
        hn: &[f32],
        dg: &mut [f32],
        dbias: &mut [f32],
        hidden: usize,
    ) {
        let h = hidden;
        let full = h - h % LANES;
        for j in 0..dy.len() / h {
            let cell = j * h..(j + 1) * h;
            let (dyj, dhj) = (&dy[cell.clone()], &mut dh_rec[cell.clone()]);
            let (hpj, hnj) = (&h_prev[cell.clone()], &hn[cell]);
            let gj = &gates[j * 3 * h..(j + 1) * 3 * h];
            let dgj = &mut dg[j * 4 * h..(j + 1) * 4 * h];
            backward_row::<LANES>(0..full, h, dyj, dhj, gj, hpj, hnj, dgj, dbias);
            backward_row::<1>(full..h, h, dyj, dhj, gj, hpj, hnj, dgj, dbias);
        }
    }
}
