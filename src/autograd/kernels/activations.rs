//! Vectorizable sigmoid and tanh over slices.
//!
//! Why not `f32::tanh` / `exp`: they are scalar libm calls (~15-40 cycles), and the LSTM applies
//! a sigmoid or tanh to every gate pre-activation, so at the paper's shapes these calls alone
//! would cost more than all the matrix products. tanh here is one branch-free rational function
//! (our own fit, see [`tanh_approx`]), and sigmoid(x) = (1 + tanh(x / 2)) / 2; LLVM turns the
//! loops below into SIMD code with one division per value.
//!
//! They use plain `a * b + c` (never `mul_add`), so the result is bit-identical whichever of the
//! AVX-512, AVX2 or baseline copies runs: the instruction set changes speed, never a number.

/// Beyond |x| = 9, 1 - tanh|x| < 3e-8 is below half an f32 ulp of 1: tanh is clamped there.
const TANH_CLAMP: f32 = 9.0;
/// tanh(x) ~ x P(x^2) / Q(x^2) on [-9, 9], fitted by iteratively reweighted least squares on
/// the relative error (1500 Chebyshev-spaced points, 40-digit arithmetic; maximum relative
/// error of the exact rational 7.2e-9, far below f32 rounding).
// The fit's digits are kept as printed; the compiler rounds them to f32.
#[allow(clippy::excessive_precision)]
const TANH_P: [f32; 7] = [
    0.999_999_997_542_371,
    0.130_860_298_551_250_66,
    0.003_106_165_811_831_623_2,
    1.117_609_016_991_558_9e-5,
    -2.030_554_559_557_037_4e-8,
    5.312_347_344_764_150_5e-11,
    -8.566_655_144_537_75e-14,
];
#[allow(clippy::excessive_precision)]
const TANH_Q: [f32; 4] = [
    1.0,
    0.464_193_588_550_694_08,
    0.024_504_106_408_776_757,
    2.549_285_032_499_170_5e-4,
];

/// tanh(x) with absolute error below 3.5e-7 (~5 f32 ulp at 1, mostly from rounding the
/// coefficients to f32) and relative error below 1e-6. NaN stays NaN.
#[inline(always)]
pub fn tanh_approx(x: f32) -> f32 {
    // Two one-sided selects, each a single min/max instruction once vectorized; a NaN input
    // fails both comparisons and propagates (f32::min/max would clamp it, and cost more).
    let x = if x > TANH_CLAMP { TANH_CLAMP } else { x };
    let x = if x < -TANH_CLAMP { -TANH_CLAMP } else { x };
    // Estrin's scheme: shallower dependency chains than Horner's, so more of them overlap.
    let (c, d) = (TANH_P, TANH_Q);
    let z = x * x;
    let z2 = z * z;
    let z4 = z2 * z2;
    let p = ((c[6] * z2 + (c[5] * z + c[4])) * z4) + ((c[3] * z + c[2]) * z2 + (c[1] * z + c[0]));
    let q = (d[3] * z + d[2]) * z2 + (d[1] * z + d[0]);
    let t = x * p / q;
    // Rounding can overshoot saturation by an ulp or two; tanh never leaves [-1, 1].
    let t = if t > 1.0 { 1.0 } else { t };
    if t < -1.0 {
        -1.0
    } else {
        t
    }
}

/// 1 / (1 + e^-x) = (1 + tanh(x / 2)) / 2, absolute error below 2e-7. NaN stays NaN.
#[inline(always)]
pub fn sigmoid_approx(x: f32) -> f32 {
    0.5 + 0.5 * tanh_approx(0.5 * x)
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
    /// xs\[i\] = sigmoid(xs\[i\]).
    pub fn sigmoid_inplace(xs: &mut [f32]) {
        for x in xs.iter_mut() {
            *x = sigmoid_approx(*x);
        }
    }
}

simd_dispatch! {
    /// xs\[i\] = tanh(xs\[i\]).
    pub fn tanh_inplace(xs: &mut [f32]) {
        for x in xs.iter_mut() {
            *x = tanh_approx(*x);
        }
    }
}

simd_dispatch! {
    /// out\[i\] = tanh(xs\[i\]). Panics if the lengths differ.
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
        (-40_000..=40_000)
            .map(|i| i as f32 * 5e-4)
            .chain([1e-30, -3e-8, 1e-5, 30.0, -88.0, 1e30])
    }

    #[test]
    fn sigmoid_has_absolute_error_below_2e_7() {
        for x in grid() {
            let want = 1.0 / (1.0 + (-(x as f64)).exp());
            let got = sigmoid_approx(x) as f64;
            assert!(
                (got - want).abs() < 2e-7,
                "sigmoid({x}) = {got}, want {want}"
            );
        }
        assert_eq!(sigmoid_approx(200.0), 1.0);
        assert_eq!(sigmoid_approx(-200.0), 0.0);
    }

    #[test]
    fn tanh_has_small_absolute_and_relative_error() {
        for x in grid() {
            let want = (x as f64).tanh();
            let got = tanh_approx(x) as f64;
            assert!(
                (got - want).abs() < 3.5e-7,
                "tanh({x}) = {got}, want {want}"
            );
            if want != 0.0 {
                assert!(
                    ((got - want) / want).abs() < 1e-6,
                    "tanh({x}) = {got}, want {want}"
                );
            }
        }
        assert_eq!(tanh_approx(50.0), 1.0);
        assert_eq!(tanh_approx(-50.0), -1.0);
        assert_eq!(tanh_approx(0.0), 0.0);
    }

    #[test]
    fn nan_propagates() {
        assert!(tanh_approx(f32::NAN).is_nan());
        assert!(sigmoid_approx(f32::NAN).is_nan());
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
