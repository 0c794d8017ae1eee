//! Ops that move values without arithmetic: concatenation along rows and along features,
//! slicing features, gathers (Q of the chosen action, row selection), and reshaping (the n
//! agents' rows of a sample side by side in one row).

use ndarray::{s, Array2, Axis};

use super::put;
use super::Op;
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::pool::zero;
use crate::autograd::tape::{GradCx, Tape, Var};

impl Tape {
    /// y = [a; b; ...] stacked along rows. Panics if the column counts differ or `parts` is empty.
    pub fn concat_rows(&mut self, parts: &[Var]) -> Var {
        assert!(!parts.is_empty(), "concat_rows: no parts");
        let cols = self.shape(parts[0]).1;
        let mut rows = 0;
        for &p in parts {
            let (r, c) = self.shape(p);
            assert_eq!(c, cols, "concat_rows: column counts differ");
            rows += r;
        }
        let mut y = self.pool().array(rows, cols);
        let mut at = 0;
        for &p in parts {
            let r = self.shape(p).0;
            y.slice_mut(s![at..at + r, ..]).assign(&self.value(p));
            at += r;
        }
        self.push_op(
            y,
            Op::ConcatRows {
                parts: parts.to_vec(),
            },
            parts,
        )
    }

    /// y = [a, b, ...] side by side: parts [m, n_i] give y [m, sum n_i] (e.g. an observation
    /// beside a one-hot of the last action). Panics if the row counts differ or `parts` is empty.
    pub fn concat_cols(&mut self, parts: &[Var]) -> Var {
        assert!(!parts.is_empty(), "concat_cols: no parts");
        let rows = self.shape(parts[0]).0;
        let mut cols = 0;
        for &p in parts {
            let (r, c) = self.shape(p);
            assert_eq!(r, rows, "concat_cols: row counts differ");
            cols += c;
        }
        let mut y = self.pool().array(rows, cols);
        let mut at = 0;
        for &p in parts {
            let c = self.shape(p).1;
            y.slice_mut(s![.., at..at + c]).assign(&self.value(p));
            at += c;
        }
        self.push_op(
            y,
            Op::ConcatCols {
                parts: parts.to_vec(),
            },
            parts,
        )
    }

    /// y = x[:, start..end]. Panics if the range is out of bounds.
    pub fn slice_cols(&mut self, x: Var, start: usize, end: usize) -> Var {
        let (rows, cols) = self.shape(x);
        assert!(
            start <= end && end <= cols,
            "slice_cols: {start}..{end} of {cols} columns"
        );
        let mut y = self.pool().array(rows, end - start);
        if end > start {
            let xs = self.value(x);
            let xs = xs.as_slice().expect("tape arrays are contiguous");
            let ys = y.as_slice_mut().expect("pool arrays are contiguous");
            for (yr, xr) in ys.chunks_exact_mut(end - start).zip(xs.chunks_exact(cols)) {
                yr.copy_from_slice(&xr[start..end]);
            }
        }
        self.push_op(y, Op::SliceCols { x, start }, &[x])
    }

    /// y = x read in row-major order as [rows, cols]: e.g. [B n, d] -> [B, n d] puts the n
    /// agent rows of each sample side by side (PyTorch's `reshape` on a contiguous tensor).
    /// Panics if rows * cols differs from x's element count.
    pub fn reshape(&mut self, x: Var, rows: usize, cols: usize) -> Var {
        let (r, c) = self.shape(x);
        assert_eq!(
            r * c,
            rows * cols,
            "reshape: [{r}, {c}] has {} elements, [{rows}, {cols}] needs {}",
            r * c,
            rows * cols
        );
        let mut y = self.pool().array(rows, cols);
        y.as_slice_mut()
            .expect("pool arrays are contiguous")
            .copy_from_slice(
                self.value(x)
                    .as_slice()
                    .expect("tape arrays are contiguous"),
            );
        self.push_op(y, Op::Reshape { x }, &[x])
    }

    /// y[k, 0] = x[k, index\[k\]]: one column per row, e.g. the Q-value of the action taken.
    /// Result [m, 1]. Panics if `index` does not have one entry per row or an entry is out of
    /// range (actions are validated where they enter the program).
    pub fn gather_cols(&mut self, x: Var, index: &[usize]) -> Var {
        let (rows, cols) = self.shape(x);
        assert_eq!(index.len(), rows, "gather_cols: one index per row");
        let mut y = self.pool().array(rows, 1);
        let vx = self.value(x);
        for (k, &a) in index.iter().enumerate() {
            assert!(a < cols, "gather_cols: index {a} out of range 0..{cols}");
            y[[k, 0]] = vx[[k, a]];
        }
        self.push_op(
            y,
            Op::GatherCols {
                x,
                index: index.to_vec(),
            },
            &[x],
        )
    }

    /// y[k, :] = x[index\[k\], :]: select (or reorder, or repeat) rows. Panics on an index out of
    /// range.
    pub fn gather_rows(&mut self, x: Var, index: &[usize]) -> Var {
        let (rows, cols) = self.shape(x);
        let mut y = self.pool().array(index.len(), cols);
        if cols > 0 {
            let vx = self.value(x);
            let xs = vx.as_slice().expect("tape arrays are contiguous");
            let ys = y.as_slice_mut().expect("pool arrays are contiguous");
            for (yr, &r) in ys.chunks_exact_mut(cols).zip(index) {
                assert!(r < rows, "gather_rows: row {r} out of range 0..{rows}");
                yr.copy_from_slice(&xs[r * cols..(r + 1) * cols]);
            }
        }
        self.push_op(
            y,
            Op::GatherRows {
                x,
                index: index.to_vec(),
            },
            &[x],
        )
    }
}

// Each part receives its block of rows of g.
pub(super) fn concat_rows_backward(parts: &[Var], g: &Array2<f32>, cx: &mut GradCx) {
    let mut at = 0;
    for &p in parts {
        let r = cx.value(p).nrows();
        if let Some((d, mode)) = cx.slot(p) {
            put!(mode, d, g.slice(s![at..at + r, ..]); |g| g);
        }
        at += r;
    }
}

// Each part receives its block of columns of g.
pub(super) fn concat_cols_backward(parts: &[Var], g: &Array2<f32>, cx: &mut GradCx) {
    let mut at = 0;
    for &p in parts {
        let c = cx.value(p).ncols();
        if let Some((d, mode)) = cx.slot(p) {
            put!(mode, d, g.slice(s![.., at..at + c]); |g| g);
        }
        at += c;
    }
}

// dx[:, start..end] += g, zero elsewhere.
pub(super) fn slice_cols_backward(x: Var, start: usize, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        if mode == Mode::Overwrite {
            zero(d);
        }
        let mut block = d.slice_mut(s![.., start..start + g.ncols()]);
        block += g;
    }
}

// dx = g read back in x's shape.
pub(super) fn reshape_backward(x: Var, g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        let src = g.as_slice().expect("tape arrays are contiguous");
        let dst = d.as_slice_mut().expect("tape arrays are contiguous");
        put!(mode, dst, src; |g| g);
    }
}

// dx[k, index[k]] += g[k, 0], zero elsewhere.
pub(super) fn gather_cols_backward(x: Var, index: &[usize], g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        if mode == Mode::Overwrite {
            zero(d);
        }
        for (k, &a) in index.iter().enumerate() {
            d[[k, a]] += g[[k, 0]];
        }
    }
}

// dx[index[k], :] += g[k, :] (rows picked twice receive both contributions).
pub(super) fn gather_rows_backward(x: Var, index: &[usize], g: &Array2<f32>, cx: &mut GradCx) {
    if let Some((d, mode)) = cx.slot(x) {
        if mode == Mode::Overwrite {
            zero(d);
        }
        for (k, &r) in index.iter().enumerate() {
            let mut row = d.index_axis_mut(Axis(0), r);
            row += &g.row(k);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{grad_check, Inputs};

    #[test]
    fn concat_rows_matches_finite_differences() {
        grad_check(
            |t, v| t.concat_rows(&[v[0], v[1], v[0]]),
            &[(2, 3), (1, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn concat_cols_matches_finite_differences() {
        // v[0] appears twice: its gradient is the sum of its two column blocks.
        grad_check(
            |t, v| t.concat_cols(&[v[0], v[1], v[0]]),
            &[(3, 2), (3, 1)],
            Inputs::Any,
        );
    }

    #[test]
    fn concat_cols_places_parts_side_by_side() {
        let mut t = crate::autograd::Tape::new();
        let a = t.constant(ndarray::arr2(&[[1.0f32], [2.0]]).view());
        let b = t.constant(ndarray::arr2(&[[3.0f32, 4.0], [5.0, 6.0]]).view());
        let y = t.concat_cols(&[a, b]);
        assert_eq!(
            t.value(y),
            ndarray::arr2(&[[1.0f32, 3.0, 4.0], [2.0, 5.0, 6.0]])
        );
    }

    #[test]
    fn slice_cols_matches_finite_differences() {
        grad_check(|t, v| t.slice_cols(v[0], 1, 3), &[(3, 5)], Inputs::Any);
    }

    #[test]
    fn slice_cols_fan_out_matches_finite_differences() {
        grad_check(
            |t, v| {
                let a = t.slice_cols(v[0], 0, 2);
                let b = t.slice_cols(v[0], 1, 3);
                t.mul(a, b)
            },
            &[(3, 4)],
            Inputs::Any,
        );
    }

    #[test]
    fn reshape_matches_finite_differences() {
        grad_check(
            |t, v| {
                let y = t.reshape(v[0], 2, 6);
                let back = t.reshape(y, 6, 2);
                t.mul(back, v[0])
            },
            &[(6, 2)],
            Inputs::Any,
        );
    }

    #[test]
    fn reshape_puts_each_samples_rows_side_by_side() {
        let mut t = crate::autograd::Tape::new();
        let x =
            t.constant(ndarray::arr2(&[[1.0f32, 2.0], [3.0, 4.0], [5.0, 6.0], [7.0, 8.0]]).view());
        let y = t.reshape(x, 2, 4);
        assert_eq!(
            t.value(y),
            ndarray::arr2(&[[1.0f32, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]])
        );
    }

    #[test]
    fn gather_cols_matches_finite_differences() {
        grad_check(
            |t, v| t.gather_cols(v[0], &[2, 0, 2, 1]),
            &[(4, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn gather_cols_picks_the_indexed_entries() {
        let mut t = crate::autograd::Tape::new();
        let x = t.param(ndarray::arr2(&[[1.0f32, 2.0, 3.0], [4.0, 5.0, 6.0]]).view());
        let y = t.gather_cols(x, &[2, 0]);
        assert_eq!(t.value(y), ndarray::arr2(&[[3.0f32], [4.0]]));
    }

    #[test]
    fn gathers_fan_out_matches_finite_differences() {
        grad_check(
            |t, v| {
                let q = t.gather_cols(v[0], &[1, 1, 0]);
                let r = t.slice_cols(v[0], 0, 1);
                t.mul(q, r)
            },
            &[(3, 2)],
            Inputs::Any,
        );
        grad_check(
            |t, v| {
                let g = t.gather_rows(v[0], &[1, 0]);
                t.add(g, v[0])
            },
            &[(2, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn gather_rows_with_repeats_matches_finite_differences() {
        grad_check(
            |t, v| t.gather_rows(v[0], &[2, 0, 2]),
            &[(3, 2)],
            Inputs::Any,
        );
    }
}
