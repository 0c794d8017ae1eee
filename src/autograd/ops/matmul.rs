//! Matrix products: plain a · b, a · w^T against PyTorch's weight layout, the broadcast bias
//! add, and the fused linear layer act(x · W^T + b) the nets use (checked against its parts).

use ndarray::{Array2, ArrayView2, Axis};

use super::{put, Op};
use crate::autograd::kernels::dense::{act_backward_rows, add_column_sums, linear_forward};
use crate::autograd::kernels::gemm::{gemm, Mode};
use crate::autograd::tape::{GradCx, Tape, Var};

use crate::autograd::kernels::dense::Activation;

impl Tape {
    /// y = a · b with a: [m, k], b: [k, n], y: [m, n]. Panics if the inner sizes differ.
    pub fn matmul(&mut self, a: Var, b: Var) -> Var {
        let ((m, k), (k2, n)) = (self.shape(a), self.shape(b));
        assert_eq!(k, k2, "matmul: [{m}, {k}] · [{k2}, {n}]");
        let mut y = self.pool().array(m, n);
        gemm(self.value(a), self.value(b), y.view_mut(), Mode::Overwrite);
        self.push_op(y, Op::MatMul { a, b }, &[a, b])
    }

    /// y = a · w^T with a: [m, k], w: [n, k] (PyTorch's Linear weight layout).
    pub fn matmul_nt(&mut self, a: Var, w: Var) -> Var {
        let ((m, k), (n, k2)) = (self.shape(a), self.shape(w));
        assert_eq!(k, k2, "matmul_nt: [{m}, {k}] · [{n}, {k2}]^T");
        let mut y = self.pool().array(m, n);
        gemm(
            self.value(a),
            self.value(w).t(),
            y.view_mut(),
            Mode::Overwrite,
        );
        self.push_op(y, Op::MatMulNt { a, b: w }, &[a, w])
    }

    /// y = x + bias, the [1, n] row `bias` added to every row of x: [m, n].
    pub fn add_bias(&mut self, x: Var, bias: Var) -> Var {
        let ((m, n), bs) = (self.shape(x), self.shape(bias));
        assert_eq!(bs, (1, n), "add_bias: bias must be [1, {n}], got {bs:?}");
        let mut y = self.pool().array(m, n);
        y.assign(&self.value(x));
        add_bias_rows(&mut y, self.value(bias));
        self.push_op(y, Op::AddBias { x, bias }, &[x, bias])
    }

    /// y = a · b + bias with a: [m, k], b: [k, n] and the [1, n] row `bias` added to every row
    /// (GPT-2's `Conv1D`): `matmul` then `add_bias` in one node, the same arithmetic (the
    /// product, then one addition per element) without the intermediate copy and its gradient.
    /// Panics if the inner sizes differ or bias is not [1, n].
    pub fn matmul_bias(&mut self, a: Var, b: Var, bias: Var) -> Var {
        let ((m, k), (k2, n), bs) = (self.shape(a), self.shape(b), self.shape(bias));
        assert_eq!(k, k2, "matmul_bias: [{m}, {k}] · [{k2}, {n}]");
        assert_eq!(bs, (1, n), "matmul_bias: bias must be [1, {n}], got {bs:?}");
        let mut y = self.pool().array(m, n);
        gemm(self.value(a), self.value(b), y.view_mut(), Mode::Overwrite);
        add_bias_rows(&mut y, self.value(bias));
        self.push_op(y, Op::MatMulBias { a, b, bias }, &[a, b, bias])
    }

    /// The fused linear layer y = act(x · w^T + b): x: [m, k], w: [n, k], b: [1, n]. One node
    /// instead of three, checked against that composition in the tests.
    pub fn linear(&mut self, x: Var, w: Var, b: Var, act: Activation) -> Var {
        let ((m, k), (n, k2), bs) = (self.shape(x), self.shape(w), self.shape(b));
        assert_eq!(k, k2, "linear: x [{m}, {k}] vs weight [{n}, {k2}]");
        assert_eq!(bs, (1, n), "linear: bias must be [1, {n}], got {bs:?}");
        let mut y = self.pool().array(m, n);
        let bias = self.value(b);
        linear_forward(
            self.value(x),
            self.value(w),
            bias.as_slice().expect("tape arrays are contiguous"),
            act,
            y.view_mut(),
        );
        self.push_op(y, Op::Linear { x, w, b, act }, &[x, w, b])
    }
}

/// y += bias row by row (y: [m, n] from the pool, bias: [1, n]).
fn add_bias_rows(y: &mut Array2<f32>, bias: ArrayView2<f32>) {
    let n = y.ncols();
    let b = bias.as_slice().expect("tape arrays are contiguous");
    if n == 0 {
        return;
    }
    for row in y
        .as_slice_mut()
        .expect("pool arrays are contiguous")
        .chunks_exact_mut(n)
    {
        for (v, &b) in row.iter_mut().zip(b) {
            *v += b;
        }
    }
}

// y = a b + 1 bias: as add_bias (bias) then matmul (a, b), with g for the product's gradient.
pub(super) fn matmul_bias_backward(a: Var, b: Var, bias: Var, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(bias) {
        column_sums_into(g.view(), d, mode);
    }
    matmul_backward(a, b, g, cx);
}

// y = a b: da = g b^T, db = a^T g
pub(super) fn matmul_backward(a: Var, b: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let (va, vb) = (cx.value(a), cx.value(b));
    if let Some((d, mode)) = cx.slot(a) {
        gemm(g.view(), vb.t(), d.view_mut(), mode);
    }
    if let Some((d, mode)) = cx.slot(b) {
        gemm(va.t(), g.view(), d.view_mut(), mode);
    }
}

// y = a w^T: da = g w, dw = g^T a
pub(super) fn matmul_nt_backward(a: Var, w: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let (va, vw) = (cx.value(a), cx.value(w));
    if let Some((d, mode)) = cx.slot(a) {
        gemm(g.view(), vw.view(), d.view_mut(), mode);
    }
    if let Some((d, mode)) = cx.slot(w) {
        gemm(g.t(), va.view(), d.view_mut(), mode);
    }
}

/// dst (=|+=) the column sums of g, dst: [1, n] (the bias gradient of `add_bias`).
fn column_sums_into(g: ArrayView2<f32>, dst: &mut Array2<f32>, mode: Mode) {
    let dst = dst.as_slice_mut().expect("tape arrays are contiguous");
    if mode == Mode::Overwrite {
        dst.fill(0.0);
    }
    match g.as_slice() {
        Some(rows) => add_column_sums(rows, dst),
        None => {
            for row in g.axis_iter(Axis(0)) {
                for (d, &v) in dst.iter_mut().zip(row.iter()) {
                    *d += v;
                }
            }
        }
    }
}

// y = x + 1 b: dx = g, db = column sums of g
pub(super) fn add_bias_backward(x: Var, bias: Var, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        put!(mode, d, g; |g| g);
    }
    if let Some((d, mode)) = cx.slot(bias) {
        column_sums_into(g.view(), d, mode);
    }
}

// y = act(z), z = x w^T + b: dz = g act'(z) (read off y), then as matmul_nt and add_bias.
pub(super) fn linear_backward(
    x: Var,
    w: Var,
    b: Var,
    act: Activation,
    y: &Array2<f32>,
    g: &Array2<f32>,
    cx: &mut GradCx,
) {
    let (vx, vw) = (cx.value(x), cx.value(w));
    // dz and its column sums (the bias gradient) in one pass.
    let mut db = cx.pool.zeros(1, g.ncols());
    let sums = db.as_slice_mut().expect("pool arrays are contiguous");
    let g_rows = g.as_slice().expect("tape arrays are contiguous");
    let dz_owned = match act {
        Activation::Identity => {
            add_column_sums(g_rows, sums);
            None
        }
        Activation::LeakyRelu(slope) => {
            let mut dz = cx.pool.array(g.nrows(), g.ncols());
            let y_rows = y.as_slice().expect("tape arrays are contiguous");
            let dz_rows = dz.as_slice_mut().expect("pool arrays are contiguous");
            act_backward_rows(g_rows, y_rows, slope, dz_rows, sums);
            Some(dz)
        }
    };
    let dz = dz_owned.as_ref().unwrap_or(g);
    if let Some((d, mode)) = cx.slot(w) {
        gemm(dz.t(), vx.view(), d.view_mut(), mode);
    }
    if let Some((d, mode)) = cx.slot(b) {
        put!(mode, d, &db; |g| g);
    }
    cx.pool.give_array(db);
    if let Some((d, mode)) = cx.slot(x) {
        gemm(dz.view(), vw.view(), d.view_mut(), mode);
    }
    if let Some(dz) = dz_owned {
        cx.pool.give_array(dz);
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{grad_check, Inputs};
    use super::*;

    #[test]
    fn matmul_matches_finite_differences() {
        grad_check(|t, v| t.matmul(v[0], v[1]), &[(4, 3), (3, 5)], Inputs::Any);
    }

    #[test]
    fn matmul_fan_out_matches_finite_differences() {
        // x x with x square: both factors are the same node.
        grad_check(|t, v| t.matmul(v[0], v[0]), &[(3, 3)], Inputs::Any);
    }

    #[test]
    fn matmul_multiplies_rows_by_columns() {
        // [1 2; 3 4] [5; 6] = [17; 39]
        let mut t = Tape::new();
        let a = t.constant(ndarray::arr2(&[[1.0f32, 2.0], [3.0, 4.0]]).view());
        let b = t.constant(ndarray::arr2(&[[5.0f32], [6.0]]).view());
        let y = t.matmul(a, b);
        assert_eq!(t.value(y), ndarray::arr2(&[[17.0f32], [39.0]]));
    }

    #[test]
    fn matmul_nt_matches_finite_differences() {
        grad_check(
            |t, v| t.matmul_nt(v[0], v[1]),
            &[(5, 3), (2, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn matmul_nt_and_add_bias_fan_out_match_finite_differences() {
        // x x^T uses x as both factors; the bias row is added to itself through a second path.
        grad_check(|t, v| t.matmul_nt(v[0], v[0]), &[(3, 4)], Inputs::Any);
        grad_check(
            |t, v| {
                let y = t.add_bias(v[0], v[1]);
                t.add_bias(y, v[1])
            },
            &[(3, 2), (1, 2)],
            Inputs::Any,
        );
    }

    #[test]
    fn add_bias_matches_finite_differences() {
        grad_check(
            |t, v| t.add_bias(v[0], v[1]),
            &[(4, 3), (1, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn linear_matches_finite_differences() {
        for act in [Activation::Identity, Activation::LEAKY_001] {
            grad_check(
                move |t, v| t.linear(v[0], v[1], v[2], act),
                &[(6, 4), (3, 4), (1, 3)],
                Inputs::Any,
            );
        }
    }

    #[test]
    fn linear_fan_out_matches_finite_differences() {
        // The same input feeds the layer twice (through x and as a later residual).
        grad_check(
            |t, v| {
                let y = t.linear(v[0], v[1], v[2], Activation::LEAKY_001);
                t.add(y, v[0])
            },
            &[(5, 3), (3, 3), (1, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn matmul_bias_matches_finite_differences() {
        grad_check(
            |t, v| t.matmul_bias(v[0], v[1], v[2]),
            &[(4, 3), (3, 5), (1, 5)],
            Inputs::Any,
        );
    }

    #[test]
    fn matmul_bias_equals_matmul_then_add_bias_bit_for_bit() {
        // Same arithmetic, so equal bits, in value and every gradient (x and the weight also feed
        // a second product, so their gradients accumulate in the same order both ways).
        use crate::autograd::ops::grad_check::random_inputs;
        let inputs = random_inputs(&[(9, 7), (7, 5), (1, 5), (5, 3)], Inputs::Any, 5);
        let seed = random_inputs(&[(9, 3)], Inputs::Any, 6).remove(0);
        let run = |fused: bool| {
            let mut t = Tape::new();
            let v: Vec<Var> = inputs.iter().map(|a| t.param(a.view())).collect();
            let z = if fused {
                t.matmul_bias(v[0], v[1], v[2])
            } else {
                let z = t.matmul(v[0], v[1]);
                t.add_bias(z, v[2])
            };
            let y = t.matmul(z, v[3]);
            let w = t.matmul(v[0], v[1]);
            let w = t.matmul(w, v[3]);
            let y = t.add(y, w);
            t.backward_with(y, seed.view());
            let grads: Vec<Array2<f32>> =
                v.iter().map(|&v| t.grad(v).unwrap().to_owned()).collect();
            (t.value(y).to_owned(), grads)
        };
        assert_eq!(run(true), run(false));
    }

    #[test]
    fn fused_linear_equals_its_composition_in_value_and_gradient() {
        use crate::autograd::ops::grad_check::{assert_close, random_inputs};
        let inputs = random_inputs(&[(7, 5), (4, 5), (1, 4)], Inputs::Any, 3);
        let seed = random_inputs(&[(7, 4)], Inputs::Any, 4).remove(0);
        let run = |fused: bool| {
            let mut t = Tape::new();
            let v: Vec<Var> = inputs.iter().map(|a| t.param(a.view())).collect();
            let y = if fused {
                t.linear(v[0], v[1], v[2], Activation::LEAKY_001)
            } else {
                let z = t.matmul_nt(v[0], v[1]);
                let z = t.add_bias(z, v[2]);
                t.leaky_relu(z, 0.01)
            };
            t.backward_with(y, seed.view());
            let grads: Vec<Array2<f32>> =
                v.iter().map(|&v| t.grad(v).unwrap().to_owned()).collect();
            (t.value(y).to_owned(), grads)
        };
        let (y1, g1) = run(true);
        let (y2, g2) = run(false);
        assert_close(&y1, &y2, 1e-6);
        for (a, b) in g1.iter().zip(&g2) {
            assert_close(a, b, 1e-5);
        }
    }
}
