//! Matrix products, the bulk of every update's arithmetic.
//!
//! One entry point, [`gemm`], so a faster kernel can replace the backend in one place. It runs on
//! one thread (matrixmultiply without its `threading` feature), so thread count never changes a
//! number.

use ndarray::linalg::general_mat_mul;
use ndarray::{ArrayView2, ArrayViewMut2};

/// How a product lands in its destination.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// c = a · b; the old contents of c are never read (may be garbage from the buffer pool).
    Overwrite,
    /// c += a · b.
    Accumulate,
}

/// c (=|+=) a · b with a: [m, k], b: [k, n], c: [m, n]. Any strides (pass `.t()` views for
/// transposes). Panics on mismatched shapes (a bug in the caller).
pub fn gemm(a: ArrayView2<f32>, b: ArrayView2<f32>, mut c: ArrayViewMut2<f32>, mode: Mode) {
    assert_eq!(a.ncols(), b.nrows(), "gemm: inner dimensions differ");
    assert_eq!(c.dim(), (a.nrows(), b.ncols()), "gemm: output shape");
    let beta = match mode {
        Mode::Overwrite => 0.0,
        Mode::Accumulate => 1.0,
    };
    if a.ncols() == 0 {
        // matrixmultiply requires k > 0 for its kernels; the product of empty factors is zero.
        if mode == Mode::Overwrite {
            c.fill(0.0);
        }
        return;
    }
    general_mat_mul(1.0, &a, &b, beta, &mut c);
}

/// Number of floating-point operations of one [m, k] · [k, n] product (a multiply-add counts 2).
pub fn gemm_flops(m: usize, k: usize, n: usize) -> f64 {
    2.0 * m as f64 * k as f64 * n as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

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
}
