//! Numeric kernels shared by the taped ops and the no-tape (acting, target) paths.

pub mod activations;
pub mod dense;
pub mod gemm;
pub mod lstm;
