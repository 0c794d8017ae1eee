//! Reductions to a scalar [1, 1]: sum, mean and masked mean. Sums run in f64 so a mean over
//! thousands of TD errors does not depend on f32 rounding order.

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

    /// y = the sum of all elements of x: [m, n] -> [1, 1] (0 for an empty x).
    pub fn sum(&mut self, x: Var) -> Var {
        let s: f64 = self.value(x).iter().map(|&v| v as f64).sum();
        let y = self.scalar_node(s);
        self.push_op(y, Op::Sum { x }, &[x])
    }

    /// y = sum(x * mask) / sum(mask): the mean of x over the entries where `mask` is 1, e.g. a
    /// loss over the valid steps of padded sequences. x, mask: [m, n] -> [1, 1]. The mask is a
    /// constant of 0s and 1s: no gradient flows into it, even if it is a parameter. An all-zero
    /// mask gives y = 0 with a zero gradient for x (never 0 / 0 = NaN), so an empty batch
    /// contributes nothing. Panics if the shapes differ.
    pub fn masked_mean(&mut self, x: Var, mask: Var) -> Var {
        assert_eq!(
            self.shape(x),
            self.shape(mask),
            "masked_mean: x and mask shapes differ"
        );
        let (vx, vm) = (self.value(x), self.value(mask));
        let count: f64 = vm.iter().map(|&m| m as f64).sum();
        let s: f64 = vx
            .iter()
            .zip(vm.iter())
            .map(|(&v, &m)| v as f64 * m as f64)
            .sum();
        let y = self.scalar_node(if count == 0.0 { 0.0 } else { s / count });
        // Only x's gradient matters: the node depends on the mask as a constant.
        self.push_op(y, Op::MaskedMean { x, mask }, &[x])
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

// dy/dx_i = 1
pub(super) fn sum_backward(x: Var, g: &Array2<f32>, cx: &mut GradCx) {
    fill_grad(x, g[[0, 0]], cx);
}

// dy/dx_i = mask_i / sum(mask); zero everywhere when the mask is all zero (y was set to 0).
pub(super) fn masked_mean_backward(x: Var, mask: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let vm = cx.value(mask);
    let count: f64 = vm.iter().map(|&m| m as f64).sum();
    let scale = if count == 0.0 {
        0.0
    } else {
        (g[[0, 0]] as f64 / count) as f32
    };
    if let Some((d, mode)) = cx.slot(x) {
        super::put!(mode, d, vm; |m| scale * m);
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
    use ndarray::{arr2, Array2};

    use super::super::grad_check::{grad_check, Inputs};
    use crate::autograd::Tape;

    #[test]
    fn mean_matches_finite_differences() {
        grad_check(|t, v| t.mean(v[0]), &[(5, 2)], Inputs::Any);
    }

    #[test]
    fn sum_matches_finite_differences() {
        grad_check(|t, v| t.sum(v[0]), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn sum_fan_out_matches_finite_differences() {
        // y = sum(x) * x: each x_i gets sum(x) + sum_j x_j-weighted seed terms.
        grad_check(
            |t, v| {
                let s = t.sum(v[0]);
                let ones = t.constant(Array2::ones((1, 3)).view());
                let row = t.matmul(s, ones);
                let rows = t.concat_rows(&[row, row]);
                t.mul(rows, v[0])
            },
            &[(2, 3)],
            Inputs::Any,
        );
    }

    fn mask() -> Array2<f32> {
        arr2(&[[1.0, 0.0, 1.0], [0.0, 1.0, 1.0]])
    }

    #[test]
    fn masked_mean_matches_finite_differences() {
        grad_check(
            |t, v| {
                let m = t.constant(mask().view());
                t.masked_mean(v[0], m)
            },
            &[(2, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn masked_mean_fan_out_matches_finite_differences() {
        grad_check(
            |t, v| {
                let m = t.constant(mask().view());
                let sq = t.square(v[0]);
                let a = t.masked_mean(sq, m);
                let b = t.masked_mean(v[0], m);
                t.sub(a, b)
            },
            &[(2, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn masked_mean_averages_only_the_unmasked_entries() {
        // (1 + 3 + 5 + 6) / 4, and dy/dx = mask / 4
        let mut t = Tape::new();
        let x = t.param(arr2(&[[1.0f32, 2.0, 3.0], [4.0, 5.0, 6.0]]).view());
        let m = t.constant(mask().view());
        let y = t.masked_mean(x, m);
        assert_eq!(t.scalar(y), 15.0 / 4.0);
        t.backward(y);
        assert_eq!(t.grad(x).unwrap(), mask() / 4.0);
    }

    #[test]
    fn masked_mean_of_an_all_zero_mask_is_zero_with_zero_gradient() {
        let mut t = Tape::new();
        let x = t.param(arr2(&[[1.0f32, 2.0], [3.0, 4.0]]).view());
        let m = t.constant(Array2::zeros((2, 2)).view());
        let y = t.masked_mean(x, m);
        assert_eq!(t.scalar(y), 0.0);
        t.backward(y);
        assert_eq!(t.grad(x).unwrap(), Array2::<f32>::zeros((2, 2)));
    }

    #[test]
    fn masked_mean_sends_no_gradient_into_the_mask() {
        let mut t = Tape::new();
        let x = t.param(arr2(&[[1.0f32, 2.0]]).view());
        let m = t.param(arr2(&[[1.0f32, 0.0]]).view());
        let y = t.masked_mean(x, m);
        t.backward(y);
        assert!(t.grad(m).is_none());
        assert_eq!(t.grad(x).unwrap(), arr2(&[[1.0f32, 0.0]]));
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
