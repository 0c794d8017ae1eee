//! Numeric kernels shared by the taped ops and the no-tape (acting, target) paths.

pub mod activations;
pub mod dense;
pub mod gemm;
pub mod gru;
pub mod lstm;

/// The arithmetic path this CPU takes: `avx512` (our GEMM and activations), `avx2` (matrixmultiply
/// GEMM, AVX2 activations) or `portable`. Runs on different paths may round differently, so a
/// run records it and figures say when they mix paths.
pub fn kernel_path() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if activations::has_avx512() {
            return "avx512";
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            return "avx2";
        }
    }
    "portable"
}
