//! Matrix products, the bulk of every update's arithmetic.
//!
//! One entry point, [`gemm`], and one arithmetic whatever the CPU: every output element is,
//! for each block of [`K_BLOCK`] consecutive k (in order), a chain of fused multiply-adds
//! `acc = fma(a[i][k], b[k][j], acc)` from `acc = 0`, after which the block's sum is added to
//! what the element holds (`acc + c`, skipped for the first block of an overwrite). Vector
//! width, tile shape and row/column order change nothing in that per-element sequence, so the
//! three kernels give the same bits and a run trained on one CPU family retrains exactly on
//! another: `avx512` (ours, ~110 GFLOP/s on one core at every shape the Q-nets use, against
//! 45-105 for `matrixmultiply`, whose packing dominates the small per-step recurrent products),
//! `avx2` (the same tiles, 8 lanes, with FMA) and `portable` (element by element with
//! `f32::mul_add`: any layout, any CPU). All run on the calling thread only, so thread count
//! never changes a number.

use ndarray::{Array2, ArrayView2, ArrayViewMut2};

/// Consecutive k summed in one chain before the chain's sum is added into the output: part of
/// the arithmetic every kernel shares (it also keeps the slices of A and B a tile row walks in
/// L2).
pub const K_BLOCK: usize = 384;

/// How a product lands in its destination.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// c = a · b; the old contents of c are never read (may be garbage from the buffer pool).
    Overwrite,
    /// c += a · b.
    Accumulate,
}

/// c (=|+=) a · b with a: [m, k], b: [k, n], c: [m, n]. Any strides (pass `.t()` views for
/// transposes); b with non-unit column stride is copied to a contiguous buffer first, so hot
/// loops should pass b pre-transposed (see [`transposed`]). Panics on mismatched shapes.
pub fn gemm(a: ArrayView2<f32>, b: ArrayView2<f32>, mut c: ArrayViewMut2<f32>, mode: Mode) {
    assert_eq!(a.ncols(), b.nrows(), "gemm: inner dimensions differ");
    assert_eq!(c.dim(), (a.nrows(), b.ncols()), "gemm: output shape");
    let (m, k, n) = (a.nrows(), a.ncols(), b.ncols());
    if m == 0 || n == 0 {
        return;
    }
    if k == 0 {
        if mode == Mode::Overwrite {
            c.fill(0.0);
        }
        return;
    }
    #[cfg(target_arch = "x86_64")]
    {
        let simd = if avx512::available() {
            Some(avx512::gemm_views as SimdKernel)
        } else if avx2::available() {
            Some(avx2::gemm_views as SimdKernel)
        } else {
            None
        };
        let nonneg = a.strides().iter().chain(b.strides()).all(|&s| s >= 0);
        if let Some(kernel) = simd.filter(|_| nonneg && c.strides()[1] == 1 && c.strides()[0] >= 0)
        {
            if b.strides()[1] == 1 {
                // SAFETY: the CPU has the kernel's features (checked above), the views describe
                // valid memory for their shapes and strides (all non-negative), b and c have
                // unit column stride, and c does not alias a or b (it is borrowed mutably while
                // they are borrowed).
                unsafe { kernel(a, b, c, mode) };
            } else {
                // b in standard layout, as the transpose of b^T: x · W^T passes W.t(), so
                // W is contiguous and takes the register-block path of `transposed`.
                let bt = transposed(b.t());
                // SAFETY: as above; `bt` is a fresh standard-layout array.
                unsafe { kernel(a, bt.view(), c, mode) };
            }
            return;
        }
    }
    portable(a, b, c.view_mut(), mode);
}

/// A vector kernel's entry point (`avx512::gemm_views`, `avx2::gemm_views`).
#[cfg(target_arch = "x86_64")]
type SimdKernel = unsafe fn(ArrayView2<f32>, ArrayView2<f32>, ArrayViewMut2<f32>, Mode);

/// The shared arithmetic element by element, for any layout and CPU: the definition the vector
/// kernels reproduce.
fn portable(a: ArrayView2<f32>, b: ArrayView2<f32>, mut c: ArrayViewMut2<f32>, mode: Mode) {
    let (m, k, n) = (a.nrows(), a.ncols(), b.ncols());
    for i in 0..m {
        for j in 0..n {
            let mut k0 = 0;
            while k0 < k {
                let end = (k0 + K_BLOCK).min(k);
                let mut acc = 0.0f32;
                for q in k0..end {
                    acc = a[[i, q]].mul_add(b[[q, j]], acc);
                }
                if mode == Mode::Accumulate || k0 > 0 {
                    acc += c[[i, j]];
                }
                c[[i, j]] = acc;
                k0 = end;
            }
        }
    }
}

/// src^T as a standard-layout array (e.g. a weight W [out, in] into W^T, the right operand of
/// x W^T, once per pass instead of once per product).
///
/// Every LSTM forward transposes both its weights, and ndarray's element-by-element strided
/// copy took 3-6% of a Warehouse run; a contiguous source goes through 16 x 16 register
/// transposes instead (about 4x faster). Values are moved, never computed, so no number
/// depends on the path.
pub fn transposed(src: ArrayView2<f32>) -> Array2<f32> {
    let (rows, cols) = src.dim();
    let Some(s) = src.as_slice() else {
        return src.t().as_standard_layout().into_owned();
    };
    let mut out = vec![0.0f32; rows * cols];
    #[cfg(target_arch = "x86_64")]
    if avx512::available() {
        // SAFETY: the CPU has AVX-512F; `s` holds rows x cols values and `out` as many.
        unsafe { avx512::transpose(s, rows, cols, &mut out) };
        return Array2::from_shape_vec((cols, rows), out).expect("cols x rows values");
    }
    transpose_portable(s, rows, cols, &mut out);
    Array2::from_shape_vec((cols, rows), out).expect("cols x rows values")
}

/// out[j * rows + i] = s[i * cols + j], element by element (CPUs without AVX-512).
fn transpose_portable(s: &[f32], rows: usize, cols: usize, out: &mut [f32]) {
    for (j, column) in out.chunks_exact_mut(rows.max(1)).take(cols).enumerate() {
        for (i, v) in column.iter_mut().enumerate() {
            *v = s[i * cols + j];
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    //! C[m, n] (=|+=) A[m, k] · B[k, n] for A with any strides and B, C with unit column
    //! stride. Register tile: 8 rows x 32 columns (16 zmm accumulators); each step broadcasts
    //! one A entry per row and multiplies it into two vectors of a B row. Columns past n are
    //! masked, rows past m use a shorter tile. k is split in blocks of 384 so the slices of A
    //! and B a tile row walks stay in L2.

    use std::arch::x86_64::*;
    use std::sync::OnceLock;

    use super::Mode;
    use ndarray::{ArrayView2, ArrayViewMut2};

    const MR: usize = 8;
    const NR: usize = 32;
    const KC: usize = super::K_BLOCK;

    /// Whether this CPU runs the kernel (checked once).
    pub fn available() -> bool {
        static HAS: OnceLock<bool> = OnceLock::new();
        *HAS.get_or_init(|| std::arch::is_x86_feature_detected!("avx512f"))
    }

    /// # Safety
    /// The CPU supports AVX-512F; the views are valid with non-negative strides; b and c have
    /// unit column stride; c does not overlap a or b.
    pub unsafe fn gemm_views(
        a: ArrayView2<f32>,
        b: ArrayView2<f32>,
        mut c: ArrayViewMut2<f32>,
        mode: Mode,
    ) {
        let (m, k, n) = (a.nrows(), a.ncols(), b.ncols());
        let (rsa, csa) = (a.strides()[0], a.strides()[1]);
        let rsb = b.strides()[0];
        let rsc = c.strides()[0];
        gemm(
            m,
            n,
            k,
            a.as_ptr(),
            rsa,
            csa,
            b.as_ptr(),
            rsb,
            c.as_mut_ptr(),
            rsc,
            mode == Mode::Accumulate,
        );
    }

    #[target_feature(enable = "avx512f")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn gemm(
        m: usize,
        n: usize,
        k: usize,
        a: *const f32,
        rsa: isize,
        csa: isize,
        b: *const f32,
        rsb: isize,
        c: *mut f32,
        rsc: isize,
        accumulate: bool,
    ) {
        // Narrow outputs (n <= 16, e.g. a Q-net's last layer with 3 or 8 actions) use a tall
        // 16 x 16 tile so fewer masked lanes are wasted.
        let (mr, narrow) = if n <= 16 { (16, true) } else { (MR, false) };
        let mut k0 = 0;
        while k0 < k {
            let kc = (k - k0).min(KC);
            let (ak, bk) = (a.offset(k0 as isize * csa), b.offset(k0 as isize * rsb));
            let acc = accumulate || k0 > 0;
            let mut i = 0;
            while i < m {
                let rows = (m - i).min(mr);
                let (ai, ci) = (ak.offset(i as isize * rsa), c.offset(i as isize * rsc));
                let mut j = 0;
                while j < n {
                    let cols = (n - j).min(NR);
                    let t = Tile {
                        k: kc,
                        a: ai,
                        rsa,
                        csa,
                        b: bk.add(j),
                        rsb,
                        c: ci.add(j),
                        rsc,
                        m0: lane_mask(cols),
                        m1: lane_mask(cols.saturating_sub(16)),
                    };
                    if narrow {
                        if rows == 16 {
                            t.run_narrow::<16>(acc)
                        } else {
                            t.run_narrow_partial(rows, acc)
                        }
                    } else {
                        match rows {
                            8 => t.run::<8>(acc),
                            7 => t.run::<7>(acc),
                            6 => t.run::<6>(acc),
                            5 => t.run::<5>(acc),
                            4 => t.run::<4>(acc),
                            3 => t.run::<3>(acc),
                            2 => t.run::<2>(acc),
                            _ => t.run::<1>(acc),
                        }
                    }
                    j += NR;
                }
                i += mr;
            }
            k0 += kc;
        }
    }

    /// out[j * rows + i] = s[i * cols + j]: whole 16 x 16 blocks in registers, the ragged
    /// right and bottom edges element by element.
    ///
    /// # Safety
    /// The CPU supports AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub unsafe fn transpose(s: &[f32], rows: usize, cols: usize, out: &mut [f32]) {
        assert!(s.len() == rows * cols && out.len() == rows * cols);
        let (full_rows, full_cols) = (rows / 16 * 16, cols / 16 * 16);
        for i0 in (0..full_rows).step_by(16) {
            for j0 in (0..full_cols).step_by(16) {
                // SAFETY: rows i0..i0+16 and columns j0..j0+16 lie inside both matrices.
                block16(
                    s.as_ptr().add(i0 * cols + j0),
                    cols,
                    out.as_mut_ptr().add(j0 * rows + i0),
                    rows,
                );
            }
        }
        for i in 0..rows {
            let first_col = if i < full_rows { full_cols } else { 0 };
            for j in first_col..cols {
                out[j * rows + i] = s[i * cols + j];
            }
        }
    }

    /// One 16 x 16 block: 16 row loads, four shuffle stages (32-bit pairs, 64-bit pairs, then
    /// 128-bit lanes twice), 16 row stores of the transpose.
    #[inline(always)]
    unsafe fn block16(src: *const f32, src_stride: usize, dst: *mut f32, dst_stride: usize) {
        let mut r = [_mm512_setzero_ps(); 16];
        for (i, v) in r.iter_mut().enumerate() {
            *v = _mm512_loadu_ps(src.add(i * src_stride));
        }
        let mut t = [_mm512_setzero_ps(); 16];
        for i in 0..8 {
            t[2 * i] = _mm512_unpacklo_ps(r[2 * i], r[2 * i + 1]);
            t[2 * i + 1] = _mm512_unpackhi_ps(r[2 * i], r[2 * i + 1]);
        }
        for i in 0..4 {
            let a0 = _mm512_castps_pd(t[4 * i]);
            let a1 = _mm512_castps_pd(t[4 * i + 1]);
            let b0 = _mm512_castps_pd(t[4 * i + 2]);
            let b1 = _mm512_castps_pd(t[4 * i + 3]);
            r[4 * i] = _mm512_castpd_ps(_mm512_unpacklo_pd(a0, b0));
            r[4 * i + 1] = _mm512_castpd_ps(_mm512_unpackhi_pd(a0, b0));
            r[4 * i + 2] = _mm512_castpd_ps(_mm512_unpacklo_pd(a1, b1));
            r[4 * i + 3] = _mm512_castpd_ps(_mm512_unpackhi_pd(a1, b1));
        }
        for i in 0..2 {
            for j in 0..4 {
                let (a, b) = (r[8 * i + j], r[8 * i + 4 + j]);
                t[8 * i + j] = _mm512_shuffle_f32x4::<0x88>(a, b);
                t[8 * i + 4 + j] = _mm512_shuffle_f32x4::<0xdd>(a, b);
            }
        }
        for j in 0..8 {
            let (a, b) = (t[j], t[8 + j]);
            r[j] = _mm512_shuffle_f32x4::<0x88>(a, b);
            r[8 + j] = _mm512_shuffle_f32x4::<0xdd>(a, b);
        }
        for (q, v) in r.iter().enumerate() {
            _mm512_storeu_ps(dst.add(q * dst_stride), *v);
        }
    }

    /// The first min(cols, 16) lanes.
    #[inline(always)]
    fn lane_mask(cols: usize) -> __mmask16 {
        if cols >= 16 {
            0xffff
        } else {
            ((1u32 << cols) - 1) as __mmask16
        }
    }

    /// One register tile's operands.
    #[derive(Clone, Copy)]
    struct Tile {
        k: usize,
        a: *const f32,
        rsa: isize,
        csa: isize,
        b: *const f32,
        rsb: isize,
        c: *mut f32,
        rsc: isize,
        m0: __mmask16,
        m1: __mmask16,
    }

    impl Tile {
        /// The leftover rows (< 16) of a narrow product, in tiles of 8, 4, 2, 1 rows.
        #[inline(always)]
        unsafe fn run_narrow_partial(&self, rows: usize, accumulate: bool) {
            let mut done = 0;
            for step in [8, 4, 2, 1] {
                while rows - done >= step {
                    let t = Tile {
                        a: self.a.offset(done as isize * self.rsa),
                        c: self.c.offset(done as isize * self.rsc),
                        ..*self
                    };
                    match step {
                        8 => t.run_narrow::<8>(accumulate),
                        4 => t.run_narrow::<4>(accumulate),
                        2 => t.run_narrow::<2>(accumulate),
                        _ => t.run_narrow::<1>(accumulate),
                    }
                    done += step;
                }
            }
        }

        /// C[0..R, 0..16] (=|+=) A[0..R, 0..k] · B[0..k, 0..16] under the first column mask
        /// (one vector per row).
        #[inline(always)]
        unsafe fn run_narrow<const R: usize>(&self, accumulate: bool) {
            let mut acc = [_mm512_setzero_ps(); R];
            let (mut ap, mut bp) = (self.a, self.b);
            for _ in 0..self.k {
                let b0 = _mm512_maskz_loadu_ps(self.m0, bp);
                for (r, a) in acc.iter_mut().enumerate() {
                    let av = _mm512_set1_ps(*ap.offset(r as isize * self.rsa));
                    *a = _mm512_fmadd_ps(av, b0, *a);
                }
                ap = ap.offset(self.csa);
                bp = bp.offset(self.rsb);
            }
            for (r, a) in acc.iter_mut().enumerate() {
                let cp = self.c.offset(r as isize * self.rsc);
                if accumulate {
                    *a = _mm512_add_ps(*a, _mm512_maskz_loadu_ps(self.m0, cp));
                }
                _mm512_mask_storeu_ps(cp, self.m0, *a);
            }
        }

        /// C[0..R, 0..32] (=|+=) A[0..R, 0..k] · B[0..k, 0..32] under the column masks.
        #[inline(always)]
        unsafe fn run<const R: usize>(&self, accumulate: bool) {
            let mut acc0 = [_mm512_setzero_ps(); R];
            let mut acc1 = [_mm512_setzero_ps(); R];
            let (mut ap, mut bp) = (self.a, self.b);
            for _ in 0..self.k {
                let b0 = _mm512_maskz_loadu_ps(self.m0, bp);
                let b1 = _mm512_maskz_loadu_ps(self.m1, bp.add(16));
                for r in 0..R {
                    let av = _mm512_set1_ps(*ap.offset(r as isize * self.rsa));
                    acc0[r] = _mm512_fmadd_ps(av, b0, acc0[r]);
                    acc1[r] = _mm512_fmadd_ps(av, b1, acc1[r]);
                }
                ap = ap.offset(self.csa);
                bp = bp.offset(self.rsb);
            }
            for r in 0..R {
                let cp = self.c.offset(r as isize * self.rsc);
                if accumulate {
                    acc0[r] = _mm512_add_ps(acc0[r], _mm512_maskz_loadu_ps(self.m0, cp));
                    acc1[r] = _mm512_add_ps(acc1[r], _mm512_maskz_loadu_ps(self.m1, cp.add(16)));
                }
                _mm512_mask_storeu_ps(cp, self.m0, acc0[r]);
                _mm512_mask_storeu_ps(cp.add(16), self.m1, acc1[r]);
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    //! The `avx512` kernel's arithmetic on CPUs with AVX2 and FMA but not AVX-512. Register
    //! tiles of R rows x V vectors of 8 columns: 4 x 2 for whole row blocks, 3 x 2, and 2 x 4 or
    //! 1 x 4 for the last rows, so even a single row (acting on one observation) keeps four
    //! independent FMA chains in flight. Each step broadcasts one A entry per row into the
    //! tile's B vectors. Whole tiles load and store plainly; the ragged right edge loads B under
    //! a lane mask (masked lanes read zeros and never fault) and writes C through a buffer
    //! (masked stores are slow on some AVX2 CPUs).

    use std::arch::x86_64::*;
    use std::sync::OnceLock;

    use super::Mode;
    use ndarray::{ArrayView2, ArrayViewMut2};

    const MR: usize = 6;
    const KC: usize = super::K_BLOCK;

    /// Whether this CPU runs the kernel (checked once).
    pub fn available() -> bool {
        static HAS: OnceLock<bool> = OnceLock::new();
        *HAS.get_or_init(|| {
            std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
        })
    }

    /// # Safety
    /// The CPU supports AVX2 and FMA; the views are valid with non-negative strides; b and c
    /// have unit column stride; c does not overlap a or b.
    pub unsafe fn gemm_views(
        a: ArrayView2<f32>,
        b: ArrayView2<f32>,
        mut c: ArrayViewMut2<f32>,
        mode: Mode,
    ) {
        let (m, k, n) = (a.nrows(), a.ncols(), b.ncols());
        let (rsa, csa) = (a.strides()[0], a.strides()[1]);
        let rsb = b.strides()[0];
        let rsc = c.strides()[0];
        gemm(
            m,
            n,
            k,
            a.as_ptr(),
            rsa,
            csa,
            b.as_ptr(),
            rsb,
            c.as_mut_ptr(),
            rsc,
            mode == Mode::Accumulate,
        );
    }

    #[target_feature(enable = "avx2,fma")]
    #[allow(clippy::too_many_arguments)]
    unsafe fn gemm(
        m: usize,
        n: usize,
        k: usize,
        a: *const f32,
        rsa: isize,
        csa: isize,
        b: *const f32,
        rsb: isize,
        c: *mut f32,
        rsc: isize,
        accumulate: bool,
    ) {
        let mut k0 = 0;
        while k0 < k {
            let kc = (k - k0).min(KC);
            let (ak, bk) = (a.offset(k0 as isize * csa), b.offset(k0 as isize * rsb));
            let acc = accumulate || k0 > 0;
            let mut i = 0;
            while i < m {
                let rows = (m - i).min(MR);
                // Vectors per tile row: 2 for 3-6 rows, 4 for 1-2 (enough independent chains;
                // 6 x 2 accumulators, 2 B vectors and a broadcast fill the 16 registers).
                let nr = if rows >= 3 { 16 } else { 32 };
                let (ai, ci) = (ak.offset(i as isize * rsa), c.offset(i as isize * rsc));
                let mut j = 0;
                while j < n {
                    let cols = (n - j).min(nr);
                    let t = Tile {
                        k: kc,
                        a: ai,
                        rsa,
                        csa,
                        b: bk.add(j),
                        rsb,
                        c: ci.add(j),
                        rsc,
                        cols,
                    };
                    match rows {
                        6 => t.run::<6, 2>(acc),
                        5 => t.run::<5, 2>(acc),
                        4 => t.run::<4, 2>(acc),
                        3 => t.run::<3, 2>(acc),
                        2 => t.run::<2, 4>(acc),
                        _ => t.run::<1, 4>(acc),
                    }
                    j += nr;
                }
                i += MR;
            }
            k0 += kc;
        }
    }

    /// All lanes below min(cols, 8) set (as `maskload` reads them: the sign bit).
    #[inline(always)]
    unsafe fn lane_mask(cols: usize) -> __m256i {
        let lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        _mm256_cmpgt_epi32(_mm256_set1_epi32(cols.min(8) as i32), lanes)
    }

    /// One register tile's operands.
    #[derive(Clone, Copy)]
    struct Tile {
        k: usize,
        a: *const f32,
        rsa: isize,
        csa: isize,
        b: *const f32,
        rsb: isize,
        c: *mut f32,
        rsc: isize,
        /// Columns of the tile inside the product (at most 8 V).
        cols: usize,
    }

    impl Tile {
        /// C[0..R, 0..cols] (=|+=) A[0..R, 0..k] · B[0..k, 0..cols], cols <= 8 V <= 32.
        #[inline(always)]
        unsafe fn run<const R: usize, const V: usize>(&self, accumulate: bool) {
            let full = self.cols == 8 * V;
            let mut acc = [[_mm256_setzero_ps(); V]; R];
            let (mut ap, mut bp) = (self.a, self.b);
            if full {
                for _ in 0..self.k {
                    let mut b = [_mm256_setzero_ps(); V];
                    for (v, bv) in b.iter_mut().enumerate() {
                        *bv = _mm256_loadu_ps(bp.add(8 * v));
                    }
                    self.step::<R, V>(ap, &b, &mut acc);
                    ap = ap.offset(self.csa);
                    bp = bp.offset(self.rsb);
                }
            } else {
                let mut masks = [_mm256_setzero_si256(); V];
                for (v, mask) in masks.iter_mut().enumerate() {
                    *mask = lane_mask(self.cols.saturating_sub(8 * v));
                }
                for _ in 0..self.k {
                    let mut b = [_mm256_setzero_ps(); V];
                    for (v, bv) in b.iter_mut().enumerate() {
                        *bv = _mm256_maskload_ps(bp.add(8 * v), masks[v]);
                    }
                    self.step::<R, V>(ap, &b, &mut acc);
                    ap = ap.offset(self.csa);
                    bp = bp.offset(self.rsb);
                }
            }
            for (r, row) in acc.iter().enumerate() {
                let cp = self.c.offset(r as isize * self.rsc);
                if full {
                    for (v, &x) in row.iter().enumerate() {
                        let x = if accumulate {
                            _mm256_add_ps(x, _mm256_loadu_ps(cp.add(8 * v)))
                        } else {
                            x
                        };
                        _mm256_storeu_ps(cp.add(8 * v), x);
                    }
                } else {
                    let mut buf = [0.0f32; 32];
                    for (v, &x) in row.iter().enumerate() {
                        _mm256_storeu_ps(buf.as_mut_ptr().add(8 * v), x);
                    }
                    for (q, &x) in buf.iter().take(self.cols).enumerate() {
                        let out = cp.add(q);
                        *out = if accumulate { x + *out } else { x };
                    }
                }
            }
        }

        /// One k: every row's A entry times the tile's B vectors, into the accumulators.
        #[inline(always)]
        unsafe fn step<const R: usize, const V: usize>(
            &self,
            ap: *const f32,
            b: &[__m256; V],
            acc: &mut [[__m256; V]; R],
        ) {
            for (r, row) in acc.iter_mut().enumerate() {
                let av = _mm256_set1_ps(*ap.offset(r as isize * self.rsa));
                for (x, &bv) in row.iter_mut().zip(b) {
                    *x = _mm256_fmadd_ps(av, bv, *x);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::s;

    #[test]
    fn overwrite_ignores_old_contents_and_accumulate_adds() {
        let a = Array2::from_shape_vec((2, 3), vec![1., 2., 3., 4., 5., 6.]).unwrap();
        let b = Array2::from_shape_vec((3, 2), vec![1., 0., 0., 1., 1., 1.]).unwrap();
        let mut c = Array2::from_elem((2, 2), f32::NAN);
        gemm(a.view(), b.view(), c.view_mut(), Mode::Overwrite);
        // [1 2 3; 4 5 6] · [1 0; 0 1; 1 1] = [4 5; 10 11]
        assert_eq!(
            c,
            Array2::from_shape_vec((2, 2), vec![4., 5., 10., 11.]).unwrap()
        );
        gemm(a.view(), b.view(), c.view_mut(), Mode::Accumulate);
        assert_eq!(
            c,
            Array2::from_shape_vec((2, 2), vec![8., 10., 20., 22.]).unwrap()
        );
    }

    #[test]
    fn empty_inner_dimension_gives_zero() {
        let a = Array2::<f32>::zeros((2, 0));
        let b = Array2::<f32>::zeros((0, 3));
        let mut c = Array2::from_elem((2, 3), 7.0);
        gemm(a.view(), b.view(), c.view_mut(), Mode::Overwrite);
        assert!(c.iter().all(|&v| v == 0.0));
    }

    /// Reference product in f64.
    fn naive(a: ArrayView2<f32>, b: ArrayView2<f32>) -> Array2<f64> {
        Array2::from_shape_fn((a.nrows(), b.ncols()), |(i, j)| {
            (0..a.ncols())
                .map(|q| a[[i, q]] as f64 * b[[q, j]] as f64)
                .sum()
        })
    }

    #[test]
    fn every_tile_edge_and_stride_case_matches_a_naive_product() {
        // Sizes around the 8 x 32 and 16 x 16 tiles and the 384 k-block; strided, transposed and
        // sliced views.
        for &(m, k, n) in &[
            (1, 1, 1),
            (7, 3, 33),
            (8, 5, 32),
            (9, 17, 16),
            (17, 400, 47),
            (3, 800, 65),
            (31, 9, 3),
            (16, 5, 8),
            (45, 390, 16),
        ] {
            let a = Array2::from_shape_fn((m, k + 2), |(i, j)| {
                ((i * 31 + j * 17) % 13) as f32 / 7.0 - 0.9
            });
            let bt =
                Array2::from_shape_fn((n, k), |(i, j)| ((i * 7 + j * 3) % 11) as f32 / 5.0 - 1.0);
            let av = a.slice(s![.., 1..k + 1]);
            for b in [bt.t(), bt.t().as_standard_layout().view().to_owned().view()] {
                let want = naive(av, b);
                let mut c = Array2::from_elem((m, n), f32::NAN);
                gemm(av, b, c.view_mut(), Mode::Overwrite);
                gemm(av, b, c.view_mut(), Mode::Accumulate);
                for ((i, j), &w) in want.indexed_iter() {
                    let got = c[[i, j]] as f64;
                    assert!(
                        (got - 2.0 * w).abs() < 1e-4 * (1.0 + w.abs()),
                        "{m}x{k}x{n} at {i},{j}: {got} vs {}",
                        2.0 * w
                    );
                }
            }
            // transposed A
            let at = av.t().to_owned();
            let b = bt.t().to_owned();
            let want = naive(at.t(), b.view());
            let mut c = Array2::zeros((m, n));
            gemm(at.t(), b.view(), c.view_mut(), Mode::Overwrite);
            for ((i, j), &w) in want.indexed_iter() {
                assert!((c[[i, j]] as f64 - w).abs() < 1e-4 * (1.0 + w.abs()));
            }
        }
    }

    /// Every kernel this CPU can run, by name, as `gemm` would call it (b and c contiguous).
    fn kernels() -> Vec<(&'static str, GemmFn)> {
        #[allow(unused_mut)]
        let mut all: Vec<(&'static str, GemmFn)> =
            vec![("portable", |a, b, c, mode| portable(a, b, c, mode))];
        #[cfg(target_arch = "x86_64")]
        {
            if avx2::available() {
                // SAFETY (in the closure): the CPU has AVX2 and FMA; the test passes standard-
                // layout b and c that do not alias a.
                all.push(("avx2", |a, b, c, mode| unsafe {
                    avx2::gemm_views(a, b, c, mode)
                }));
            }
            if avx512::available() {
                // SAFETY: as above, with AVX-512F.
                all.push(("avx512", |a, b, c, mode| unsafe {
                    avx512::gemm_views(a, b, c, mode)
                }));
            }
        }
        all
    }

    type GemmFn = fn(ArrayView2<f32>, ArrayView2<f32>, ArrayViewMut2<f32>, Mode);

    #[test]
    fn every_kernel_gives_the_portable_arithmetic_bit_for_bit() {
        // Shapes around every kernel's tiles (6 x 16, 2 x 32, 8 x 32, 16 x 16) and the k block, values
        // whose products round, overwrite then accumulate (a second k block adds into c).
        let shapes = [
            (1, 1, 1),
            (3, 7, 5),
            (4, 16, 16),
            (5, 33, 17),
            (9, 17, 16),
            (17, 400, 47),
            (3, 800, 65),
            (31, 9, 3),
            (16, 5, 8),
            (45, 390, 16),
            (64, 64, 96),
            (8, 20, 40),
            (2, 5, 33),
        ];
        let kernels = kernels();
        for (m, k, n) in shapes {
            let a = Array2::from_shape_fn((m, k), |(i, j)| {
                ((i * 31 + j * 17) % 101) as f32 * 0.013_7 - 0.61
            });
            let b = Array2::from_shape_fn((k, n), |(i, j)| {
                ((i * 7 + j * 29) % 89) as f32 * -0.021_3 + 0.97
            });
            let start = Array2::from_shape_fn((m, n), |(i, j)| (i + 3 * j) as f32 * 0.1);
            let run = |f: GemmFn| {
                let mut c = start.clone();
                f(a.view(), b.view(), c.view_mut(), Mode::Accumulate);
                let acc = c.clone();
                f(a.view(), b.view(), c.view_mut(), Mode::Overwrite);
                (acc, c)
            };
            let want = run(kernels[0].1);
            for (name, f) in &kernels[1..] {
                let got = run(*f);
                let bits = |x: &Array2<f32>| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&got.0), bits(&want.0), "{name} {m}x{k}x{n} accumulate");
                assert_eq!(bits(&got.1), bits(&want.1), "{name} {m}x{k}x{n} overwrite");
            }
            // The dispatching entry point, with a transposed right operand too.
            let mut c = start.clone();
            gemm(a.view(), b.view(), c.view_mut(), Mode::Accumulate);
            assert_eq!(c, want.0);
            let bt = b.t().as_standard_layout().into_owned();
            let mut c = start.clone();
            gemm(a.view(), bt.t(), c.view_mut(), Mode::Overwrite);
            assert_eq!(c, want.1);
        }
    }

    #[test]
    fn output_with_a_row_stride_leaves_other_columns_alone() {
        let a = Array2::from_elem((3, 2), 1.0f32);
        let b = Array2::from_elem((2, 4), 1.0f32);
        let mut big = Array2::from_elem((3, 10), -1.0f32);
        gemm(
            a.view(),
            b.view(),
            big.slice_mut(s![.., 3..7]),
            Mode::Overwrite,
        );
        for ((_, j), &v) in big.indexed_iter() {
            assert_eq!(v, if (3..7).contains(&j) { 2.0 } else { -1.0 });
        }
    }

    #[test]
    fn transposed_moves_every_entry_across_block_edges() {
        let shapes = [
            (1, 1),
            (3, 17),
            (16, 16),
            (17, 33),
            (32, 48),
            (256, 64),
            (64, 256),
        ];
        for (rows, cols) in shapes.into_iter().chain([(5, 0), (0, 4)]) {
            let src = Array2::from_shape_fn((rows, cols), |(i, j)| (i * 1000 + j) as f32);
            let t = transposed(src.view());
            assert_eq!(t.dim(), (cols, rows));
            assert!(t.is_standard_layout());
            assert_eq!(t, src.t(), "{rows} x {cols}");
            // A strided source (every other column) takes ndarray's path, same result.
            let strided = src.slice(s![.., ..;2]);
            assert_eq!(transposed(strided), strided.t(), "{rows} x {cols}, strided");
            // The portable path, whichever path this CPU takes above.
            let mut out = vec![f32::NAN; rows * cols];
            transpose_portable(src.as_slice().unwrap(), rows, cols, &mut out);
            assert_eq!(out, t.as_slice().unwrap(), "{rows} x {cols}, portable");
        }
    }

    #[test]
    fn a_transposed_right_operand_gives_the_bits_of_its_copy() {
        let a = Array2::from_shape_fn((9, 20), |(i, j)| ((i * 7 + j * 3) % 11) as f32 * 0.37);
        let w = Array2::from_shape_fn((35, 20), |(i, j)| ((i * 5 + j) % 13) as f32 * -0.21);
        let mut via_view = Array2::zeros((9, 35));
        let mut via_copy = Array2::zeros((9, 35));
        gemm(a.view(), w.t(), via_view.view_mut(), Mode::Overwrite);
        let wt = w.t().as_standard_layout().into_owned();
        gemm(a.view(), wt.view(), via_copy.view_mut(), Mode::Overwrite);
        assert_eq!(via_view, via_copy);
    }
}
