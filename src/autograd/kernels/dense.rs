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

/// Column `col` of [`linear_forward`]'s output for one input row: act(x · w\[col, :\] + b\[col\])
/// with the bits the whole layer gives there, whatever the CPU (the product's arithmetic, see
/// [`super::gemm`]: per block of `K_BLOCK` consecutive k a chain of fused multiply-adds from 0,
/// each block's sum added to the ones before, then the bias). For a caller that needs a layer at
/// one column per row (a Q-net's value of one chosen action) instead of all of them. Panics if
/// `col` is out of range or `x` is not a row of `w`'s width.
pub fn linear_forward_at(
    x: &[f32],
    w: ArrayView2<f32>,
    b: &[f32],
    act: Activation,
    col: usize,
) -> f32 {
    assert_eq!(x.len(), w.ncols(), "linear_at: input width");
    let row = w.row(col);
    let row = row.as_slice().expect("weights are contiguous rows");
    #[cfg(target_arch = "x86_64")]
    if has_fma() {
        // SAFETY: the CPU has FMA (checked just above).
        return unsafe { linear_forward_at_fma(x, row, b[col], act) };
    }
    linear_forward_at_imp(x, row, b[col], act)
}

/// acc\[i\] = fma(g, x\[i\], acc\[i\]) for every i: one row's term of a product's chains (the
/// fused multiply-add `mul_add` computes, as an instruction where the CPU has one). Panics if
/// the lengths differ.
pub fn fma_row_into(g: f32, x: &[f32], acc: &mut [f32]) {
    assert_eq!(x.len(), acc.len(), "fma_row_into: lengths");
    #[cfg(target_arch = "x86_64")]
    if has_fma() {
        // SAFETY: the CPU has FMA (checked just above).
        return unsafe { fma_row_into_fma(g, x, acc) };
    }
    fma_row_into_imp(g, x, acc)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn fma_row_into_fma(g: f32, x: &[f32], acc: &mut [f32]) {
    fma_row_into_imp(g, x, acc)
}

#[inline(always)]
fn fma_row_into_imp(g: f32, x: &[f32], acc: &mut [f32]) {
    for (a, &v) in acc.iter_mut().zip(x) {
        *a = g.mul_add(v, *a);
    }
}

/// Whether the CPU has FMA (checked once): `mul_add` is then one instruction instead of a call
/// into libm's `fmaf`, with the same result.
#[cfg(target_arch = "x86_64")]
fn has_fma() -> bool {
    static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HAS.get_or_init(|| std::arch::is_x86_feature_detected!("fma"))
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
unsafe fn linear_forward_at_fma(x: &[f32], row: &[f32], b: f32, act: Activation) -> f32 {
    linear_forward_at_imp(x, row, b, act)
}

#[inline(always)]
fn linear_forward_at_imp(x: &[f32], row: &[f32], b: f32, act: Activation) -> f32 {
    let mut sum = 0.0f32;
    let mut k0 = 0;
    while k0 < x.len() {
        let end = (k0 + super::gemm::K_BLOCK).min(x.len());
        let mut acc = 0.0f32;
        for k in k0..end {
            acc = x[k].mul_add(row[k], acc);
        }
        sum = if k0 == 0 { acc } else { acc + sum };
        k0 = end;
    }
    act.apply(sum + b)
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

/// out\[o\] = act(w[o, :] . x + b\[o\]) for w: [out.len(), x.len()] row-major, act a leaky ReLU
/// with `slope` (1 = identity): one layer for one input row (acting). Every output is
/// [`dot`]`(w[o, :], x) + b[o]` through the activation, whatever the CPU.
pub fn matvec_act(w: &[f32], x: &[f32], b: &[f32], slope: f32, out: &mut [f32]) {
    matvec_act_rows(w, x.len(), x, b, slope, out)
}

/// [`matvec_act`] on several input rows at once: out[l * n + o] = act(w[o, :] . xs_l + b\[o\])
/// for every row xs_l of `xs` (rows of `k` values, w: [n, k], n = b.len(), out: rows of n),
/// each output bit for bit [`matvec_act`]'s. Eight outputs are computed side by side (eight
/// independent chains, their final sums in one vector) and each block of eight weight rows is
/// read once for all the input rows, so a layer larger than the caches (Mac-CAC's 64 x 3 375
/// output layer) streams from memory once per lockstep step instead of once per deciding lane.
/// Panics if the lengths are not whole rows.
pub fn matvec_act_rows(w: &[f32], k: usize, xs: &[f32], b: &[f32], slope: f32, out: &mut [f32]) {
    let n = b.len();
    assert!(k > 0 && w.len() == n * k, "matvec_act: weight shape");
    assert!(
        xs.len().is_multiple_of(k) && out.len() == xs.len() / k * n,
        "matvec_act: input and output rows"
    );
    #[cfg(target_arch = "x86_64")]
    if avx2::available() {
        // SAFETY: the CPU has AVX2 (checked); the lengths are checked above.
        unsafe { avx2::matvec_act_rows(w, k, xs, b, slope, out) };
        return;
    }
    for (o, (row, &bv)) in w.chunks_exact(k).zip(b).enumerate() {
        for (x, y) in xs.chunks_exact(k).zip(out.chunks_exact_mut(n)) {
            y[o] = act_out(dot(row, x) + bv, slope);
        }
    }
}

/// The activation of [`matvec_act`]: z for z > 0, slope * z otherwise.
#[inline(always)]
fn act_out(z: f32, slope: f32) -> f32 {
    if z > 0.0 {
        z
    } else {
        slope * z
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    //! [`super::matvec_act_rows`] eight outputs at a time: one 8-wide accumulator per output
    //! holds [`super::dot`]'s eight partial sums, and its final sums
    //! ((p0 + p4) + (p1 + p5)) + ((p2 + p6) + (p3 + p7)) are formed for the eight outputs
    //! together (the halves added, then two horizontal pair additions, which add exactly those
    //! pairs). Separate multiplies and adds, never fused, as `dot` computes.

    use std::arch::x86_64::*;
    use std::sync::OnceLock;

    use super::{act_out, dot};

    /// Whether this CPU runs the kernel (checked once).
    pub fn available() -> bool {
        static HAS: OnceLock<bool> = OnceLock::new();
        *HAS.get_or_init(|| std::arch::is_x86_feature_detected!("avx2"))
    }

    /// # Safety
    /// The CPU supports AVX2; w holds b.len() rows of k, xs whole rows of k, out as many rows
    /// of b.len().
    #[target_feature(enable = "avx2")]
    pub unsafe fn matvec_act_rows(
        w: &[f32],
        k: usize,
        xs: &[f32],
        b: &[f32],
        slope: f32,
        out: &mut [f32],
    ) {
        let n = b.len();
        let rows = xs.len() / k;
        let whole = k / 8 * 8;
        let zero = _mm256_setzero_ps();
        let slope_v = _mm256_set1_ps(slope);
        // The horizontal additions leave outputs 0, 2, 4, 6, 1, 3, 5, 7; this puts them back.
        let order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
        let mut o = 0;
        while o + 8 <= n {
            let rows_w = &w[o * k..(o + 8) * k];
            let bv = _mm256_loadu_ps(b.as_ptr().add(o));
            for l in 0..rows {
                let x = &xs[l * k..(l + 1) * k];
                let mut acc = [zero; 8];
                let mut c = 0;
                while c < whole {
                    let xv = _mm256_loadu_ps(x.as_ptr().add(c));
                    for (r, a) in acc.iter_mut().enumerate() {
                        let wv = _mm256_loadu_ps(rows_w.as_ptr().add(r * k + c));
                        *a = _mm256_add_ps(*a, _mm256_mul_ps(wv, xv));
                    }
                    c += 8;
                }
                // Each accumulator's low half plus its high half (p_j + p_(j+4)), two outputs
                // per vector.
                let halves = |a: __m256, b: __m256| {
                    _mm256_add_ps(
                        _mm256_permute2f128_ps::<0x20>(a, b),
                        _mm256_permute2f128_ps::<0x31>(a, b),
                    )
                };
                let s01 = halves(acc[0], acc[1]);
                let s23 = halves(acc[2], acc[3]);
                let s45 = halves(acc[4], acc[5]);
                let s67 = halves(acc[6], acc[7]);
                let sums = _mm256_hadd_ps(_mm256_hadd_ps(s01, s23), _mm256_hadd_ps(s45, s67));
                let sums = _mm256_permutevar8x32_ps(sums, order);
                // dot's tail: the products past the last whole chunk, added one by one from 0.
                let mut tails = [0.0f32; 8];
                for (r, t) in tails.iter_mut().enumerate() {
                    let row = &rows_w[r * k..(r + 1) * k];
                    for (wq, xq) in row[whole..].iter().zip(&x[whole..]) {
                        *t += wq * xq;
                    }
                }
                let z = _mm256_add_ps(_mm256_add_ps(sums, _mm256_loadu_ps(tails.as_ptr())), bv);
                let positive = _mm256_cmp_ps::<_CMP_GT_OQ>(z, zero);
                let y = _mm256_blendv_ps(_mm256_mul_ps(slope_v, z), z, positive);
                _mm256_storeu_ps(out.as_mut_ptr().add(l * n + o), y);
            }
            o += 8;
        }
        for o in o..n {
            let row = &w[o * k..(o + 1) * k];
            for l in 0..rows {
                out[l * n + o] = act_out(dot(row, &xs[l * k..(l + 1) * k]) + b[o], slope);
            }
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
    fn one_column_is_the_whole_layers_bits() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        // Widths inside one product block, on its edge and across two and three blocks.
        for k in [1, 7, 64, 384, 385, 800, 1200] {
            let (m, n) = (5, 19);
            let mut r = |len| -> Vec<f32> { (0..len).map(|_| rng.gen_range(-2.0..2.0)).collect() };
            let x = ndarray::Array2::from_shape_vec((m, k), r(m * k)).unwrap();
            let w = ndarray::Array2::from_shape_vec((n, k), r(n * k)).unwrap();
            let b = r(n);
            for act in [Activation::Identity, Activation::LEAKY_001] {
                let mut y = ndarray::Array2::zeros((m, n));
                linear_forward(x.view(), w.view(), &b, act, y.view_mut());
                for i in 0..m {
                    let row = x.row(i).to_vec();
                    for j in 0..n {
                        let one = linear_forward_at(&row, w.view(), &b, act, j);
                        assert_eq!(one.to_bits(), y[[i, j]].to_bits(), "k {k} row {i} col {j}");
                    }
                }
            }
        }
    }

    #[test]
    fn dot_handles_lengths_that_are_not_multiples_of_eight() {
        let a: Vec<f32> = (0..13).map(|i| i as f32).collect();
        let b = vec![1.0f32; 13];
        assert_eq!(dot(&a, &b), 78.0);
    }

    #[test]
    fn every_output_is_the_scalar_dot_through_the_activation_bit_for_bit() {
        // Output counts around the 8-output blocks, lengths with and without dot's tail, one
        // row and several, both slopes; a NaN and infinities in one input row.
        for (k, n, rows, slope) in [
            (64, 37, 5, 1.0f32),
            (13, 9, 3, 0.01),
            (8, 1, 1, 1.0),
            (3, 16, 2, 0.01),
            (70, 3375, 2, 1.0),
        ] {
            let val = |i: usize, s: usize| (((i * s) % 97) as f32 / 13.0 - 3.7).sin() * 1.3;
            let w: Vec<f32> = (0..n * k).map(|i| val(i, 31)).collect();
            let b: Vec<f32> = (0..n).map(|i| val(i, 7) * 0.1).collect();
            let mut xs: Vec<f32> = (0..rows * k).map(|i| val(i, 11)).collect();
            if rows > 2 {
                xs[k] = f32::NAN;
                xs[2 * k] = f32::INFINITY;
                xs[2 * k + 1] = f32::NEG_INFINITY;
            }
            let mut out = vec![f32::NAN; rows * n];
            matvec_act_rows(&w, k, &xs, &b, slope, &mut out);
            let bits = |v: f32| v.to_bits();
            for (l, (x, got)) in xs.chunks_exact(k).zip(out.chunks_exact(n)).enumerate() {
                for (o, row) in w.chunks_exact(k).enumerate() {
                    let want = act_out(dot(row, x) + b[o], slope);
                    assert_eq!(bits(got[o]), bits(want), "k {k} n {n} row {l} output {o}");
                }
                let mut one = vec![f32::NAN; n];
                matvec_act(&w, x, &b, slope, &mut one);
                assert_eq!(
                    one.iter().map(|&v| bits(v)).collect::<Vec<_>>(),
                    got.iter().map(|&v| bits(v)).collect::<Vec<_>>()
                );
            }
        }
    }
}
