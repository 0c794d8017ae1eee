//! Reductions over consecutive groups of rows: with a batch of B samples of n agents stored as
//! B n rows (as `attention.rs` stores them), these pool the agents of each sample, [B n, d] ->
//! [B, d]. ACAC's `mean_linear` and `max_linear` value heads are these followed by a linear
//! layer (PyTorch's `x.mean(dim=1)` and `x.max(dim=1)[0]` on [B, n, d]).

use ndarray::Array2;

use super::Op;
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::pool::zero;
use crate::autograd::tape::{GradCx, Tape, Var};

const CONTIGUOUS: &str = "tape arrays are contiguous";

impl Tape {
    /// y[b, :] = mean of rows b n..(b + 1) n of x: [B n, d] -> [B, d] (sum, then divided by
    /// n, as PyTorch's `mean`). Panics if n is 0 or does not divide the rows.
    pub fn row_group_mean(&mut self, x: Var, n: usize) -> Var {
        let (rows, d) = self.shape(x);
        assert!(
            n > 0 && rows % n == 0,
            "row_group_mean: {rows} rows are not groups of {n}"
        );
        let mut y = self.pool().zeros(rows / n, d);
        {
            let xs = self.value(x);
            let xs = xs.as_slice().expect(CONTIGUOUS);
            let ys = y.as_slice_mut().expect(CONTIGUOUS);
            for (yr, group) in ys.chunks_exact_mut(d).zip(xs.chunks_exact(n * d)) {
                for xr in group.chunks_exact(d) {
                    for (y, &x) in yr.iter_mut().zip(xr) {
                        *y += x;
                    }
                }
                for y in yr.iter_mut() {
                    *y /= n as f32;
                }
            }
        }
        self.push_op(y, Op::RowGroupMean { x, n }, &[x])
    }

    /// y[b, c] = max over rows b n..(b + 1) n of x[., c]: [B n, d] -> [B, d]. The gradient
    /// flows to the row holding the maximum, the first one on a tie. Panics if n is 0 or does
    /// not divide the rows.
    pub fn row_group_max(&mut self, x: Var, n: usize) -> Var {
        let (rows, d) = self.shape(x);
        assert!(
            n > 0 && rows % n == 0,
            "row_group_max: {rows} rows are not groups of {n}"
        );
        let mut y = self.pool().array(rows / n, d);
        // The winning row within its group, per output element (exact in f32 for n < 2^24).
        let mut arg = self.pool().array(rows / n, d);
        {
            let xs = self.value(x);
            let xs = xs.as_slice().expect(CONTIGUOUS);
            let ys = y.as_slice_mut().expect(CONTIGUOUS);
            let args = arg.as_slice_mut().expect(CONTIGUOUS);
            for ((yr, ar), group) in ys
                .chunks_exact_mut(d)
                .zip(args.chunks_exact_mut(d))
                .zip(xs.chunks_exact(n * d))
            {
                yr.copy_from_slice(&group[..d]);
                ar.fill(0.0);
                for (i, xr) in group.chunks_exact(d).enumerate().skip(1) {
                    for c in 0..d {
                        // NaN wins, as in PyTorch's max.
                        if xr[c] > yr[c] || (xr[c].is_nan() && !yr[c].is_nan()) {
                            yr[c] = xr[c];
                            ar[c] = i as f32;
                        }
                    }
                }
            }
        }
        let arg = self.push_aux(arg);
        self.push_op(y, Op::RowGroupMax { x, n, arg }, &[x])
    }
}

// dx[b n + i, :] = g[b, :] / n
pub(super) fn row_group_mean_backward(x: Var, n: usize, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((dst, mode)) = cx.slot(x) {
        let d = g.ncols();
        let gs = g.as_slice().expect(CONTIGUOUS);
        let ds = dst.as_slice_mut().expect(CONTIGUOUS);
        for (gr, group) in gs.chunks_exact(d).zip(ds.chunks_exact_mut(n * d)) {
            for dr in group.chunks_exact_mut(d) {
                for (dv, &gv) in dr.iter_mut().zip(gr) {
                    match mode {
                        Mode::Overwrite => *dv = gv / n as f32,
                        Mode::Accumulate => *dv += gv / n as f32,
                    }
                }
            }
        }
    }
}

// dx[b n + arg[b, c], c] = g[b, c], zero elsewhere
pub(super) fn row_group_max_backward(x: Var, n: usize, arg: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let args = cx.value(arg).as_slice().expect(CONTIGUOUS);
    if let Some((dst, mode)) = cx.slot(x) {
        if mode == Mode::Overwrite {
            zero(dst);
        }
        let d = g.ncols();
        let gs = g.as_slice().expect(CONTIGUOUS);
        let ds = dst.as_slice_mut().expect(CONTIGUOUS);
        for ((gr, ar), group) in gs
            .chunks_exact(d)
            .zip(args.chunks_exact(d))
            .zip(ds.chunks_exact_mut(n * d))
        {
            for c in 0..d {
                group[ar[c] as usize * d + c] += gr[c];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use ndarray::arr2;

    use super::super::grad_check::{grad_check, Inputs};
    use crate::autograd::Tape;

    #[test]
    fn row_group_mean_matches_finite_differences() {
        grad_check(|t, v| t.row_group_mean(v[0], 3), &[(6, 4)], Inputs::Any);
    }

    #[test]
    fn row_group_max_matches_finite_differences() {
        // Offsets 3 apart keep rows of a group more than a step apart (away from the kink)
        // and put the maximum in a different row from column to column.
        grad_check(
            |t, v| {
                let off =
                    ndarray::Array2::from_shape_fn((6, 3), |(r, c)| 3.0 * ((r + c) % 3) as f32);
                let off = t.constant(off.view());
                let x = t.add(v[0], off);
                t.row_group_max(x, 3)
            },
            &[(6, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn group_reductions_fan_out_match_finite_differences() {
        grad_check(
            |t, v| {
                let off =
                    ndarray::Array2::from_shape_fn((4, 3), |(r, c)| 3.0 * ((r + c) % 2) as f32);
                let off = t.constant(off.view());
                let x = t.add(v[0], off);
                let m = t.row_group_mean(x, 2);
                let x = t.row_group_max(x, 2);
                t.mul(m, x)
            },
            &[(4, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn groups_pool_their_own_rows_and_max_ties_go_to_the_first() {
        let mut t = Tape::new();
        let x = t.param(arr2(&[[1.0f32, 5.0], [3.0, 5.0], [-1.0, 0.0], [-2.0, 4.0]]).view());
        let mean = t.row_group_mean(x, 2);
        let max = t.row_group_max(x, 2);
        assert_eq!(t.value(mean), arr2(&[[2.0f32, 5.0], [-1.5, 2.0]]));
        assert_eq!(t.value(max), arr2(&[[3.0f32, 5.0], [-1.0, 4.0]]));
        let s = t.sum(max);
        t.backward(s);
        assert_eq!(
            t.grad(x).unwrap(),
            arr2(&[[0.0f32, 1.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        );
    }
}
