//! Elementwise loops over contiguous slices for the taped ops (sums, products, gradient
//! accumulation, GPT-2's GELU), compiled for AVX-512 and AVX2 besides the baseline target and
//! chosen at run time (`simd_dispatch`). Each element's arithmetic is the same separate
//! IEEE operations in the same order on every path (no fused multiply-add), so the path
//! changes no bit; it only decides how many elements one instruction handles (the baseline
//! x86-64 build has 4 lanes, AVX-512 16), which mattered for ACAC's critic, whose GPT-2 block
//! passes over [rows, 64] and [rows, 256] activations and gradients a dozen times an update.

use super::activations::simd_dispatch;

simd_dispatch! {
    /// out\[i\] = a\[i\] + b\[i\]. Panics if the lengths differ.
    pub fn add_into(a: &[f32], b: &[f32], out: &mut [f32]) {
        assert!(a.len() == out.len() && b.len() == out.len(), "add_into: length mismatch");
        for ((o, &a), &b) in out.iter_mut().zip(a).zip(b) {
            *o = a + b;
        }
    }
}

simd_dispatch! {
    /// out\[i\] = a\[i\] - b\[i\]. Panics if the lengths differ.
    pub fn sub_into(a: &[f32], b: &[f32], out: &mut [f32]) {
        assert!(a.len() == out.len() && b.len() == out.len(), "sub_into: length mismatch");
        for ((o, &a), &b) in out.iter_mut().zip(a).zip(b) {
            *o = a - b;
        }
    }
}

simd_dispatch! {
    /// out\[i\] = a\[i\] * b\[i\]. Panics if the lengths differ.
    pub fn mul_into(a: &[f32], b: &[f32], out: &mut [f32]) {
        assert!(a.len() == out.len() && b.len() == out.len(), "mul_into: length mismatch");
        for ((o, &a), &b) in out.iter_mut().zip(a).zip(b) {
            *o = a * b;
        }
    }
}

simd_dispatch! {
    /// dst\[i\] = src\[i\], or dst\[i\] += src\[i\] when `accumulate`. Panics if the lengths
    /// differ.
    pub fn put_copy(dst: &mut [f32], src: &[f32], accumulate: bool) {
        assert_eq!(dst.len(), src.len(), "put_copy: length mismatch");
        if accumulate {
            for (d, &s) in dst.iter_mut().zip(src) {
                *d += s;
            }
        } else {
            dst.copy_from_slice(src);
        }
    }
}

simd_dispatch! {
    /// dst\[i\] = g\[i\] * b\[i\], or dst\[i\] += g\[i\] * b\[i\] when `accumulate` (the
    /// product rounded, then added). Panics if the lengths differ.
    pub fn put_mul(dst: &mut [f32], g: &[f32], b: &[f32], accumulate: bool) {
        assert!(g.len() == dst.len() && b.len() == dst.len(), "put_mul: length mismatch");
        if accumulate {
            for ((d, &g), &b) in dst.iter_mut().zip(g).zip(b) {
                *d += g * b;
            }
        } else {
            for ((d, &g), &b) in dst.iter_mut().zip(g).zip(b) {
                *d = g * b;
            }
        }
    }
}

simd_dispatch! {
    /// Each row of `rows` (of `bias.len()` columns) += bias. Panics unless `rows` holds whole
    /// rows.
    pub fn add_bias_rows(rows: &mut [f32], bias: &[f32]) {
        let n = bias.len();
        if n == 0 {
            return;
        }
        assert_eq!(rows.len() % n, 0, "add_bias_rows: not whole rows");
        for row in rows.chunks_exact_mut(n) {
            for (v, &b) in row.iter_mut().zip(bias) {
                *v += b;
            }
        }
    }
}

/// sqrt(2 / pi), as `math.sqrt(2.0 / math.pi)` rounded to f32.
pub const GELU_SQRT_2_OVER_PI: f32 = 0.797_884_6;
/// GELU's cubic term's coefficient.
pub const GELU_CUBIC: f32 = 0.044_715;

simd_dispatch! {
    /// GELU's tanh argument in PyTorch's order: u\[i\] = sqrt(2 / pi) (x + 0.044715 x^3).
    pub fn gelu_argument(xs: &[f32], us: &mut [f32]) {
        assert_eq!(xs.len(), us.len(), "gelu_argument: length mismatch");
        for (u, &x) in us.iter_mut().zip(xs) {
            *u = GELU_SQRT_2_OVER_PI * (x + GELU_CUBIC * (x * x * x));
        }
    }
}

simd_dispatch! {
    /// GELU from x and t = tanh(u): y\[i\] = 0.5 x (1 + t).
    pub fn gelu_output(xs: &[f32], ts: &[f32], ys: &mut [f32]) {
        assert!(xs.len() == ys.len() && ts.len() == ys.len(), "gelu_output: length mismatch");
        for ((y, &x), &t) in ys.iter_mut().zip(xs).zip(ts) {
            *y = 0.5 * x * (1.0 + t);
        }
    }
}

simd_dispatch! {
    /// GELU's gradient: d\[i\] (=|+=) g dy/dx with
    /// dy/dx = 0.5 (1 + t) + 0.5 x (1 - t^2) sqrt(2 / pi) (1 + 3 0.044715 x^2).
    pub fn gelu_backward(ds: &mut [f32], gs: &[f32], xs: &[f32], ts: &[f32], accumulate: bool) {
        let n = ds.len();
        assert!(gs.len() == n && xs.len() == n && ts.len() == n, "gelu_backward: length mismatch");
        let dydx = |x: f32, t: f32| {
            0.5 * (1.0 + t)
                + 0.5 * x * (1.0 - t * t) * GELU_SQRT_2_OVER_PI * (1.0 + 3.0 * GELU_CUBIC * x * x)
        };
        let rows = ds.iter_mut().zip(gs).zip(xs).zip(ts);
        if accumulate {
            rows.for_each(|(((d, &g), &x), &t)| *d += g * dydx(x, t));
        } else {
            rows.for_each(|(((d, &g), &x), &t)| *d = g * dydx(x, t));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values that exercise rounding, signed zeros, infinities and NaN.
    fn awkward(n: usize, seed: u32) -> Vec<f32> {
        let special = [
            0.0,
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            1e-38,
            -3.3e38,
        ];
        let mut s = seed;
        (0..n)
            .map(|i| {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                if i % 17 == 5 {
                    special[(s >> 8) as usize % special.len()]
                } else {
                    ((s >> 8) as f32 / (1u32 << 24) as f32 - 0.5) * 8.0
                }
            })
            .collect()
    }

    fn same_bits(a: &[f32], b: &[f32]) {
        assert_eq!(a.len(), b.len());
        for (i, (x, y)) in a.iter().zip(b).enumerate() {
            assert_eq!(x.to_bits(), y.to_bits(), "element {i}: {x} against {y}");
        }
    }

    /// Every kernel against the same arithmetic written element by element, at lengths
    /// around the vector widths (the dispatched path here is this CPU's widest).
    #[test]
    fn every_kernel_equals_its_scalar_arithmetic_bit_for_bit() {
        for n in [0, 1, 3, 7, 8, 15, 16, 17, 31, 33, 64, 257, 1000] {
            let (a, b, c) = (awkward(n, 1), awkward(n, 2), awkward(n, 3));
            let t: Vec<f32> = c.iter().map(|v| v.tanh()).collect();
            let mut out = vec![0.0; n];
            add_into(&a, &b, &mut out);
            same_bits(
                &out,
                &a.iter().zip(&b).map(|(a, b)| a + b).collect::<Vec<_>>(),
            );
            sub_into(&a, &b, &mut out);
            same_bits(
                &out,
                &a.iter().zip(&b).map(|(a, b)| a - b).collect::<Vec<_>>(),
            );
            mul_into(&a, &b, &mut out);
            same_bits(
                &out,
                &a.iter().zip(&b).map(|(a, b)| a * b).collect::<Vec<_>>(),
            );
            for accumulate in [false, true] {
                let base = |d: f32, v: f32| if accumulate { d + v } else { v };
                let mut d = c.clone();
                put_copy(&mut d, &a, accumulate);
                let want: Vec<f32> = c.iter().zip(&a).map(|(&d, &s)| base(d, s)).collect();
                same_bits(&d, &want);
                let mut d = c.clone();
                put_mul(&mut d, &a, &b, accumulate);
                let want: Vec<f32> = (0..n).map(|i| base(c[i], a[i] * b[i])).collect();
                same_bits(&d, &want);
                let mut d = c.clone();
                gelu_backward(&mut d, &a, &b, &t, accumulate);
                let want: Vec<f32> = (0..n)
                    .map(|i| {
                        let (x, t) = (b[i], t[i]);
                        let dydx = 0.5 * (1.0 + t)
                            + 0.5
                                * x
                                * (1.0 - t * t)
                                * GELU_SQRT_2_OVER_PI
                                * (1.0 + 3.0 * GELU_CUBIC * x * x);
                        base(c[i], a[i] * dydx)
                    })
                    .collect();
                same_bits(&d, &want);
            }
            gelu_argument(&a, &mut out);
            let want: Vec<f32> = a
                .iter()
                .map(|&x| GELU_SQRT_2_OVER_PI * (x + GELU_CUBIC * (x * x * x)))
                .collect();
            same_bits(&out, &want);
            gelu_output(&a, &t, &mut out);
            let want: Vec<f32> = (0..n).map(|i| 0.5 * a[i] * (1.0 + t[i])).collect();
            same_bits(&out, &want);
        }
        for n in [1, 5, 16, 19, 64] {
            let bias = awkward(n, 4);
            let mut rows = awkward(3 * n, 5);
            let want: Vec<f32> = rows
                .iter()
                .enumerate()
                .map(|(i, &v)| v + bias[i % n])
                .collect();
            add_bias_rows(&mut rows, &bias);
            same_bits(&rows, &want);
        }
    }
}
