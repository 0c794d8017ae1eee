//! Matrix products: plain a · b, a · w^T against PyTorch's weight layout, the broadcast bias
//! add, and the fused linear layer act(x · W^T + b) the nets use (checked against its parts).

use ndarray::{Array2, ArrayView2, Axis};

use super::{put, Op};
use crate::autograd::kernels::dense::{
    act_backward_rows, add_column_sums, fma_row_into, linear_forward, linear_forward_at,
};
use crate::autograd::kernels::elementwise;
use crate::autograd::kernels::gemm::{gemm, Mode, K_BLOCK};
use crate::autograd::pool::zero;
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

    /// The fused linear layer without activation at one column per row: y[r, 0] = (x · w^T +
    /// b)[r, cols\[r\]] with x: [m, k], w: [n, k], b: [1, n] (a Q-net's value of the action
    /// taken, whose loss reads no other column). Values have the bits of `linear` then
    /// `gather_cols`; so do the gradients, but for the sign of a zero result (the composition
    /// also adds the other columns' zero gradients, which turns -0 into +0), which no number
    /// downstream can show: a gradient only enters products and sums. The backward reads one
    /// row of w per row of x instead of all n. Panics on mismatched shapes or a column out of
    /// range.
    pub fn linear_at(&mut self, x: Var, w: Var, b: Var, cols: &[usize]) -> Var {
        let ((m, k), (n, k2), bs) = (self.shape(x), self.shape(w), self.shape(b));
        assert_eq!(k, k2, "linear_at: x [{m}, {k}] vs weight [{n}, {k2}]");
        assert_eq!(bs, (1, n), "linear_at: bias must be [1, {n}], got {bs:?}");
        assert_eq!(cols.len(), m, "linear_at: one column per row");
        let mut y = self.pool().array(m, 1);
        let (vx, vw, vb) = (self.value(x), self.value(w), self.value(b));
        let bias = vb.as_slice().expect("tape arrays are contiguous");
        for (r, &c) in cols.iter().enumerate() {
            assert!(c < n, "linear_at: column {c} out of range 0..{n}");
            let row = vx.row(r);
            let row = row.as_slice().expect("tape arrays are contiguous");
            y[[r, 0]] = linear_forward_at(row, vw, bias, Activation::Identity, c);
        }
        let cols = cols.to_vec();
        self.push_op(y, Op::LinearAt { x, w, b, cols }, &[x, w, b])
    }
}

/// y += bias row by row (y: [m, n] from the pool, bias: [1, n]).
fn add_bias_rows(y: &mut Array2<f32>, bias: ArrayView2<f32>) {
    let b = bias.as_slice().expect("tape arrays are contiguous");
    elementwise::add_bias_rows(y.as_slice_mut().expect("pool arrays are contiguous"), b);
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

// y[r] = x[r] · w[c_r] + b[c_r]: the dense backward of `linear` with a gradient that is zero
// outside column c_r of each row, term by term in the same order (the products' blocks of
// K_BLOCK rows included), the zero terms left out.
pub(super) fn linear_at_backward(
    x: Var,
    w: Var,
    b: Var,
    cols: &[usize],
    g: &Array2<f32>,
    cx: &mut GradCx,
) {
    let (vx, vw) = (cx.value(x), cx.value(w));
    let g = g.as_slice().expect("tape arrays are contiguous");
    let (n, k) = vw.dim();
    let mut sums = cx.pool.zeros(1, n);
    for (&c, &gr) in cols.iter().zip(g) {
        sums[[0, c]] += gr;
    }
    if let Some((d, mode)) = cx.slot(b) {
        put!(mode, d, &sums; |s| s);
    }
    cx.pool.give_array(sums);
    let mut acc_rows = cx.pool.zeros(n, k);
    if let Some((d, mode)) = cx.slot(w) {
        if mode == Mode::Overwrite {
            zero(d);
        }
        let d = d.as_slice_mut().expect("tape arrays are contiguous");
        let acc = acc_rows.as_slice_mut().expect("pool arrays are contiguous");
        let mut touched = vec![false; n];
        for start in (0..cols.len()).step_by(K_BLOCK) {
            let end = (start + K_BLOCK).min(cols.len());
            for r in start..end {
                let c = cols[r];
                touched[c] = true;
                let xr = vx.row(r);
                let xr = xr.as_slice().expect("tape arrays are contiguous");
                fma_row_into(g[r], xr, &mut acc[c * k..(c + 1) * k]);
            }
            for c in 0..n {
                if std::mem::take(&mut touched[c]) {
                    let (a, dst) = (&mut acc[c * k..(c + 1) * k], &mut d[c * k..(c + 1) * k]);
                    for (av, dv) in a.iter_mut().zip(dst) {
                        *dv += *av;
                        *av = 0.0;
                    }
                }
            }
        }
    }
    cx.pool.give_array(acc_rows);
    if let Some((d, mode)) = cx.slot(x) {
        // fma(g, w, 0) then, accumulating, + d: the dense chain's one nonzero term.
        let mut row = vec![0.0f32; k];
        for (r, &c) in cols.iter().enumerate() {
            let wr = vw.row(c);
            row.fill(0.0);
            fma_row_into(
                g[r],
                wr.as_slice().expect("tape arrays are contiguous"),
                &mut row,
            );
            let mut dr = d.row_mut(r);
            let dr = dr.as_slice_mut().expect("tape arrays are contiguous");
            match mode {
                Mode::Overwrite => dr.copy_from_slice(&row),
                Mode::Accumulate => dr.iter_mut().zip(&row).for_each(|(dv, &v)| *dv += v),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{grad_check, Inputs};
    use super::*;

    #[test]
    fn linear_at_matches_finite_differences() {
        grad_check(
            |t, v| t.linear_at(v[0], v[1], v[2], &[2, 0, 2, 1, 3]),
            &[(5, 3), (4, 3), (1, 4)],
            Inputs::Any,
        );
    }

    #[test]
    fn linear_at_is_linear_then_gather_cols() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        // Rows across two product blocks, outputs across two (the input gradient's blocks), and
        // x used twice so its gradient also accumulates.
        for (m, k, n) in [(7, 5, 3), (900, 64, 225), (50, 9, 400)] {
            let mut r =
                |rows, cols| Array2::from_shape_fn((rows, cols), |_| rng.gen_range(-1.0f32..1.0));
            let (x, w, b, other) = (r(m, k), r(n, k), r(1, n), r(m, k));
            let cols: Vec<usize> = (0..m).map(|_| rng.gen_range(0..n)).collect();
            let run = |sparse: bool| {
                let mut t = Tape::new();
                let (vx, vw, vb) = (t.param(x.view()), t.param(w.view()), t.param(b.view()));
                let q = if sparse {
                    t.linear_at(vx, vw, vb, &cols)
                } else {
                    let all = t.linear(vx, vw, vb, Activation::Identity);
                    t.gather_cols(all, &cols)
                };
                let o = t.constant(other.view());
                let xo = t.mul(vx, o);
                let xs = t.mean(xo);
                let sq = t.square(q);
                let l = t.mean(sq);
                let total = t.add(l, xs);
                t.backward(total);
                let grads: Vec<Array2<f32>> = [vx, vw, vb]
                    .iter()
                    .map(|&v| t.grad(v).unwrap().to_owned())
                    .collect();
                (t.value(q).to_owned(), grads)
            };
            let (dense, sparse) = (run(false), run(true));
            let bits = |a: &Array2<f32>| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&dense.0), bits(&sparse.0), "values, {m}x{k}x{n}");
            for (i, (d, s)) in dense.1.iter().zip(&sparse.1).enumerate() {
                // Equal as numbers (a zero's sign may differ), and bit for bit where not zero.
                assert_eq!(d, s, "gradient {i}, {m}x{k}x{n}");
                for (a, b) in d.iter().zip(s) {
                    if *a != 0.0 {
                        assert_eq!(a.to_bits(), b.to_bits(), "gradient {i}");
                    }
                }
            }
        }
    }

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
