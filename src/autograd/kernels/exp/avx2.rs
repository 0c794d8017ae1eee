//! The AVX2 + FMA kernels of [`super`]: four doubles per vector, each lane the scalar code's
//! operations in the same order (fused where it fuses, rounded where it rounds).

use std::arch::x86_64::*;

use super::tables::{EXPF_TABLE, EXP_TABLE};
use super::{
    exp_f32, exp_f64, C2, C3, C4, C5, EXPF_MAIN_BOUND, EXP_MAIN_BOUND, EXP_TINY, F_C0, F_C1, F_C2,
    F_INV_LN2_N, INV_LN2_N, NEG_LN2_HI_N, NEG_LN2_LO_N, SHIFT,
};

/// `exp_f64_main` on four lanes (garbage, but no fault, outside the main range).
#[inline(always)]
unsafe fn exp4_main(x: __m256d) -> __m256d {
    let shift = _mm256_set1_pd(SHIFT);
    let kd = _mm256_fmadd_pd(x, _mm256_set1_pd(INV_LN2_N), shift);
    let ki = _mm256_castpd_si256(kd);
    let kd = _mm256_sub_pd(kd, shift);
    let r = _mm256_fmadd_pd(kd, _mm256_set1_pd(NEG_LN2_HI_N), x);
    let r = _mm256_fmadd_pd(kd, _mm256_set1_pd(NEG_LN2_LO_N), r);
    let (tail, sbits) = exp_table_rows(ki);
    let scale = _mm256_castsi256_pd(_mm256_add_epi64(sbits, _mm256_slli_epi64::<45>(ki)));
    let r2 = _mm256_mul_pd(r, r);
    let c23 = _mm256_fmadd_pd(r, _mm256_set1_pd(C3), _mm256_set1_pd(C2));
    let low = _mm256_fmadd_pd(c23, r2, _mm256_add_pd(r, tail));
    let c45 = _mm256_fmadd_pd(r, _mm256_set1_pd(C5), _mm256_set1_pd(C4));
    let tmp = _mm256_fmadd_pd(_mm256_mul_pd(r2, r2), c45, low);
    _mm256_fmadd_pd(scale, tmp, scale)
}

/// The four lanes of `v`.
#[inline(always)]
unsafe fn lanes_u64(v: __m256i) -> [u64; 4] {
    let mut k = [0u64; 4];
    _mm256_storeu_si256(k.as_mut_ptr() as *mut __m256i, v);
    k
}

/// exp's table row of each lane's k (k mod 128): its tail and sbits. Four 16-byte loads of the
/// (tail, sbits) pairs, cheaper than two gathers on the CPUs measured.
#[inline(always)]
unsafe fn exp_table_rows(ki: __m256i) -> (__m256d, __m256i) {
    let k = lanes_u64(ki);
    let pair = |l: usize| {
        // SAFETY: 2 (k mod 128) + 1 < 256, inside the table.
        _mm_loadu_si128(EXP_TABLE.as_ptr().add(2 * (k[l] % 128) as usize) as *const __m128i)
    };
    // (tail, sbits) of lanes 0 and 2, of lanes 1 and 3; then the tails and the sbits in order.
    let even = _mm256_set_m128i(pair(2), pair(0));
    let odd = _mm256_set_m128i(pair(3), pair(1));
    (
        _mm256_castsi256_pd(_mm256_unpacklo_epi64(even, odd)),
        _mm256_unpackhi_epi64(even, odd),
    )
}

/// [`exp_f64`] on four lanes.
#[inline(always)]
unsafe fn exp4(x: __m256d) -> __m256d {
    let a = _mm256_andnot_pd(_mm256_set1_pd(-0.0), x);
    let y = exp4_main(x);
    let tiny = _mm256_cmp_pd::<_CMP_LT_OQ>(a, _mm256_set1_pd(EXP_TINY));
    let y = _mm256_blendv_pd(y, _mm256_add_pd(_mm256_set1_pd(1.0), x), tiny);
    let main = _mm256_cmp_pd::<_CMP_LT_OQ>(a, _mm256_set1_pd(EXP_MAIN_BOUND));
    let lanes = _mm256_movemask_pd(main);
    if lanes == 0b1111 {
        return y;
    }
    patch_f64(x, y, lanes)
}

/// `y` with each lane not in `lanes` (a bit per lane) replaced by [`exp_f64`] of `x`'s.
#[cold]
#[target_feature(enable = "avx2,fma")]
unsafe fn patch_f64(x: __m256d, y: __m256d, lanes: i32) -> __m256d {
    let (mut xs, mut ys) = ([0.0f64; 4], [0.0f64; 4]);
    _mm256_storeu_pd(xs.as_mut_ptr(), x);
    _mm256_storeu_pd(ys.as_mut_ptr(), y);
    for l in 0..4 {
        if lanes & (1 << l) == 0 {
            ys[l] = exp_f64(xs[l]);
        }
    }
    _mm256_loadu_pd(ys.as_ptr())
}

/// [`exp_f32`] on four lanes.
#[inline(always)]
unsafe fn expf4(x: __m128) -> __m128 {
    let xd = _mm256_cvtps_pd(x);
    let shift = _mm256_set1_pd(SHIFT);
    let inv = _mm256_set1_pd(F_INV_LN2_N);
    let kd = _mm256_fmadd_pd(inv, xd, shift);
    let ki = _mm256_castpd_si256(kd);
    let kd = _mm256_sub_pd(kd, shift);
    let r = _mm256_fmsub_pd(inv, xd, kd);
    let k = lanes_u64(ki);
    let t = |l: usize| EXPF_TABLE[(k[l] % 32) as usize] as i64;
    let sbits = _mm256_set_epi64x(t(3), t(2), t(1), t(0));
    let s = _mm256_castsi256_pd(_mm256_add_epi64(sbits, _mm256_slli_epi64::<47>(ki)));
    let r2 = _mm256_mul_pd(r, r);
    let high = _mm256_fmadd_pd(r, _mm256_set1_pd(F_C0), _mm256_set1_pd(F_C1));
    let low = _mm256_fmadd_pd(r, _mm256_set1_pd(F_C2), _mm256_set1_pd(1.0));
    let y = _mm256_mul_pd(_mm256_fmadd_pd(high, r2, low), s);
    let y = _mm256_cvtpd_ps(y);
    let a = _mm_andnot_ps(_mm_set1_ps(-0.0), x);
    let lanes = _mm_movemask_ps(_mm_cmplt_ps(a, _mm_set1_ps(EXPF_MAIN_BOUND)));
    if lanes == 0b1111 {
        return y;
    }
    patch_f32(x, y, lanes)
}

/// `y` with each lane not in `lanes` (a bit per lane) replaced by [`exp_f32`] of `x`'s.
#[cold]
#[target_feature(enable = "avx2,fma")]
unsafe fn patch_f32(x: __m128, y: __m128, lanes: i32) -> __m128 {
    let (mut xs, mut ys) = ([0.0f32; 4], [0.0f32; 4]);
    _mm_storeu_ps(xs.as_mut_ptr(), x);
    _mm_storeu_ps(ys.as_mut_ptr(), y);
    for l in 0..4 {
        if lanes & (1 << l) == 0 {
            ys[l] = exp_f32(xs[l]);
        }
    }
    _mm_loadu_ps(ys.as_ptr())
}

/// e^(c - shift) for four f32 lanes `c`, the difference in f32 and the rest in f64.
#[inline(always)]
unsafe fn exp4_shifted(c: __m128, shift: __m128) -> __m256d {
    exp4(_mm256_cvtps_pd(_mm_sub_ps(c, shift)))
}

/// # Safety
/// The CPU has AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn exp_f64_in_place(v: &mut [f64]) {
    let mut chunks = v.chunks_exact_mut(4);
    for c in &mut chunks {
        _mm256_storeu_pd(c.as_mut_ptr(), exp4(_mm256_loadu_pd(c.as_ptr())));
    }
    for x in chunks.into_remainder() {
        *x = exp_f64(*x);
    }
}

/// # Safety
/// The CPU has AVX2 and FMA; `x` and `out` have the same length.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn exp_f32_into(x: &[f32], out: &mut [f32]) {
    let whole = x.len() / 4 * 4;
    for j in (0..whole).step_by(4) {
        let e = expf4(_mm_loadu_ps(x.as_ptr().add(j)));
        _mm_storeu_ps(out.as_mut_ptr().add(j), e);
    }
    for j in whole..x.len() {
        out[j] = exp_f32(x[j]);
    }
}

/// # Safety
/// The CPU has AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn sum_exp_f64(row: &[f32], shift: f32) -> f64 {
    let shift_v = _mm_set1_ps(shift);
    let mut s = -0.0f64;
    let mut e = [0.0f64; 4];
    let mut chunks = row.chunks_exact(4);
    for c in &mut chunks {
        _mm256_storeu_pd(
            e.as_mut_ptr(),
            exp4_shifted(_mm_loadu_ps(c.as_ptr()), shift_v),
        );
        s = s + e[0] + e[1] + e[2] + e[3];
    }
    for &v in chunks.remainder() {
        s += exp_f64(f64::from(v - shift));
    }
    s
}

/// Calls `f` on each column of four rows of the same length in order, as one vector (lane r =
/// row r).
#[inline(always)]
unsafe fn for_each_column(rows: [&[f32]; 4], mut f: impl FnMut(__m128)) {
    let n = rows[0].len();
    let whole = n / 4 * 4;
    let p = rows.map(|r| r.as_ptr());
    for j in (0..whole).step_by(4) {
        // Four columns of the four rows, turned so each vector is one column.
        let a0 = _mm_loadu_ps(p[0].add(j));
        let a1 = _mm_loadu_ps(p[1].add(j));
        let a2 = _mm_loadu_ps(p[2].add(j));
        let a3 = _mm_loadu_ps(p[3].add(j));
        let (t0, t1) = (_mm_unpacklo_ps(a0, a1), _mm_unpacklo_ps(a2, a3));
        let (t2, t3) = (_mm_unpackhi_ps(a0, a1), _mm_unpackhi_ps(a2, a3));
        f(_mm_movelh_ps(t0, t1));
        f(_mm_movehl_ps(t1, t0));
        f(_mm_movelh_ps(t2, t3));
        f(_mm_movehl_ps(t3, t2));
    }
    let [r0, r1, r2, r3] = rows.map(|r| &r[whole..]);
    for (((&a, &b), &c), &d) in r0.iter().zip(r1).zip(r2).zip(r3) {
        f(_mm_set_ps(d, c, b, a));
    }
}

/// # Safety
/// The CPU has AVX2 and FMA; the four rows have the same length.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn sum_exp_f64_rows4(rows: [&[f32]; 4], shifts: [f32; 4]) -> [f64; 4] {
    let shift_v = _mm_loadu_ps(shifts.as_ptr());
    let mut sums = _mm256_set1_pd(-0.0);
    for_each_column(rows, |c| {
        sums = _mm256_add_pd(sums, exp4_shifted(c, shift_v));
    });
    let mut out = [0.0f64; 4];
    _mm256_storeu_pd(out.as_mut_ptr(), sums);
    out
}

/// # Safety
/// The CPU has AVX2 and FMA; the four rows have the same length.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn sum_exp_f32_rows4(rows: [&[f32]; 4], shifts: [f32; 4]) -> [f32; 4] {
    let shift_v = _mm_loadu_ps(shifts.as_ptr());
    let mut sums = _mm_set1_ps(-0.0);
    for_each_column(rows, |c| {
        sums = _mm_add_ps(sums, expf4(_mm_sub_ps(c, shift_v)));
    });
    let mut out = [0.0f32; 4];
    _mm_storeu_ps(out.as_mut_ptr(), sums);
    out
}

/// # Safety
/// The CPU has AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn sum_exp_f32(row: &[f32], shift: f32) -> f32 {
    let shift_v = _mm_set1_ps(shift);
    let mut s = -0.0f32;
    let mut e = [0.0f32; 4];
    let mut chunks = row.chunks_exact(4);
    for c in &mut chunks {
        _mm_storeu_ps(
            e.as_mut_ptr(),
            expf4(_mm_sub_ps(_mm_loadu_ps(c.as_ptr()), shift_v)),
        );
        s = s + e[0] + e[1] + e[2] + e[3];
    }
    for &v in chunks.remainder() {
        s += exp_f32(v - shift);
    }
    s
}
