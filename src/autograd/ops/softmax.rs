//! Row-wise normalizations over the columns (one row per sample, one column per action or
//! class): softmax, log-softmax and log-sum-exp, the pieces of a policy-gradient loss.
//!
//! Each row is shifted by its maximum before exponentiating, so logits of any size give finite
//! results (e^(x - max) <= 1, and the row's sum is >= 1). A row whose maximum is not finite is
//! not shifted: all -inf gives log-sum-exp -inf and a NaN softmax, as in PyTorch.

use ndarray::{Array2, ArrayView1, ArrayView2, Axis, Zip};

use super::{put, Op};
use crate::autograd::kernels::exp::{
    exp_f32, exp_f32_into, exp_f64, sum_exp_f64, sum_exp_f64_rows4,
};
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};

/// The row's maximum if finite, else 0 (see the module docs).
fn row_shift<'a>(row: impl IntoIterator<Item = &'a f32>) -> f32 {
    let max = row.into_iter().copied().fold(f32::NEG_INFINITY, f32::max);
    if max.is_finite() {
        max
    } else {
        0.0
    }
}

/// Each row's shift ([`row_shift`]) and ln(sum e^(x - shift)), the differences in f32 and the
/// exponentials (glibc's `exp`, bit for bit) and the sum in f64, added in column order; four
/// rows' sums side by side where the rows are contiguous.
fn shifts_and_log_sums(x: ArrayView2<f32>) -> Vec<(f32, f32)> {
    let n = x.ncols();
    let log = |s: f64| s.ln() as f32;
    let (Some(flat), true) = (x.as_slice(), n > 0) else {
        return x
            .rows()
            .into_iter()
            .map(|row| {
                let shift = row_shift(row);
                let sum = row
                    .iter()
                    .fold(-0.0, |s, &v| s + exp_f64(f64::from(v - shift)));
                (shift, log(sum))
            })
            .collect();
    };
    let rows: Vec<&[f32]> = flat.chunks_exact(n).collect();
    let mut out: Vec<(f32, f32)> = Vec::with_capacity(rows.len());
    let mut quads = rows.chunks_exact(4);
    for q in &mut quads {
        let shifts = [q[0], q[1], q[2], q[3]].map(row_shift);
        let sums = sum_exp_f64_rows4([q[0], q[1], q[2], q[3]], shifts);
        out.extend((0..4).map(|k| (shifts[k], log(sums[k]))));
    }
    for row in quads.remainder() {
        let shift = row_shift(*row);
        out.push((shift, log(sum_exp_f64(row, shift))));
    }
    out
}

impl Tape {
    /// y[i, j] = e^x[i, j] / sum_k e^x[i, k]: each row of x: [m, n] becomes a probability
    /// distribution over its n columns. Stable for any finite logits (see the module docs).
    pub fn softmax(&mut self, x: Var) -> Var {
        let (m, n) = self.shape(x);
        let mut y = self.pool().array(m, n);
        let xv = self.value(x);
        let stats = shifts_and_log_sums(xv.view());
        for ((mut yr, xr), &(shift, log_sum)) in y.rows_mut().into_iter().zip(xv.rows()).zip(&stats)
        {
            // x - shift first: it is exact near the maximum, where x - lse would round at the
            // magnitude of x.
            Zip::from(&mut yr).and(&xr).for_each(|y, &x| {
                *y = exp_f32((x - shift) - log_sum);
            });
        }
        self.push_op(y, Op::Softmax { x }, &[x])
    }

    /// y[i, j] = x[i, j] - ln sum_k e^x[i, k], the log of [`Tape::softmax`] computed without
    /// forming the probabilities (so a tiny probability keeps its exact log instead of -inf).
    /// x, y: [m, n].
    pub fn log_softmax(&mut self, x: Var) -> Var {
        let (m, n) = self.shape(x);
        let mut y = self.pool().array(m, n);
        let xv = self.value(x);
        let stats = shifts_and_log_sums(xv.view());
        for ((mut yr, xr), &(shift, log_sum)) in y.rows_mut().into_iter().zip(xv.rows()).zip(&stats)
        {
            Zip::from(&mut yr).and(&xr).for_each(|y, &x| {
                *y = (x - shift) - log_sum;
            });
        }
        self.push_op(y, Op::LogSoftmax { x }, &[x])
    }

    /// y[k, 0] = log_softmax(x)[k, index\[k\]]: the log-probability of one column per row (the
    /// macro-action taken), x: [m, n] -> [m, 1]. The bits of `gather_cols(log_softmax(x),
    /// index)`, value and gradient, without the [m, n] log-probabilities, their [m, n] gradient
    /// (zeros but one entry a row) or its row sums: on Mac-CAC's 3 375 joint macro-actions
    /// those passes over memory were most of the actor loss's cost. Panics if `index` does not
    /// have one entry per row or an entry is out of range.
    pub fn log_softmax_at(&mut self, x: Var, index: &[usize]) -> Var {
        let (m, n) = self.shape(x);
        assert_eq!(index.len(), m, "log_softmax_at: one index per row");
        let mut y = self.pool().array(m, 1);
        let xv = self.value(x);
        let stats = shifts_and_log_sums(xv.view());
        for (k, (&a, &(shift, log_sum))) in index.iter().zip(&stats).enumerate() {
            assert!(a < n, "log_softmax_at: index {a} out of range 0..{n}");
            y[[k, 0]] = (xv[[k, a]] - shift) - log_sum;
        }
        let index = index.to_vec();
        self.push_op(y, Op::LogSoftmaxAt { x, index, stats }, &[x])
    }

    /// y[i, 0] = ln sum_k e^x[i, k] = max_i + ln sum_k e^(x[i, k] - max_i): x: [m, n] ->
    /// [m, 1]. A row with no columns gives -inf.
    pub fn logsumexp(&mut self, x: Var) -> Var {
        let m = self.shape(x).0;
        let mut y = self.pool().array(m, 1);
        let stats = shifts_and_log_sums(self.value(x).view());
        for (yi, &(shift, log_sum)) in y.iter_mut().zip(&stats) {
            *yi = shift + log_sum;
        }
        self.push_op(y, Op::LogSumExp { x }, &[x])
    }
}

// y = softmax(x): dx_j = y_j (g_j - sum_k g_k y_k)
pub(super) fn softmax_backward(x: Var, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        for ((mut dr, gr), yr) in d
            .axis_iter_mut(Axis(0))
            .zip(g.axis_iter(Axis(0)))
            .zip(y.axis_iter(Axis(0)))
        {
            let dot: f32 = gr.iter().zip(yr.iter()).map(|(&g, &y)| g * y).sum();
            put!(mode, &mut dr, &gr, &yr; |g, y| y * (g - dot));
        }
    }
}

// y = x - lse(x): dx_j = g_j - softmax_j sum_k g_k, with softmax_j = e^(y_j)
pub(super) fn log_softmax_backward(x: Var, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        let mut exps: Vec<f32> = Vec::new();
        for ((mut dr, gr), yr) in d
            .axis_iter_mut(Axis(0))
            .zip(g.axis_iter(Axis(0)))
            .zip(y.axis_iter(Axis(0)))
        {
            let total: f32 = gr.sum();
            // e^y a row at a time (glibc's `expf`, bit for bit, four at a time).
            exps.resize(yr.len(), 0.0);
            match yr.as_slice() {
                Some(ys) => exp_f32_into(ys, &mut exps),
                None => exps.iter_mut().zip(&yr).for_each(|(e, &y)| *e = exp_f32(y)),
            }
            let e = ArrayView1::from(&exps[..]);
            put!(mode, &mut dr, &gr, &e; |g, e| g - e * total);
        }
    }
}

// y_k = log_softmax(x)[k, a_k]: the backward of `gather_cols` then `log_softmax`, step for step.
// The gather's gradient row is +0 everywhere but g_a = +0 + g_k at a_k, so its sum (ndarray's
// eight partial sums from +0: every other term adds +0, exactly) is g_a; then dx_j = g_j - e^(y_j)
// g_a with y_j = (x_j - shift) - log_sum recomputed as the forward computes it.
pub(super) fn log_softmax_at_backward(
    x: Var,
    index: &[usize],
    stats: &[(f32, f32)],
    g: &Array2<f32>,
    cx: &mut GradCx,
) {
    let vx = cx.value(x);
    if let Some((d, mode)) = cx.slot(x) {
        let n = vx.ncols();
        let (mut ys, mut exps) = (vec![0.0f32; n], vec![0.0f32; n]);
        for (k, ((mut dr, xr), (&a, &(shift, log_sum)))) in d
            .axis_iter_mut(Axis(0))
            .zip(vx.axis_iter(Axis(0)))
            .zip(index.iter().zip(stats))
            .enumerate()
        {
            for (y, &x) in ys.iter_mut().zip(&xr) {
                *y = (x - shift) - log_sum;
            }
            exp_f32_into(&ys, &mut exps);
            let ga = 0.0 + g[[k, 0]];
            let dr = dr.as_slice_mut().expect("gradient arrays are contiguous");
            let (before, rest) = dr.split_at_mut(a);
            let (at, after) = rest.split_first_mut().expect("a < n");
            let (e_before, rest) = exps.split_at(a);
            let (e_at, e_after) = rest.split_first().expect("a < n");
            let at_value = ga - e_at * ga;
            match mode {
                Mode::Overwrite => {
                    for (dj, &e) in before.iter_mut().zip(e_before) {
                        *dj = 0.0 - e * ga;
                    }
                    *at = at_value;
                    for (dj, &e) in after.iter_mut().zip(e_after) {
                        *dj = 0.0 - e * ga;
                    }
                }
                Mode::Accumulate => {
                    for (dj, &e) in before.iter_mut().zip(e_before) {
                        *dj += 0.0 - e * ga;
                    }
                    *at += at_value;
                    for (dj, &e) in after.iter_mut().zip(e_after) {
                        *dj += 0.0 - e * ga;
                    }
                }
            }
        }
    }
}

// y_i = lse(x_i): dx_ij = g_i softmax_ij = g_i e^(x_ij - y_i)
pub(super) fn logsumexp_backward(x: Var, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
    let vx = cx.value(x);
    if let Some((d, mode)) = cx.slot(x) {
        for (((mut dr, xr), &gi), &yi) in d
            .axis_iter_mut(Axis(0))
            .zip(vx.axis_iter(Axis(0)))
            .zip(g.iter())
            .zip(y.iter())
        {
            put!(mode, &mut dr, &xr; |x| gi * (x - yi).exp());
        }
    }
}

#[cfg(test)]
mod tests {
    use ndarray::arr2;

    use super::super::grad_check::{grad_check, Inputs};
    use crate::autograd::Tape;

    /// The definitions with the platform's exp and expf, per row in column order; the kernels
    /// (four rows side by side, four values at a time) must give their bits.
    #[test]
    fn the_forwards_and_the_log_softmax_gradient_are_the_definitions_bit_for_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for (m, n) in [(1, 1), (3, 15), (4, 16), (7, 37), (9, 3375)] {
            let x = ndarray::Array2::from_shape_fn((m, n), |(i, j)| match (i * n + j) % 89 {
                3 => f32::NEG_INFINITY,
                7 => -900.0,
                _ => rng.gen_range(-40.0..40.0),
            });
            let g = ndarray::Array2::from_shape_fn((m, n), |_| rng.gen_range(-1.0f32..1.0));
            let mut t = Tape::new();
            let xv = t.param(x.view());
            let (y, p, l) = (t.log_softmax(xv), t.softmax(xv), t.logsumexp(xv));
            let w = t.constant(g.view());
            let prod = t.mul(y, w);
            let loss = t.sum(prod);
            t.backward(loss);
            let bits =
                |a: ndarray::ArrayView2<f32>| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            let mut want_y = x.clone();
            let mut want_p = x.clone();
            let mut want_l = ndarray::Array2::<f32>::zeros((m, 1));
            let mut want_dx = x.clone();
            for i in 0..m {
                let row = x.row(i);
                let max = row.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                let shift = if max.is_finite() { max } else { 0.0 };
                let sum: f64 = row.iter().map(|&v| ((v - shift) as f64).exp()).sum();
                let log_sum = sum.ln() as f32;
                want_l[[i, 0]] = shift + log_sum;
                for j in 0..n {
                    want_y[[i, j]] = (x[[i, j]] - shift) - log_sum;
                    want_p[[i, j]] = ((x[[i, j]] - shift) - log_sum).exp();
                }
                let total: f32 = g.row(i).sum();
                for j in 0..n {
                    want_dx[[i, j]] = g[[i, j]] - want_y[[i, j]].exp() * total;
                }
            }
            assert_eq!(bits(t.value(y)), bits(want_y.view()), "log_softmax {m}x{n}");
            assert_eq!(bits(t.value(p)), bits(want_p.view()), "softmax {m}x{n}");
            assert_eq!(bits(t.value(l)), bits(want_l.view()), "logsumexp {m}x{n}");
            let dx = t.grad(xv).expect("x's gradient");
            assert_eq!(bits(dx), bits(want_dx.view()), "d log_softmax {m}x{n}");
        }
    }

    /// `log_softmax_at` against `gather_cols(log_softmax(x))`, values and gradients bit for bit:
    /// -inf and -900 logits, a taken column at either end, a gradient of -0 and of 0, and x
    /// also feeding the loss directly (the accumulating gradient).
    #[test]
    fn log_softmax_at_is_the_gathered_log_softmax_bit_for_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        for (m, n) in [(1, 1), (5, 15), (9, 37), (6, 3375)] {
            let x = ndarray::Array2::from_shape_fn((m, n), |(i, j)| match (i * n + j) % 89 {
                3 => f32::NEG_INFINITY,
                7 => -900.0,
                _ => rng.gen_range(-40.0..40.0),
            });
            let index: Vec<usize> = (0..m)
                .map(|i| match i {
                    0 => 0,
                    1 => n - 1,
                    _ => rng.gen_range(0..n),
                })
                .collect();
            let weights = ndarray::Array2::from_shape_fn((m, 1), |(i, _)| match i {
                2 => -0.0,
                3 => 0.0,
                _ => rng.gen_range(-1.0f32..1.0),
            });
            let direct = ndarray::Array2::from_shape_fn((m, n), |_| rng.gen_range(-1.0f32..1.0));
            let bits =
                |a: ndarray::ArrayView2<f32>| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            for fan_out in [false, true] {
                let run = |fused: bool| {
                    let mut t = Tape::new();
                    let xv = t.param(x.view());
                    let taken = if fused {
                        t.log_softmax_at(xv, &index)
                    } else {
                        let l = t.log_softmax(xv);
                        t.gather_cols(l, &index)
                    };
                    let w = t.constant(weights.view());
                    let weighted = t.mul(taken, w);
                    let mut loss = t.sum(weighted);
                    if fan_out {
                        let d = t.constant(direct.view());
                        let dx = t.mul(xv, d);
                        let s = t.sum(dx);
                        loss = t.add(loss, s);
                    }
                    t.backward(loss);
                    let dx = t.grad(xv).expect("x's gradient");
                    (bits(t.value(taken)), bits(dx))
                };
                let (fused, plain) = (run(true), run(false));
                assert_eq!(fused.0, plain.0, "values {m}x{n}");
                assert_eq!(fused.1, plain.1, "gradients {m}x{n}, fan-out {fan_out}");
            }
        }
    }

    #[test]
    fn log_softmax_at_matches_finite_differences() {
        grad_check(
            |t, v| t.log_softmax_at(v[0], &[2, 0, 3]),
            &[(3, 4)],
            Inputs::Any,
        );
    }

    #[test]
    fn softmax_matches_finite_differences() {
        grad_check(|t, v| t.softmax(v[0]), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn log_softmax_matches_finite_differences() {
        grad_check(|t, v| t.log_softmax(v[0]), &[(3, 4)], Inputs::Any);
    }

    #[test]
    fn logsumexp_matches_finite_differences() {
        grad_check(|t, v| t.logsumexp(v[0]), &[(4, 3)], Inputs::Any);
    }

    #[test]
    fn softmax_family_fan_out_matches_finite_differences() {
        // Each op's input also feeds the result directly.
        grad_check(
            |t, v| {
                let p = t.softmax(v[0]);
                t.mul(p, v[0])
            },
            &[(2, 3)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let l = t.log_softmax(v[0]);
                let p = t.softmax(v[0]);
                t.mul(l, p)
            },
            &[(3, 3)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let l = t.logsumexp(v[0]);
                let c = t.concat_cols(&[l, l, l]);
                t.sub(v[0], c)
            },
            &[(2, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn softmax_rows_sum_to_one_and_match_the_definition() {
        // [0, ln 3]: e^0 / (1 + 3) = 1/4, 3 / 4.
        let mut t = Tape::new();
        let x = t.constant(arr2(&[[0.0f32, 3.0f32.ln()], [2.0, 2.0]]).view());
        let p = t.softmax(x);
        let want = arr2(&[[0.25f32, 0.75], [0.5, 0.5]]);
        for (a, b) in t.value(p).iter().zip(want.iter()) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }

    #[test]
    fn huge_logits_stay_finite() {
        // Without the max shift e^1000 overflows to inf and inf / inf is NaN.
        let mut t = Tape::new();
        let x = t.constant(arr2(&[[1000.0f32, 1000.0, -1000.0]]).view());
        let p = t.softmax(x);
        let l = t.log_softmax(x);
        let s = t.logsumexp(x);
        assert!((t.value(p)[[0, 0]] - 0.5).abs() < 1e-6);
        assert_eq!(t.value(p)[[0, 2]], 0.0);
        assert!((t.value(l)[[0, 1]] + 2.0f32.ln()).abs() < 1e-5);
        // log_softmax keeps the log of a probability that underflows to 0.
        assert!((t.value(l)[[0, 2]] + 2000.0 + 2.0f32.ln()).abs() < 1e-2);
        assert!((t.scalar(s) - (1000.0 + 2.0f32.ln())).abs() < 1e-3);
    }

    #[test]
    fn log_softmax_is_the_log_of_softmax() {
        let mut t = Tape::new();
        let x = t.constant(arr2(&[[0.3f32, -1.2, 2.0, 0.0]]).view());
        let p = t.softmax(x);
        let lp = t.log(p);
        let l = t.log_softmax(x);
        for (a, b) in t.value(lp).iter().zip(t.value(l).iter()) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }
}
