//! Reductions to a scalar [1, 1]: sum, mean, masked mean, and mean squared error. Sums run in f64
//! so a mean over thousands of TD errors does not depend on f32 rounding order.

use ndarray::Array2;

use super::Op;
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};

impl Tape {
    fn scalar_node(&mut self, value: f64) -> Array2<f32> {
        let mut y = self.pool().array(1, 1);
        y[[0, 0]] = value as f32;
        y
    }

    /// y = mean of all elements of x (0 for an empty x).
    pub fn mean(&mut self, x: Var) -> Var {
        let n = self.value(x).len();
        let s: f64 = self.value(x).iter().map(|&v| v as f64).sum();
        let y = self.scalar_node(if n == 0 { 0.0 } else { s / n as f64 });
        self.push_op(y, Op::Mean { x }, &[x])
    }
}

// dy/dx_i = 1 / n
pub(super) fn mean_backward(x: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let n = cx.value(x).len().max(1) as f32;
    fill_grad(x, g[[0, 0]] / n, cx);
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

    #[test]
    fn mean_matches_finite_differences() {
        grad_check(|t, v| t.mean(v[0]), &[(5, 2)], Inputs::Any);
    }

    #[test]
    fn mean_fan_out_matches_finite_differences() {
        grad_check(
            |t, v| {
                let m = t.mean(v[0]);
                let sq = t.square(v[0]);
                let s = t.mean(sq);
                t.mul(m, s)
            },
            &[(2, 3)],
            Inputs::Any,
        );
    }
}
