//! Elementwise ops on same-shaped arrays: add, sub, mul, scale, the activations (sigmoid, tanh,
//! leaky ReLU), square (the TD loss), exp and log.

use ndarray::Array2;

use super::{put, Op};
use crate::autograd::kernels::activations::{sigmoid_inplace, tanh_inplace};
use crate::autograd::kernels::elementwise::{add_into, mul_into, put_copy, put_mul, sub_into};
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};

impl Tape {
    /// A copy of `x`'s value in a recycled buffer.
    fn copy_of(&mut self, x: Var) -> Array2<f32> {
        let (r, c) = self.shape(x);
        let mut y = self.pool().array(r, c);
        y.assign(&self.value(x));
        y
    }

    /// y = kernel(a, b) over the (contiguous) values; panics if the shapes differ.
    fn binary(
        &mut self,
        a: Var,
        b: Var,
        what: &str,
        kernel: fn(&[f32], &[f32], &mut [f32]),
    ) -> Array2<f32> {
        let shape = self.shape(a);
        assert_eq!(shape, self.shape(b), "{what}: shapes differ");
        let mut y = self.pool().array(shape.0, shape.1);
        let contiguous = "tape arrays are contiguous";
        let (va, vb) = (self.value(a), self.value(b));
        kernel(
            va.as_slice().expect(contiguous),
            vb.as_slice().expect(contiguous),
            y.as_slice_mut().expect(contiguous),
        );
        y
    }

    /// y = a + b (same shapes; see [`Tape::add_bias`] for broadcasting a row).
    pub fn add(&mut self, a: Var, b: Var) -> Var {
        let y = self.binary(a, b, "add", add_into);
        self.push_op(y, Op::Add { a, b }, &[a, b])
    }

    /// y = a - b (same shapes).
    pub fn sub(&mut self, a: Var, b: Var) -> Var {
        let y = self.binary(a, b, "sub", sub_into);
        self.push_op(y, Op::Sub { a, b }, &[a, b])
    }

    /// y = a * b elementwise (same shapes).
    pub fn mul(&mut self, a: Var, b: Var) -> Var {
        let y = self.binary(a, b, "mul", mul_into);
        self.push_op(y, Op::Mul { a, b }, &[a, b])
    }

    /// y = 1 / (1 + e^-x). Backward reuses the output: dy/dx = y (1 - y).
    pub fn sigmoid(&mut self, x: Var) -> Var {
        let mut y = self.copy_of(x);
        sigmoid_inplace(y.as_slice_mut().expect("tape arrays are contiguous"));
        self.push_op(y, Op::Sigmoid { x }, &[x])
    }

    /// y = tanh(x). Backward reuses the output: dy/dx = 1 - y^2.
    pub fn tanh(&mut self, x: Var) -> Var {
        let mut y = self.copy_of(x);
        tanh_inplace(y.as_slice_mut().expect("tape arrays are contiguous"));
        self.push_op(y, Op::Tanh { x }, &[x])
    }

    /// y = x for x > 0, slope * x otherwise. PyTorch's layers use slope 0.01; the hysteretic TD
    /// transform max(h d, d) of `docs/ALGORITHMS.md` §5 is exactly this op with slope h (h <= 1).
    pub fn leaky_relu(&mut self, x: Var, slope: f32) -> Var {
        let mut y = self.copy_of(x);
        y.mapv_inplace(|v| if v > 0.0 { v } else { slope * v });
        self.push_op(y, Op::LeakyRelu { x, slope }, &[x])
    }

    /// y = x^2 elementwise.
    pub fn square(&mut self, x: Var) -> Var {
        let mut y = self.copy_of(x);
        y.mapv_inplace(|v| v * v);
        self.push_op(y, Op::Square { x }, &[x])
    }

    /// y = c * x elementwise, for a constant c (a loss coefficient, a discount): x, y: [m, n].
    pub fn scale(&mut self, x: Var, c: f32) -> Var {
        let mut y = self.copy_of(x);
        y.mapv_inplace(|v| c * v);
        self.push_op(y, Op::Scale { x, c }, &[x])
    }

    /// y = e^x elementwise (libm's `f32::exp`), x, y: [m, n]. Backward reuses the output:
    /// dy/dx = y. Overflows to +inf above x ~ 88.7; for probabilities from logits use
    /// [`Tape::softmax`], which is stable.
    pub fn exp(&mut self, x: Var) -> Var {
        let mut y = self.copy_of(x);
        y.mapv_inplace(f32::exp);
        self.push_op(y, Op::Exp { x }, &[x])
    }

    /// y = ln(x) elementwise, x, y: [m, n]; dy/dx = 1 / x. Follows IEEE: ln(0) = -inf and a
    /// negative x gives NaN (with an infinite or NaN gradient), so keep x > 0 (for the log of
    /// probabilities use [`Tape::log_softmax`], which never forms them).
    pub fn log(&mut self, x: Var) -> Var {
        let mut y = self.copy_of(x);
        y.mapv_inplace(f32::ln);
        self.push_op(y, Op::Log { x }, &[x])
    }
}

// d(a + b) = da + db
pub(super) fn add_backward(a: Var, b: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let gs = g.as_slice().expect("tape arrays are contiguous");
    for v in [a, b] {
        if let Some((d, mode)) = cx.slot(v) {
            let ds = d.as_slice_mut().expect("tape arrays are contiguous");
            put_copy(ds, gs, mode == Mode::Accumulate);
        }
    }
}

// d(a - b) = da - db
pub(super) fn sub_backward(a: Var, b: Var, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(a) {
        let gs = g.as_slice().expect("tape arrays are contiguous");
        let ds = d.as_slice_mut().expect("tape arrays are contiguous");
        put_copy(ds, gs, mode == Mode::Accumulate);
    }
    if let Some((d, mode)) = cx.slot(b) {
        put!(mode, d, g; |g| -g);
    }
}

// d(a * b) = b da + a db (a fan-out mul(x, x) gets both terms: 2 x dx)
pub(super) fn mul_backward(a: Var, b: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let (va, vb) = (cx.value(a), cx.value(b));
    let contiguous = "tape arrays are contiguous";
    let gs = g.as_slice().expect(contiguous);
    for (v, other) in [(a, vb), (b, va)] {
        if let Some((d, mode)) = cx.slot(v) {
            let ds = d.as_slice_mut().expect(contiguous);
            let os = other.as_slice().expect(contiguous);
            put_mul(ds, gs, os, mode == Mode::Accumulate);
        }
    }
}

// dy/dx = y (1 - y)
pub(super) fn sigmoid_backward(x: Var, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g, y; |g, y| g * y * (1.0 - y));
    }
}

// dy/dx = 1 - y^2
pub(super) fn tanh_backward(x: Var, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g, y; |g, y| g * (1.0 - y * y));
    }
}

// dy/dx = 1 for x > 0, slope otherwise
pub(super) fn leaky_relu_backward(x: Var, slope: f32, g: &Array2<f32>, cx: &mut GradCx) {
    let vx = cx.value(x);
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g, vx; |g, x| if x > 0.0 { g } else { slope * g });
    }
}

// dy/dx = 2 x
pub(super) fn square_backward(x: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let vx = cx.value(x);
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g, vx; |g, x| 2.0 * x * g);
    }
}

// dy/dx = c
pub(super) fn scale_backward(x: Var, c: f32, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g; |g| c * g);
    }
}

// dy/dx = e^x = y
pub(super) fn exp_backward(x: Var, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g, y; |g, y| g * y);
    }
}

// dy/dx = 1 / x
pub(super) fn log_backward(x: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let vx = cx.value(x);
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g, vx; |g, x| g / x);
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{grad_check, Inputs};

    #[test]
    fn add_matches_finite_differences() {
        grad_check(|t, v| t.add(v[0], v[1]), &[(3, 4), (3, 4)], Inputs::Any);
    }

    #[test]
    fn add_fan_out_doubles_the_gradient() {
        grad_check(|t, v| t.add(v[0], v[0]), &[(2, 5)], Inputs::Any);
    }

    #[test]
    fn sub_matches_finite_differences() {
        grad_check(|t, v| t.sub(v[0], v[1]), &[(4, 3), (4, 3)], Inputs::Any);
    }

    #[test]
    fn mul_matches_finite_differences() {
        grad_check(|t, v| t.mul(v[0], v[1]), &[(3, 5), (3, 5)], Inputs::Any);
    }

    #[test]
    fn mul_fan_out_matches_finite_differences() {
        // y = x * x: dy/dx = 2 x, both operand slots feed the same gradient.
        grad_check(|t, v| t.mul(v[0], v[0]), &[(3, 3)], Inputs::Any);
    }

    #[test]
    fn sigmoid_matches_finite_differences() {
        grad_check(|t, v| t.sigmoid(v[0]), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn tanh_matches_finite_differences() {
        grad_check(|t, v| t.tanh(v[0]), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn tanh_fan_out_matches_finite_differences() {
        grad_check(
            |t, v| {
                let y = t.tanh(v[0]);
                t.mul(y, v[0])
            },
            &[(4, 2)],
            Inputs::Any,
        );
    }

    #[test]
    fn leaky_relu_matches_finite_differences() {
        grad_check(
            |t, v| t.leaky_relu(v[0], 0.01),
            &[(4, 5)],
            Inputs::AwayFromZero,
        );
        grad_check(
            |t, v| t.leaky_relu(v[0], 0.3),
            &[(4, 5)],
            Inputs::AwayFromZero,
        );
    }

    #[test]
    fn square_matches_finite_differences() {
        grad_check(|t, v| t.square(v[0]), &[(3, 2)], Inputs::Any);
    }

    #[test]
    fn unary_ops_fan_out_matches_finite_differences() {
        // Each op's input also feeds the result directly: y = op(x) * x, or op(x) - x.
        grad_check(
            |t, v| {
                let y = t.sigmoid(v[0]);
                t.mul(y, v[0])
            },
            &[(3, 3)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let y = t.square(v[0]);
                t.sub(y, v[0])
            },
            &[(2, 4)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let y = t.leaky_relu(v[0], 0.2);
                t.mul(y, v[0])
            },
            &[(3, 2)],
            Inputs::AwayFromZero,
        );
    }

    #[test]
    fn scale_matches_finite_differences() {
        grad_check(|t, v| t.scale(v[0], -2.5), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn exp_matches_finite_differences() {
        grad_check(|t, v| t.exp(v[0]), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn log_matches_finite_differences() {
        // ln needs x > 0: take the log of e^x, which is x again (d/dx = 1 through both ops),
        // and of x^2 + 0.5 away from zero: d/dx ln(x^2 + 0.5) = 2x / (x^2 + 0.5).
        grad_check(
            |t, v| {
                let e = t.exp(v[0]);
                t.log(e)
            },
            &[(2, 3)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let sq = t.square(v[0]);
                let half = t.constant(ndarray::Array2::from_elem((3, 2), 0.5).view());
                let pos = t.add(sq, half);
                t.log(pos)
            },
            &[(3, 2)],
            Inputs::Any,
        );
    }

    #[test]
    fn exp_log_and_scale_fan_out_match_finite_differences() {
        // y = e^x * x, ln(e^x) - x (= 0, the terms cancel), c x + x.
        grad_check(
            |t, v| {
                let e = t.exp(v[0]);
                t.mul(e, v[0])
            },
            &[(3, 3)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let e = t.exp(v[0]);
                let l = t.log(e);
                t.sub(l, v[0])
            },
            &[(2, 3)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let s = t.scale(v[0], 0.3);
                t.add(s, v[0])
            },
            &[(2, 2)],
            Inputs::Any,
        );
    }

    #[test]
    fn log_of_zero_is_minus_infinity_and_exp_inverts_log() {
        let mut t = crate::autograd::Tape::new();
        let x = t.constant(ndarray::arr2(&[[0.0f32, 1.0, 2.0]]).view());
        let l = t.log(x);
        assert_eq!(t.value(l)[[0, 0]], f32::NEG_INFINITY);
        assert_eq!(t.value(l)[[0, 1]], 0.0);
        let e = t.exp(l);
        assert!((t.value(e)[[0, 2]] - 2.0).abs() < 1e-6);
    }

    #[test]
    fn sub_fan_out_cancels() {
        // y = x - x = 0: the two contributions cancel exactly.
        grad_check(|t, v| t.sub(v[0], v[0]), &[(2, 3)], Inputs::Any);
        let mut t = crate::autograd::Tape::new();
        let x = t.param(ndarray::arr2(&[[1.0f32, -2.0]]).view());
        let y = t.sub(x, x);
        let s = t.mean(y);
        t.backward(s);
        assert_eq!(t.grad(x).unwrap(), ndarray::arr2(&[[0.0f32, 0.0]]));
    }

    #[test]
    fn leaky_relu_with_slope_h_is_the_hysteretic_transform() {
        // `docs/ALGORITHMS.md` §5: max(h d, d) for h <= 1
        let mut t = crate::autograd::Tape::new();
        let d = t.constant(ndarray::arr2(&[[-2.0f32, 0.5, 0.0, 3.0]]).view());
        let y = t.leaky_relu(d, 0.2);
        let want: Vec<f32> = [-2.0f32, 0.5, 0.0, 3.0]
            .iter()
            .map(|&d| (0.2 * d).max(d))
            .collect();
        assert_eq!(t.value(y).iter().copied().collect::<Vec<_>>(), want);
    }
}
