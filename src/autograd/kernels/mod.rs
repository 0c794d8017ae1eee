//! Numeric kernels shared by the taped ops and the no-tape (acting, target) paths.

pub mod activations;
pub mod dense;
pub mod elementwise;
pub mod exp;
pub mod gemm;
pub mod gru;
pub mod lstm;

/// The kernel path this CPU takes: `avx512` (AVX-512 GEMM and activations), `avx2-fma` (AVX2
/// with FMA) or `portable-fma` (element by element with `f32::mul_add`). The three give the same
/// bits ([`gemm`]'s shared arithmetic; the activations never fuse), so a run records its path
/// for information and retrains exactly on any of them.
pub fn kernel_path() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if activations::has_avx512() {
            return "avx512";
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            return "avx2-fma";
        }
    }
    "portable-fma"
}

/// The paths of [`kernel_path`]: one arithmetic.
const SHARED_ARITHMETIC: [&str; 3] = ["avx512", "avx2-fma", "portable-fma"];

/// Whether runs recorded on kernel paths `a` and `b` have the same arithmetic. Builds before
/// 2026-12-04 recorded `avx2` and `portable` for `matrixmultiply`'s GEMM, which rounds
/// differently from everything else (and from each other's CPUs' tile choices).
pub fn same_arithmetic(a: &str, b: &str) -> bool {
    a == b || (SHARED_ARITHMETIC.contains(&a) && SHARED_ARITHMETIC.contains(&b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn todays_paths_share_arithmetic_and_the_old_matrixmultiply_ones_do_not() {
        assert!(SHARED_ARITHMETIC.contains(&kernel_path()));
        assert!(same_arithmetic("avx512", "avx2-fma"));
        assert!(same_arithmetic("portable-fma", "avx2-fma"));
        assert!(same_arithmetic("avx2", "avx2"));
        assert!(!same_arithmetic("avx2", "avx512"));
        assert!(!same_arithmetic("portable", "avx2-fma"));
    }
}
