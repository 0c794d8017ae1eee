//! Reductions to a scalar [1, 1]: sum, mean, masked mean, and mean squared error. Sums run in f64
//! so a mean over thousands of TD errors does not depend on f32 rounding order.

use ndarray::{Array2, ArrayView2};

use super::{put, Op};
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};

impl Tape {
    fn scalar_node(&mut self, value: f64) -> Array2<f32> {
        let mut y = self.pool().array(1, 1);
        y[[0, 0]] = value as f32;
        y
    }

    /// y = sum of all elements of x.
    pub fn sum(&mut self, x: Var) -> Var {
        let s: f64 = self.value(x).iter().map(|&v| v as f64).sum();
        let y = self.scalar_node(s);
        self.push_op(y, Op::Sum { x }, &[x])
    }

    /// y = mean of all elements of x (0 for an empty x).
    pub fn mean(&mut self, x: Var) -> Var {
        let n = self.value(x).len();
        let s: f64 = self.value(x).iter().map(|&v| v as f64).sum();
        let y = self.scalar_node(if n == 0 { 0.0 } else { s / n as f64 });
        self.push_op(y, Op::Mean { x }, &[x])
    }

    /// y = sum(x * mask) / sum(mask) for a 0/1 (or weight) mask of x's shape; 0, with zero
    /// gradient, when the mask is empty. Panics if the shapes differ.
    pub fn masked_mean(&mut self, x: Var, mask: ArrayView2<f32>) -> Var {
        assert_eq!(self.shape(x), mask.dim(), "masked_mean: mask shape");
        let count: f64 = mask.iter().map(|&m| m as f64).sum();
        let s: f64 = self
            .value(x)
            .iter()
            .zip(mask.iter())
            .map(|(&v, &m)| v as f64 * m as f64)
            .sum();
        let y = self.scalar_node(if count == 0.0 { 0.0 } else { s / count });
        let mask = self.constant(mask);
        let count = count as f32;
        self.push_op(y, Op::MaskedMean { x, mask, count }, &[x])
    }

    /// y = mean((x - target)^2), the MSE against a constant target of x's shape.
    pub fn mse(&mut self, x: Var, target: ArrayView2<f32>) -> Var {
        assert_eq!(self.shape(x), target.dim(), "mse: target shape");
        let n = target.len();
        let s: f64 = self
            .value(x)
            .iter()
            .zip(target.iter())
            .map(|(&v, &t)| (v as f64 - t as f64).powi(2))
            .sum();
        let y = self.scalar_node(if n == 0 { 0.0 } else { s / n as f64 });
        let target = self.constant(target);
        self.push_op(y, Op::Mse { x, target }, &[x])
    }
}

// dy/dx_i = 1
pub(super) fn sum_backward(x: Var, g: &Array2<f32>, cx: &mut GradCx) {
    fill_grad(x, g[[0, 0]], cx);
}

// dy/dx_i = 1 / n
pub(super) fn mean_backward(x: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let n = cx.value(x).len().max(1) as f32;
    fill_grad(x, g[[0, 0]] / n, cx);
}

// dy/dx_i = mask_i / sum(mask)
pub(super) fn masked_mean_backward(
    x: Var,
    mask: Var,
    count: f32,
    g: &Array2<f32>,
    cx: &mut GradCx,
) {
    let scale = if count == 0.0 { 0.0 } else { g[[0, 0]] / count };
    let m = cx.value(mask);
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, m; |m| scale * m);
    }
}

// dy/dx_i = 2 (x_i - t_i) / n
pub(super) fn mse_backward(x: Var, target: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let (vx, vt) = (cx.value(x), cx.value(target));
    let scale = 2.0 * g[[0, 0]] / vx.len().max(1) as f32;
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, vx, vt; |x, t| scale * (x - t));
    }
}

/// Every element of x's gradient gets the same contribution `v`.
fn fill_grad(x: Var, v: f32, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        match mode {
            Mode::Overwrite => d.fill(v),
            Mode::Accumulate => d.mapv_inplace(|a| a + v),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{grad_check, Inputs};
    use ndarray::Array2;

    #[test]
    fn sum_matches_finite_differences() {
        grad_check(|t, v| t.sum(v[0]), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn mean_matches_finite_differences() {
        grad_check(|t, v| t.mean(v[0]), &[(5, 2)], Inputs::Any);
    }

    #[test]
    fn mean_fan_out_matches_finite_differences() {
        grad_check(
            |t, v| {
                let m = t.mean(v[0]);
                let s = t.sum(v[0]);
                t.mul(m, s)
            },
            &[(2, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn masked_mean_matches_finite_differences() {
        let mask = Array2::from_shape_fn((4, 3), |(i, j)| ((i + j) % 2) as f32);
        grad_check(
            move |t, v| t.masked_mean(v[0], mask.view()),
            &[(4, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn masked_mean_averages_only_the_masked_entries() {
        let mut t = crate::autograd::Tape::new();
        let x = t.param(ndarray::arr2(&[[1.0f32, 10.0], [3.0, 100.0]]).view());
        let mask = ndarray::arr2(&[[1.0f32, 0.0], [1.0, 0.0]]);
        let y = t.masked_mean(x, mask.view());
        assert_eq!(t.scalar(y), 2.0);
        t.backward(y);
        // dy/dx = mask / 2
        assert_eq!(
            t.grad(x).unwrap(),
            ndarray::arr2(&[[0.5f32, 0.0], [0.5, 0.0]])
        );
    }

    #[test]
    fn empty_mask_gives_zero_loss_and_zero_gradient() {
        let mut t = crate::autograd::Tape::new();
        let x = t.param(ndarray::arr2(&[[1.0f32, 2.0]]).view());
        let y = t.masked_mean(x, Array2::zeros((1, 2)).view());
        assert_eq!(t.scalar(y), 0.0);
        t.backward(y);
        assert!(t.grad(x).unwrap().iter().all(|&g| g == 0.0));
    }

    #[test]
    fn mse_matches_finite_differences() {
        let target = Array2::from_shape_fn((3, 2), |(i, j)| i as f32 - j as f32 * 0.5);
        grad_check(
            move |t, v| t.mse(v[0], target.view()),
            &[(3, 2)],
            Inputs::Any,
        );
    }

    #[test]
    fn masked_mean_and_mse_fan_out_match_finite_differences() {
        let mask = Array2::from_shape_fn((3, 2), |(i, _)| (i != 1) as u8 as f32);
        let target = Array2::from_elem((3, 2), 0.5f32);
        grad_check(
            move |t, v| {
                let a = t.masked_mean(v[0], mask.view());
                let b = t.mse(v[0], target.view());
                let s = t.sum(v[0]);
                let ab = t.mul(a, b);
                t.mul(ab, s)
            },
            &[(3, 2)],
            Inputs::Any,
        );
    }

    #[test]
    fn mse_of_known_values() {
        let mut t = crate::autograd::Tape::new();
        let x = t.param(ndarray::arr2(&[[1.0f32, 3.0]]).view());
        let y = t.mse(x, ndarray::arr2(&[[0.0f32, 1.0]]).view());
        // ((1-0)^2 + (3-1)^2) / 2 = 2.5; dy/dx = 2 (x - t) / 2 = [1, 2]
        assert_eq!(t.scalar(y), 2.5);
        t.backward(y);
        assert_eq!(t.grad(x).unwrap(), ndarray::arr2(&[[1.0f32, 2.0]]));
    }
}
