//! Row-wise normalizations over the columns (one row per sample, one column per action or
//! class): softmax, log-softmax and log-sum-exp, the pieces of a policy-gradient loss.
//!
//! Each row is shifted by its maximum before exponentiating, so logits of any size give finite
//! results (e^(x - max) <= 1, and the row's sum is >= 1). A row whose maximum is not finite is
//! not shifted: all -inf gives log-sum-exp -inf and a NaN softmax, as in PyTorch.

use ndarray::{Array2, ArrayView1, Axis, Zip};

use super::{put, Op};
use crate::autograd::tape::{GradCx, Tape, Var};

/// The row's maximum if finite, else 0 (see the module docs), and ln(sum e^(x - shift)).
fn shift_and_log_sum(row: ArrayView1<f32>) -> (f32, f32) {
    let max = row.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let shift = if max.is_finite() { max } else { 0.0 };
    let sum: f64 = row.iter().map(|&v| ((v - shift) as f64).exp()).sum();
    (shift, sum.ln() as f32)
}

impl Tape {
    /// y[i, j] = e^x[i, j] / sum_k e^x[i, k]: each row of x: [m, n] becomes a probability
    /// distribution over its n columns. Stable for any finite logits (see the module docs).
    pub fn softmax(&mut self, x: Var) -> Var {
        let (m, n) = self.shape(x);
        let mut y = self.pool().array(m, n);
        Zip::from(y.rows_mut())
            .and(self.value(x).rows())
            .for_each(|mut yr, xr| {
                // x - shift first: it is exact near the maximum, where x - lse would round
                // at the magnitude of x.
                let (shift, log_sum) = shift_and_log_sum(xr);
                Zip::from(&mut yr).and(&xr).for_each(|y, &x| {
                    *y = ((x - shift) - log_sum).exp();
                });
            });
        self.push_op(y, Op::Softmax { x }, &[x])
    }

    /// y[i, j] = x[i, j] - ln sum_k e^x[i, k], the log of [`Tape::softmax`] computed without
    /// forming the probabilities (so a tiny probability keeps its exact log instead of -inf).
    /// x, y: [m, n].
    pub fn log_softmax(&mut self, x: Var) -> Var {
        let (m, n) = self.shape(x);
        let mut y = self.pool().array(m, n);
        Zip::from(y.rows_mut())
            .and(self.value(x).rows())
            .for_each(|mut yr, xr| {
                let (shift, log_sum) = shift_and_log_sum(xr);
                Zip::from(&mut yr).and(&xr).for_each(|y, &x| {
                    *y = (x - shift) - log_sum;
                });
            });
        self.push_op(y, Op::LogSoftmax { x }, &[x])
    }

    /// y[i, 0] = ln sum_k e^x[i, k] = max_i + ln sum_k e^(x[i, k] - max_i): x: [m, n] ->
    /// [m, 1]. A row with no columns gives -inf.
    pub fn logsumexp(&mut self, x: Var) -> Var {
        let m = self.shape(x).0;
        let mut y = self.pool().array(m, 1);
        Zip::from(y.rows_mut())
            .and(self.value(x).rows())
            .for_each(|mut yr, xr| {
                let (shift, log_sum) = shift_and_log_sum(xr);
                yr[0] = shift + log_sum;
            });
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
        for ((mut dr, gr), yr) in d
            .axis_iter_mut(Axis(0))
            .zip(g.axis_iter(Axis(0)))
            .zip(y.axis_iter(Axis(0)))
        {
            let total: f32 = gr.sum();
            put!(mode, &mut dr, &gr, &yr; |g, y| g - y.exp() * total);
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
