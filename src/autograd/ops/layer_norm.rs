//! Layer normalization over each row's columns (PyTorch's `nn.LayerNorm(d)` on [.., d] inputs):
//! the normalization GPT-2's blocks and ACAC's actor use. One fused node, because its
//! composition (row means by matmul, a reciprocal square root through exp and log) would be six
//! nodes and several temporaries; the tests keep that composition as the oracle.
//!
//! ```text
//! mu = mean_j x_j,  var = mean_j (x_j - mu)^2  (biased, as PyTorch),  r = 1 / sqrt(var + eps)
//! xhat_j = (x_j - mu) r,  y_j = xhat_j gain_j + bias_j
//! ```

use ndarray::{Array2, Zip};

use super::{put, Op};
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};

impl Tape {
    /// y = (x - mean) / sqrt(var + eps) * gain + bias row by row, with x: [m, d], gain and
    /// bias: [1, d] (PyTorch's `weight` and `bias` as rows), y: [m, d]; mean and the biased
    /// variance are over each row's d columns. Panics if gain or bias is not [1, d].
    pub fn layer_norm(&mut self, x: Var, gain: Var, bias: Var, eps: f32) -> Var {
        let (m, d) = self.shape(x);
        for (what, v) in [("gain", gain), ("bias", bias)] {
            let s = self.shape(v);
            assert_eq!(s, (1, d), "layer_norm: {what} must be [1, {d}], got {s:?}");
        }
        let mut y = self.pool().array(m, d);
        // (mean, 1 / sqrt(var + eps)) per row, kept for the backward.
        let mut stats = self.pool().array(m, 2);
        {
            let (vx, vg, vb) = (self.value(x), self.value(gain), self.value(bias));
            let (gain, bias) = (vg.row(0), vb.row(0));
            Zip::from(y.rows_mut())
                .and(stats.rows_mut())
                .and(vx.rows())
                .for_each(|mut yr, mut st, xr| {
                    // Sums in f64: a row's statistics do not depend on f32 summation order.
                    let mean = xr.iter().map(|&v| v as f64).sum::<f64>() / d as f64;
                    let var = xr.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / d as f64;
                    let (mean, rstd) = (mean as f32, (1.0 / (var + eps as f64).sqrt()) as f32);
                    st[0] = mean;
                    st[1] = rstd;
                    Zip::from(&mut yr)
                        .and(&xr)
                        .and(&gain)
                        .and(&bias)
                        .for_each(|y, &x, &g, &b| *y = (x - mean) * rstd * g + b);
                });
        }
        let stats = self.push_aux(stats);
        self.push_op(
            y,
            Op::LayerNorm {
                x,
                gain,
                bias,
                stats,
            },
            &[x, gain, bias],
        )
    }
}

// xhat = (x - mu) r; dgain = sum_rows g xhat, dbias = sum_rows g;
// dxhat = g gain, dx = r (dxhat - mean_j dxhat - xhat mean_j(dxhat xhat))
pub(super) fn layer_norm_backward(
    x: Var,
    gain: Var,
    bias: Var,
    stats: Var,
    g: &Array2<f32>,
    cx: &mut GradCx,
) {
    let (vx, vg, st) = (cx.value(x), cx.value(gain), cx.value(stats));
    let d = vx.ncols();
    let contiguous = "tape arrays are contiguous";
    let (xs, gs, gain_s) = (
        vx.as_slice().expect(contiguous),
        g.as_slice().expect(contiguous),
        vg.as_slice().expect(contiguous),
    );
    let stats_s = st.as_slice().expect(contiguous);
    // xhat of one row, written into `out`.
    let xhat_row = |r: usize, out: &mut [f32]| {
        let (mean, rstd) = (stats_s[2 * r], stats_s[2 * r + 1]);
        for (o, &x) in out.iter_mut().zip(&xs[r * d..(r + 1) * d]) {
            *o = (x - mean) * rstd;
        }
    };
    let mut xhat = cx.pool.array(1, d);
    let xh = xhat.as_slice_mut().expect(contiguous);
    if cx.wants(gain) || cx.wants(bias) {
        let mut sums = cx.pool.zeros(2, d);
        {
            let (dgain, dbias) = sums.as_slice_mut().expect(contiguous).split_at_mut(d);
            for (r, gr) in gs.chunks_exact(d).enumerate() {
                xhat_row(r, xh);
                for j in 0..d {
                    dgain[j] += gr[j] * xh[j];
                    dbias[j] += gr[j];
                }
            }
        }
        for (k, v) in [gain, bias].into_iter().enumerate() {
            if let Some((dst, mode)) = cx.slot(v) {
                put!(mode, dst, sums.slice(ndarray::s![k..k + 1, ..]); |s| s);
            }
        }
        cx.pool.give_array(sums);
    }
    if let Some((dst, mode)) = cx.slot(x) {
        let ds = dst.as_slice_mut().expect(contiguous);
        for (r, (gr, dr)) in gs.chunks_exact(d).zip(ds.chunks_exact_mut(d)).enumerate() {
            xhat_row(r, xh);
            let (mut sum_dxhat, mut sum_dxhat_xhat) = (0.0f32, 0.0f32);
            for j in 0..d {
                let dxhat = gr[j] * gain_s[j];
                sum_dxhat += dxhat;
                sum_dxhat_xhat += dxhat * xh[j];
            }
            let (mean_dxhat, mean_dxhat_xhat) = (sum_dxhat / d as f32, sum_dxhat_xhat / d as f32);
            let rstd = stats_s[2 * r + 1];
            for j in 0..d {
                let v = rstd * (gr[j] * gain_s[j] - mean_dxhat - xh[j] * mean_dxhat_xhat);
                match mode {
                    Mode::Overwrite => dr[j] = v,
                    Mode::Accumulate => dr[j] += v,
                }
            }
        }
    }
    cx.pool.give_array(xhat);
}

#[cfg(test)]
mod tests {
    use ndarray::Array2;

    use super::super::grad_check::{assert_close, grad_check, random_inputs, Inputs};
    use crate::autograd::{Tape, Var};

    /// Layer norm from the public elementary ops: row means as products with a ones column,
    /// 1 / sqrt(var + eps) as exp(-ln(var + eps) / 2). The oracle for the fused op.
    fn unfused(t: &mut Tape, x: Var, gain: Var, bias: Var, eps: f32) -> Var {
        let (m, d) = t.shape(x);
        let avg = t.constant(Array2::from_elem((d, 1), 1.0 / d as f32).view());
        let ones_row = t.constant(Array2::ones((1, d)).view());
        let ones_col = t.constant(Array2::ones((m, 1)).view());
        let mean = t.matmul(x, avg);
        let mean_b = t.matmul(mean, ones_row);
        let centered = t.sub(x, mean_b);
        let sq = t.square(centered);
        let var = t.matmul(sq, avg);
        let eps = t.constant(Array2::from_elem((m, 1), eps).view());
        let var_eps = t.add(var, eps);
        let log = t.log(var_eps);
        let half = t.scale(log, -0.5);
        let rstd = t.exp(half);
        let rstd_b = t.matmul(rstd, ones_row);
        let xhat = t.mul(centered, rstd_b);
        let gain_b = t.matmul(ones_col, gain);
        let scaled = t.mul(xhat, gain_b);
        t.add_bias(scaled, bias)
    }

    #[test]
    fn layer_norm_matches_finite_differences() {
        grad_check(
            |t, v| t.layer_norm(v[0], v[1], v[2], 1e-5),
            &[(4, 6), (1, 6), (1, 6)],
            Inputs::Any,
        );
    }

    #[test]
    fn layer_norm_fan_out_matches_finite_differences() {
        // x feeds the norm and the residual; gain is also added as the bias.
        grad_check(
            |t, v| {
                let y = t.layer_norm(v[0], v[1], v[1], 1e-5);
                t.add(y, v[0])
            },
            &[(3, 5), (1, 5)],
            Inputs::Any,
        );
    }

    #[test]
    fn fused_layer_norm_equals_its_composition_in_value_and_gradient() {
        let inputs = random_inputs(&[(7, 9), (1, 9), (1, 9)], Inputs::Any, 3);
        let seed = random_inputs(&[(7, 9)], Inputs::Any, 4).remove(0);
        let run = |fused: bool| {
            let mut t = Tape::new();
            let v: Vec<Var> = inputs.iter().map(|a| t.param(a.view())).collect();
            let y = if fused {
                t.layer_norm(v[0], v[1], v[2], 1e-5)
            } else {
                unfused(&mut t, v[0], v[1], v[2], 1e-5)
            };
            t.backward_with(y, seed.view());
            let grads: Vec<Array2<f32>> =
                v.iter().map(|&v| t.grad(v).unwrap().to_owned()).collect();
            (t.value(y).to_owned(), grads)
        };
        let (y1, g1) = run(true);
        let (y2, g2) = run(false);
        assert_close(&y1, &y2, 2e-6);
        for (a, b) in g1.iter().zip(&g2) {
            assert_close(a, b, 1e-5);
        }
    }

    #[test]
    fn rows_come_out_with_zero_mean_and_unit_variance_before_the_affine_part() {
        let mut t = Tape::new();
        let x = t.constant(ndarray::arr2(&[[1.0f32, 2.0, 3.0, 6.0], [5.0, 5.0, 5.0, 5.0]]).view());
        let gain = t.constant(Array2::ones((1, 4)).view());
        let bias = t.constant(Array2::zeros((1, 4)).view());
        let y = t.layer_norm(x, gain, bias, 0.0);
        let r0 = t.value(y).row(0).to_owned();
        assert!(r0.sum().abs() < 1e-6);
        assert!((r0.mapv(|v| v * v).sum() / 4.0 - 1.0).abs() < 1e-6);
        // A constant row with eps = 0 would divide 0 by 0; with eps > 0 it maps to the bias.
        let y = t.layer_norm(x, gain, bias, 1e-5);
        assert!(t.value(y).row(1).iter().all(|&v| v == 0.0));
    }
}
