//! Layer normalization over each row's columns (PyTorch's `nn.LayerNorm(d)` on [.., d] inputs):
//! the normalization GPT-2's blocks and ACAC's actor use. One fused node, because its
//! composition (row means by matmul, a reciprocal square root through exp and log) would be six
//! nodes and several temporaries; the tests keep that composition as the oracle.
//!
//! ```text
//! mu = mean_j x_j,  var = mean_j (x_j - mu)^2  (biased, as PyTorch),  r = 1 / sqrt(var + eps)
//! xhat_j = (x_j - mu) r,  y_j = xhat_j gain_j + bias_j
//! ```

use ndarray::Array2;

use super::{put, Op};
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};

/// Rows whose statistics are summed side by side: independent chains the CPU overlaps, each
/// row's additions still in column order (so the same bits as one row at a time).
const ROWS: usize = 8;

/// N rows of the forward: each row's mean and variance are `Iterator::sum`s (the sum's start
/// value, then one addition per column in order), run for the N rows side by side.
// Column j of every row in turn: the loops are over columns, then rows, on purpose.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn forward_rows<const N: usize>(
    xb: &[f32],
    gain: &[f32],
    bias: &[f32],
    eps: f32,
    yb: &mut [f32],
    stats: &mut [f32],
) {
    let d = gain.len();
    let xr: [&[f32]; N] = std::array::from_fn(|r| &xb[r * d..(r + 1) * d]);
    let zero = std::iter::empty::<f64>().sum::<f64>();
    let mut sum = [zero; N];
    for j in 0..d {
        for r in 0..N {
            sum[r] += xr[r][j] as f64;
        }
    }
    let mean = sum.map(|s| s / d as f64);
    let mut sq = [zero; N];
    for j in 0..d {
        for r in 0..N {
            sq[r] += (xr[r][j] as f64 - mean[r]).powi(2);
        }
    }
    for r in 0..N {
        let var = sq[r] / d as f64;
        let (mean, rstd) = (mean[r] as f32, (1.0 / (var + eps as f64).sqrt()) as f32);
        stats[2 * r] = mean;
        stats[2 * r + 1] = rstd;
        let yr = &mut yb[r * d..(r + 1) * d];
        for (((y, &x), &g), &b) in yr.iter_mut().zip(xr[r]).zip(gain).zip(bias) {
            *y = (x - mean) * rstd * g + b;
        }
    }
}

/// N rows of dx: per row two f32 sums over the columns in order, for the N rows side by side.
/// xh: the rows' xhat, rstd: their 1 / sqrt(var + eps).
#[inline(always)]
fn dx_rows<const N: usize>(
    gb: &[f32],
    xh: &[f32],
    gain: &[f32],
    rstd: [f32; N],
    db: &mut [f32],
    mode: Mode,
) {
    let d = gain.len();
    let gr: [&[f32]; N] = std::array::from_fn(|r| &gb[r * d..(r + 1) * d]);
    let xr: [&[f32]; N] = std::array::from_fn(|r| &xh[r * d..(r + 1) * d]);
    let (mut sum_dxhat, mut sum_dxhat_xhat) = ([0.0f32; N], [0.0f32; N]);
    for j in 0..d {
        for r in 0..N {
            let dxhat = gr[r][j] * gain[j];
            sum_dxhat[r] += dxhat;
            sum_dxhat_xhat[r] += dxhat * xr[r][j];
        }
    }
    for r in 0..N {
        let (mean_dxhat, mean_dxhat_xhat) = (sum_dxhat[r] / d as f32, sum_dxhat_xhat[r] / d as f32);
        let dr = &mut db[r * d..(r + 1) * d];
        let (rs, g, x) = (rstd[r], gr[r], xr[r]);
        let v = |g: f32, gain: f32, x: f32| rs * (g * gain - mean_dxhat - x * mean_dxhat_xhat);
        // Zipped slices and the mode outside the loop, so it runs vector-wide (each element's
        // operations are the same, in the same order).
        let lanes = dr.iter_mut().zip(g).zip(gain).zip(x);
        match mode {
            Mode::Overwrite => lanes.for_each(|(((d, &g), &gain), &x)| *d = v(g, gain, x)),
            Mode::Accumulate => lanes.for_each(|(((d, &g), &gain), &x)| *d += v(g, gain, x)),
        }
    }
}

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
            let contiguous = "tape arrays are contiguous";
            let (vx, vg, vb) = (self.value(x), self.value(gain), self.value(bias));
            let (xs, gain, bias) = (
                vx.as_slice().expect(contiguous),
                vg.as_slice().expect(contiguous),
                vb.as_slice().expect(contiguous),
            );
            let ys = y.as_slice_mut().expect(contiguous);
            let st = stats.as_slice_mut().expect(contiguous);
            // Sums in f64: a row's statistics do not depend on f32 summation order.
            let mut r0 = 0;
            while r0 < m {
                let (rows, at) = if m - r0 >= ROWS {
                    (ROWS, r0 * d)
                } else {
                    (1, r0 * d)
                };
                let (xb, yb) = (&xs[at..at + rows * d], &mut ys[at..at + rows * d]);
                let sb = &mut st[2 * r0..2 * (r0 + rows)];
                if rows == ROWS {
                    forward_rows::<ROWS>(xb, gain, bias, eps, yb, sb);
                } else {
                    forward_rows::<1>(xb, gain, bias, eps, yb, sb);
                }
                r0 += rows;
            }
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
    let m = vx.nrows();
    let mut xhats = cx.pool.array(ROWS, d);
    if let Some((dst, mode)) = cx.slot(x) {
        let ds = dst.as_slice_mut().expect(contiguous);
        let xhs = xhats.as_slice_mut().expect(contiguous);
        let mut r0 = 0;
        while r0 < m {
            let rows = if m - r0 >= ROWS { ROWS } else { 1 };
            for r in 0..rows {
                xhat_row(r0 + r, &mut xhs[r * d..(r + 1) * d]);
            }
            let (gb, db) = (
                &gs[r0 * d..(r0 + rows) * d],
                &mut ds[r0 * d..(r0 + rows) * d],
            );
            let rstd = |r: usize| stats_s[2 * (r0 + r) + 1];
            if rows == ROWS {
                dx_rows::<ROWS>(gb, xhs, gain_s, std::array::from_fn(rstd), db, mode);
            } else {
                dx_rows::<1>(gb, xhs, gain_s, [rstd(0)], db, mode);
            }
            r0 += rows;
        }
    }
    cx.pool.give_array(xhats);
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

    /// The forward and the x gradient one row at a time, as written before rows were
    /// interleaved: the interleaved kernels must give the same bits.
    fn row_at_a_time(
        x: &Array2<f32>,
        gain: &[f32],
        bias: &[f32],
        g: &Array2<f32>,
    ) -> [Array2<f32>; 2] {
        let (m, d) = x.dim();
        let (mut y, mut dx) = (Array2::zeros((m, d)), Array2::zeros((m, d)));
        for r in 0..m {
            let xr = x.row(r);
            let mean = xr.iter().map(|&v| v as f64).sum::<f64>() / d as f64;
            let var = xr.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / d as f64;
            let (mean, rstd) = (mean as f32, (1.0 / (var + 1e-5f32 as f64).sqrt()) as f32);
            let xh: Vec<f32> = xr.iter().map(|&v| (v - mean) * rstd).collect();
            for j in 0..d {
                y[[r, j]] = (xr[j] - mean) * rstd * gain[j] + bias[j];
            }
            let (mut s1, mut s2) = (0.0f32, 0.0f32);
            for j in 0..d {
                let dxhat = g[[r, j]] * gain[j];
                s1 += dxhat;
                s2 += dxhat * xh[j];
            }
            let (m1, m2) = (s1 / d as f32, s2 / d as f32);
            for j in 0..d {
                dx[[r, j]] = rstd * (g[[r, j]] * gain[j] - m1 - xh[j] * m2);
            }
        }
        [y, dx]
    }

    #[test]
    fn interleaved_rows_give_the_bits_of_one_row_at_a_time() {
        // 19 rows: two full blocks of 8 and a partial one; one row of negative zeros.
        let mut inputs = random_inputs(&[(19, 37), (1, 37), (1, 37), (19, 37)], Inputs::Any, 8);
        inputs[0] *= 7.0;
        inputs[0].row_mut(3).fill(-0.0);
        let mut t = Tape::new();
        let v: Vec<Var> = inputs[..3].iter().map(|a| t.param(a.view())).collect();
        let y = t.layer_norm(v[0], v[1], v[2], 1e-5);
        t.backward_with(y, inputs[3].view());
        let [want_y, want_dx] = row_at_a_time(
            &inputs[0],
            inputs[1].as_slice().unwrap(),
            inputs[2].as_slice().unwrap(),
            &inputs[3],
        );
        assert_eq!(t.value(y).mapv(f32::to_bits), want_y.mapv(f32::to_bits));
        assert_eq!(
            t.grad(v[0]).unwrap().mapv(f32::to_bits),
            want_dx.mapv(f32::to_bits)
        );
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
