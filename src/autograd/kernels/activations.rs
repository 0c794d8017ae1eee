//! Vectorizable exp, sigmoid and tanh over slices.
//!
//! Why not `f32::exp`: it is a scalar libm call (~15 cycles), and the LSTM applies a sigmoid or
//! tanh to every gate pre-activation, so at the paper's shapes these calls alone would cost more
//! than all the matrix products. The functions below are branch-free Cephes-style polynomials
//! (accurate to a few ulp, see the tests) written so LLVM turns each loop into SIMD code.
//!
//! They use plain `a * b + c` (never `mul_add`), so the result is bit-identical whether the AVX2
//! copy or the baseline SSE2 copy runs: the instruction set changes speed, never a number.

const LOG2E: f32 = std::f32::consts::LOG2_E;
/// ln 2 split in a part exact in few bits and a correction (Cephes `C1`, `C2`).
const LN2_HI: f32 = 0.693_359_4;
const LN2_LO: f32 = -2.121_944_4e-4;
/// 1.5 * 2^23: adding it rounds a float of magnitude < 2^22 to an integer in the low mantissa bits.
const ROUND_MAGIC: f32 = 12_582_912.0;
/// Inputs are clamped so that 2^n stays a normal float (n in -126..=127).
const EXP_MIN: f32 = -87.0;
const EXP_MAX: f32 = 88.0;

/// e^x for x in [-87, 88] (clamped outside), relative error below 3e-7.
#[inline(always)]
pub fn exp_approx(x: f32) -> f32 {
    let x = x.max(EXP_MIN).min(EXP_MAX);
    // n = round(x / ln 2), read back both as a float and as the integer in the mantissa bits.
    let t = x * LOG2E + ROUND_MAGIC;
    let n_int = t.to_bits() as i32 - ROUND_MAGIC.to_bits() as i32;
    let n = t - ROUND_MAGIC;
    // r = x - n ln 2 in [-ln2/2, ln2/2]; e^r by the Cephes minimax polynomial.
    let r = x - n * LN2_HI - n * LN2_LO;
    let r2 = r * r;
    let mut p = 1.987_569_1e-4_f32;
    p = p * r + 1.398_2e-3;
    p = p * r + 8.333_452e-3;
    p = p * r + 4.166_579_6e-2;
    p = p * r + 1.666_666_5e-1;
    p = p * r + 5.000_000_1e-1;
    let er = p * r2 + r + 1.0;
    let two_n = f32::from_bits(((n_int + 127) as u32) << 23);
    er * two_n
}

/// 1 / (1 + e^-x), absolute error below 2e-7.
#[inline(always)]
pub fn sigmoid_approx(x: f32) -> f32 {
    1.0 / (1.0 + exp_approx(-x))
}

/// tanh(x), absolute error below 3e-7 and small relative error near 0 (Cephes `tanhf` split:
/// an odd polynomial for |x| < 0.625, `1 - 2 / (e^(2|x|) + 1)` beyond, both computed, one kept).
#[inline(always)]
pub fn tanh_approx(x: f32) -> f32 {
    let a = x.abs();
    let z = x * x;
    let mut p = -5.704_988_7e-3_f32;
    p = p * z + 2.063_908_9e-2;
    p = p * z + -5.373_971_6e-2;
    p = p * z + 1.333_144_2e-1;
    p = p * z + -3.333_328_2e-1;
    let small = x + x * z * p;
    let big = 1.0 - 2.0 / (exp_approx(2.0 * a) + 1.0);
    let big = if x < 0.0 { -big } else { big };
    if a < 0.625 {
        small
    } else {
        big
    }
}

/// Compile `$body` three times: for AVX-512 and for AVX2 (chosen at run time when the CPU has
/// them) and for the baseline target. The body must not use `mul_add`, so every copy gives the
/// same bits (no instruction set fuses a multiply and an add unless asked to).
macro_rules! simd_dispatch {
    ($(#[$doc:meta])* pub fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $body:block) => {
        $(#[$doc])*
        #[allow(clippy::too_many_arguments)]
        pub fn $name($($arg: $ty),*) {
            #[inline(always)]
            #[allow(clippy::too_many_arguments)]
            fn imp($($arg: $ty),*) $body
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn avx512($($arg: $ty),*) {
                    imp($($arg),*)
                }
                #[target_feature(enable = "avx2")]
                #[allow(clippy::too_many_arguments)]
                unsafe fn avx2($($arg: $ty),*) {
                    imp($($arg),*)
                }
                if $crate::autograd::kernels::activations::has_avx512() {
                    // SAFETY: the CPU supports AVX-512F (checked just above).
                    return unsafe { avx512($($arg),*) };
                }
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: the CPU supports AVX2 (checked just above).
                    return unsafe { avx2($($arg),*) };
                }
            }
            imp($($arg),*)
        }
    };
}
#[allow(unused_imports)]
pub(crate) use simd_dispatch;

/// Whether the CPU has AVX-512F (checked once).
#[cfg(target_arch = "x86_64")]
pub fn has_avx512() -> bool {
    static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *HAS.get_or_init(|| std::arch::is_x86_feature_detected!("avx512f"))
}

simd_dispatch! {
    /// xs[i] = sigmoid(xs[i]).
    pub fn sigmoid_inplace(xs: &mut [f32]) {
        for x in xs.iter_mut() {
            *x = sigmoid_approx(*x);
        }
    }
}

simd_dispatch! {
    /// xs[i] = tanh(xs[i]).
    pub fn tanh_inplace(xs: &mut [f32]) {
        for x in xs.iter_mut() {
            *x = tanh_approx(*x);
        }
    }
}

simd_dispatch! {
    /// out[i] = tanh(xs[i]). Panics if the lengths differ.
    pub fn tanh_into(xs: &[f32], out: &mut [f32]) {
        assert_eq!(xs.len(), out.len(), "tanh_into: length mismatch");
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = tanh_approx(x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> impl Iterator<Item = f32> {
        (-40_000..=40_000).map(|i| i as f32 * 5e-4)
    }

    #[test]
    fn exp_has_relative_error_below_3e_7() {
        for x in (-8_700..=8_800).map(|i| i as f32 * 0.01) {
            let want = (x as f64).exp();
            let got = exp_approx(x) as f64;
            assert!(((got - want) / want).abs() < 3e-7, "exp({x}) = {got}, want {want}");
        }
    }

    #[test]
    fn sigmoid_has_absolute_error_below_2e_7() {
        for x in grid() {
            let want = 1.0 / (1.0 + (-(x as f64)).exp());
            let got = sigmoid_approx(x) as f64;
            assert!((got - want).abs() < 2e-7, "sigmoid({x}) = {got}, want {want}");
        }
        assert_eq!(sigmoid_approx(200.0), 1.0);
        assert!(sigmoid_approx(-200.0) < 1e-37);
    }

    #[test]
    fn tanh_has_small_absolute_and_relative_error() {
        for x in grid() {
            let want = (x as f64).tanh();
            let got = tanh_approx(x) as f64;
            assert!((got - want).abs() < 3e-7, "tanh({x}) = {got}, want {want}");
            if want.abs() > 1e-30 {
                assert!(((got - want) / want).abs() < 1e-6, "tanh({x}) = {got}, want {want}");
            }
        }
        assert_eq!(tanh_approx(50.0), 1.0);
        assert_eq!(tanh_approx(-50.0), -1.0);
    }

    #[test]
    fn slice_versions_match_the_scalar_functions_bit_for_bit() {
        let xs: Vec<f32> = (0..1003).map(|i| (i as f32 - 500.0) * 0.037).collect();
        let mut s = xs.clone();
        sigmoid_inplace(&mut s);
        let mut t = xs.clone();
        tanh_inplace(&mut t);
        let mut u = vec![0.0; xs.len()];
        tanh_into(&xs, &mut u);
        for (i, &x) in xs.iter().enumerate() {
            assert_eq!(s[i].to_bits(), sigmoid_approx(x).to_bits());
            assert_eq!(t[i].to_bits(), tanh_approx(x).to_bits());
            assert_eq!(u[i].to_bits(), t[i].to_bits());
        }
    }
}
