//! e^x with glibc's arithmetic, four values at a time.
//!
//! Why: a log-softmax over Mac-CAC's 3 375 joint macro-actions, its gradient and the joint
//! draw's eps-mixture called libm's `exp` or `expf` once per entry, about a quarter of a 3-agent
//! Overcooked run. Every committed run computed those with glibc (2.27 and later) on CPUs with
//! FMA and AVX2, that is with `__exp_fma` and `__expf_fma`: the table-driven algorithm of ARM's
//! optimized-routines (e^x = 2^(k/N) e^r, k = round(x N / ln 2), a short polynomial in r; N = 128
//! for exp, 32 for expf, computed in double). The functions here do the same operations, in the
//! same order, with the same fused multiply-adds and the same constants (the tables from their
//! definition by `scripts/exp_tables.py`, the polynomial coefficients those routines publish), so
//! they return glibc's bits for every input, and the same bits on any CPU and libm: the AVX2
//! kernel and the portable `mul_add` code run the same arithmetic. Inputs outside the main range
//! (|x| >= 512 for exp, |x| >= 88 for expf, NaN, infinities) go to the platform's `exp`/`expf`,
//! as glibc's own special cases do.
//!
//! Sums keep their order: `sum_*` add the terms one by one from the first, exactly as
//! `iter().map(..).sum()` does; only the exponentials are computed side by side.

#[cfg(target_arch = "x86_64")]
mod avx2;
mod tables;

use tables::{EXPF_TABLE, EXP_TABLE};

/// 1 / ln 2 x 128, k's scale for exp.
const INV_LN2_N: f64 = f64::from_bits(0x4067_1547_652b_82fe);
/// -ln 2 / 128 in two parts (the high part has trailing zeros, so k x it is exact).
const NEG_LN2_HI_N: f64 = f64::from_bits(0xbf76_2e42_fefa_0000);
const NEG_LN2_LO_N: f64 = f64::from_bits(0xbd0c_f79a_bc9e_3b3a);
/// exp's polynomial e^r - 1 ~ r + C2 r^2 + C3 r^3 + C4 r^4 + C5 r^5 on |r| <= ln 2 / 256.
const C2: f64 = f64::from_bits(0x3fdf_ffff_ffff_fdbd);
const C3: f64 = f64::from_bits(0x3fc5_5555_5555_543c);
const C4: f64 = f64::from_bits(0x3fa5_5555_cf17_2b91);
const C5: f64 = f64::from_bits(0x3f81_1111_67a4_d017);
/// 1.5 x 2^52: adding it rounds to an integer held in the low bits.
const SHIFT: f64 = f64::from_bits(0x4338_0000_0000_0000);
/// exp's main path: 2^-54 <= |x| < 512 (smaller: 1 + x; larger: the platform's exp).
const EXP_TINY: f64 = f64::from_bits(0x3c90_0000_0000_0000);
const EXP_MAIN_BOUND: f64 = 512.0;
/// 1 / ln 2 x 32, k's scale for expf (in double).
const F_INV_LN2_N: f64 = f64::from_bits(0x4047_1547_652b_82fe);
/// expf's polynomial 2^(r/32) ~ 1 + F_C2 r + F_C1 r^2 + F_C0 r^3.
const F_C0: f64 = f64::from_bits(0x3ebc_6af8_4b91_2394);
const F_C1: f64 = f64::from_bits(0x3f2e_bfce_50fa_c4f3);
const F_C2: f64 = f64::from_bits(0x3f96_2e42_ff0c_52d6);
/// expf's main path: |x| < 88.
const EXPF_MAIN_BOUND: f32 = 88.0;

/// e^x, bit for bit glibc's `exp` (see the module docs).
#[inline]
pub fn exp_f64(x: f64) -> f64 {
    let a = x.abs();
    if a < EXP_MAIN_BOUND {
        if a >= EXP_TINY {
            exp_f64_main(x)
        } else {
            1.0 + x
        }
    } else {
        x.exp()
    }
}

/// e^x, bit for bit glibc's `expf` (see the module docs).
#[inline]
pub fn exp_f32(x: f32) -> f32 {
    if x.abs() < EXPF_MAIN_BOUND {
        exp_f32_main(x)
    } else {
        x.exp()
    }
}

/// exp's main path (2^-54 <= |x| < 512).
#[inline(always)]
fn exp_f64_main(x: f64) -> f64 {
    let kd = x.mul_add(INV_LN2_N, SHIFT);
    let ki = kd.to_bits();
    let kd = kd - SHIFT;
    let r = kd.mul_add(NEG_LN2_HI_N, x);
    let r = kd.mul_add(NEG_LN2_LO_N, r);
    let i = 2 * (ki % 128) as usize;
    let tail = f64::from_bits(EXP_TABLE[i]);
    let scale = f64::from_bits(EXP_TABLE[i + 1].wrapping_add(ki << 45));
    let r2 = r * r;
    let low = r.mul_add(C3, C2).mul_add(r2, r + tail);
    let tmp = (r2 * r2).mul_add(r.mul_add(C5, C4), low);
    scale.mul_add(tmp, scale)
}

/// expf's main path (|x| < 88), in double.
#[inline(always)]
fn exp_f32_main(x: f32) -> f32 {
    let xd = f64::from(x);
    let kd = F_INV_LN2_N.mul_add(xd, SHIFT);
    let ki = kd.to_bits();
    let kd = kd - SHIFT;
    let r = F_INV_LN2_N.mul_add(xd, -kd);
    let s = f64::from_bits(EXPF_TABLE[(ki % 32) as usize].wrapping_add(ki << 47));
    let r2 = r * r;
    let y = r.mul_add(F_C0, F_C1).mul_add(r2, r.mul_add(F_C2, 1.0));
    (y * s) as f32
}

/// Whether this CPU runs the vector kernels (AVX2 and FMA, checked once).
#[cfg(target_arch = "x86_64")]
fn vector() -> bool {
    static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HAS.get_or_init(|| {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    })
}

/// v\[i\] = e^v\[i\] ([`exp_f64`] of each).
pub fn exp_f64_in_place(v: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if vector() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above).
        return unsafe { avx2::exp_f64_in_place(v) };
    }
    for x in v {
        *x = exp_f64(*x);
    }
}

/// out\[i\] = e^x\[i\] ([`exp_f32`] of each). Panics if the lengths differ.
pub fn exp_f32_into(x: &[f32], out: &mut [f32]) {
    assert_eq!(x.len(), out.len(), "exp_f32_into: length mismatch");
    #[cfg(target_arch = "x86_64")]
    if vector() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above).
        return unsafe { avx2::exp_f32_into(x, out) };
    }
    for (o, &v) in out.iter_mut().zip(x) {
        *o = exp_f32(v);
    }
}

/// sum_j e^(row\[j\] - shift), each difference in f32 and its exponential and the sum in f64,
/// added in order from the first: `row.iter().map(|&v| ((v - shift) as f64).exp()).sum()`.
pub fn sum_exp_f64(row: &[f32], shift: f32) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if vector() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above).
        return unsafe { avx2::sum_exp_f64(row, shift) };
    }
    row.iter()
        .fold(-0.0, |s, &v| s + exp_f64(f64::from(v - shift)))
}

/// [`sum_exp_f64`] of four rows of the same length at once (one row per vector lane, so each
/// row's additions stay in order while four chains run side by side). Panics if the lengths
/// differ.
pub fn sum_exp_f64_rows4(rows: [&[f32]; 4], shifts: [f32; 4]) -> [f64; 4] {
    let n = rows[0].len();
    assert!(
        rows.iter().all(|r| r.len() == n),
        "sum_exp_f64_rows4: rows of different lengths"
    );
    #[cfg(target_arch = "x86_64")]
    if vector() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above); the rows have n entries.
        return unsafe { avx2::sum_exp_f64_rows4(rows, shifts) };
    }
    std::array::from_fn(|r| sum_exp_f64(rows[r], shifts[r]))
}

/// sum_j e^(row\[j\] - shift) in f32, added in order from the first:
/// `row.iter().map(|&v| (v - shift).exp()).sum()`.
pub fn sum_exp_f32(row: &[f32], shift: f32) -> f32 {
    #[cfg(target_arch = "x86_64")]
    if vector() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above).
        return unsafe { avx2::sum_exp_f32(row, shift) };
    }
    row.iter().fold(-0.0, |s, &v| s + exp_f32(v - shift))
}

/// [`sum_exp_f32`] of four rows of the same length at once, as [`sum_exp_f64_rows4`]. Panics if
/// the lengths differ.
pub fn sum_exp_f32_rows4(rows: [&[f32]; 4], shifts: [f32; 4]) -> [f32; 4] {
    let n = rows[0].len();
    assert!(
        rows.iter().all(|r| r.len() == n),
        "sum_exp_f32_rows4: rows of different lengths"
    );
    #[cfg(target_arch = "x86_64")]
    if vector() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above); the rows have n entries.
        return unsafe { avx2::sum_exp_f32_rows4(rows, shifts) };
    }
    std::array::from_fn(|r| sum_exp_f32(rows[r], shifts[r]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Inputs over every path: the main ranges densely, their edges, tiny, huge, signed zeros,
    /// subnormals, infinities and NaN.
    fn inputs_f64(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut v: Vec<f64> = (0..n)
            .map(|k| match k % 4 {
                0 => rng.gen_range(-30.0..0.0),
                1 => rng.gen_range(-745.0..710.0),
                2 => rng.gen_range(-1.0..1.0) * 2f64.powi(rng.gen_range(-60..0)),
                _ => f64::from(rng.gen_range(-40.0f32..0.0) - rng.gen_range(-40.0f32..0.0)),
            })
            .collect();
        for b in [EXP_TINY, EXP_MAIN_BOUND, 708.0, 709.8, 745.2, 1024.0, 1e300] {
            for s in [1.0, -1.0] {
                let x = s * b;
                v.extend([
                    x,
                    f64::from_bits(x.to_bits() - 1),
                    f64::from_bits(x.to_bits() + 1),
                ]);
            }
        }
        v.extend([
            0.0,
            -0.0,
            5e-324,
            -5e-324,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ]);
        v
    }

    fn inputs_f32(n: usize) -> Vec<f32> {
        let mut v: Vec<f32> = inputs_f64(n, 18).into_iter().map(|x| x as f32).collect();
        for b in [EXPF_MAIN_BOUND, 88.7, 103.9, 104.0] {
            for s in [1.0f32, -1.0] {
                let x = s * b;
                v.extend([
                    x,
                    f32::from_bits(x.to_bits() - 1),
                    f32::from_bits(x.to_bits() + 1),
                ]);
            }
        }
        v
    }

    fn same_f64(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    fn same_f32(a: f32, b: f32) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    #[test]
    fn exp_f64_is_the_platform_exp_bit_for_bit() {
        for x in inputs_f64(400_000, 17) {
            assert!(
                same_f64(exp_f64(x), x.exp()),
                "exp({x:e}): {} vs {}",
                exp_f64(x),
                x.exp()
            );
        }
    }

    #[test]
    fn exp_f32_is_the_platform_expf_bit_for_bit() {
        for x in inputs_f32(400_000) {
            assert!(
                same_f32(exp_f32(x), x.exp()),
                "expf({x:e}): {} vs {}",
                exp_f32(x),
                x.exp()
            );
        }
    }

    /// Every f32 whose exponential is neither 0, 1 (the last rounding) nor infinite, through
    /// the scalar code and the slice kernel: about a billion inputs, a minute on one core.
    /// `cargo test --release --lib -- --ignored every_input`.
    #[test]
    #[ignore]
    fn exp_f32_every_input_in_range_is_the_platform_expf() {
        let mut block = Vec::with_capacity(4096);
        let mut out = vec![0.0; 4096];
        for high in 0..=(u32::MAX >> 12) {
            block.clear();
            block.extend(
                (0..4096)
                    .map(|low| f32::from_bits(high << 12 | low))
                    .filter(|x| x.abs() >= 1e-9 && x.abs() <= 104.0),
            );
            exp_f32_into(&block, &mut out[..block.len()]);
            for (x, y) in block.iter().zip(&out) {
                let want = x.exp();
                assert!(same_f32(exp_f32(*x), want), "expf({x:e})");
                assert!(same_f32(*y, want), "exp_f32_into({x:e})");
            }
        }
    }

    /// A hundred million f64 inputs over every path, through the slice kernel.
    /// `cargo test --release --lib -- --ignored every_input`.
    #[test]
    #[ignore]
    fn exp_f64_every_input_of_a_hundred_million_is_the_platform_exp() {
        for chunk in 0..100 {
            let xs = inputs_f64(1_000_000, chunk);
            let mut v = xs.clone();
            exp_f64_in_place(&mut v);
            for (x, y) in xs.iter().zip(&v) {
                assert!(same_f64(*y, x.exp()), "exp({x:e})");
            }
        }
    }

    #[test]
    fn the_slices_give_the_scalar_bits() {
        let xs = inputs_f64(10_007, 19);
        let mut v = xs.clone();
        exp_f64_in_place(&mut v);
        for (x, y) in xs.iter().zip(&v) {
            assert!(same_f64(*y, exp_f64(*x)), "exp_f64_in_place({x:e})");
        }
        let xs = inputs_f32(10_007);
        let mut out = vec![0.0; xs.len()];
        exp_f32_into(&xs, &mut out);
        for (x, y) in xs.iter().zip(&out) {
            assert!(same_f32(*y, exp_f32(*x)), "exp_f32_into({x:e})");
        }
    }

    #[test]
    fn sums_add_in_order_as_the_iterator_does() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for n in [0, 1, 3, 4, 5, 8, 15, 16, 17, 33, 3375] {
            let rows: Vec<Vec<f32>> = (0..4)
                .map(|_| (0..n).map(|_| rng.gen_range(-20.0f32..20.0)).collect())
                .collect();
            let mut rows = rows;
            if n > 2 {
                // Entries out of the main ranges and the row's maximum itself (a zero term).
                rows[1][1] = -900.0;
                rows[2][2] = f32::NAN;
            }
            let shifts = [1.5f32, 20.0, 0.0, -3.25];
            let want: Vec<f64> = (0..4)
                .map(|r| {
                    rows[r]
                        .iter()
                        .map(|&v| f64::from(v - shifts[r]).exp())
                        .sum()
                })
                .collect();
            for r in 0..4 {
                assert!(
                    same_f64(sum_exp_f64(&rows[r], shifts[r]), want[r]),
                    "n {n} row {r}"
                );
                let want32: f32 = rows[r].iter().map(|&v| (v - shifts[r]).exp()).sum();
                assert!(
                    same_f32(sum_exp_f32(&rows[r], shifts[r]), want32),
                    "f32 n {n} row {r}"
                );
            }
            let four = sum_exp_f64_rows4([&rows[0], &rows[1], &rows[2], &rows[3]], shifts);
            let four32 = sum_exp_f32_rows4([&rows[0], &rows[1], &rows[2], &rows[3]], shifts);
            for r in 0..4 {
                assert!(same_f64(four[r], want[r]), "rows4 n {n} row {r}");
                let want32: f32 = rows[r].iter().map(|&v| (v - shifts[r]).exp()).sum();
                assert!(same_f32(four32[r], want32), "f32 rows4 n {n} row {r}");
            }
        }
    }
}
