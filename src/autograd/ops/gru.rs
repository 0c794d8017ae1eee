//! The fused GRU op over a batch of variable-length sequences, built as the LSTM op is
//! (`lstm.rs`). Forward and backward live in `kernels/gru.rs`; this file records the node and
//! turns gate gradients into parameter and input gradients. Checked against the unfused
//! composition of the public elementary ops and by finite differences (tests below).

use ndarray::{s, Array2};

use super::Op;
use crate::autograd::kernels::gemm::{gemm, Mode};
use crate::autograd::kernels::gru::{gru_backward, gru_forward, permute_nrz, GruCache, GruWeights};
use crate::autograd::tape::{GradCx, Tape, Var};
use crate::autograd::SeqPacking;

/// The GRU's parameters on a tape: w_ih [3H, in], w_hh [3H, H], b_ih [1, 3H], b_hh [1, 3H]
/// (PyTorch names and gate order r, z, n).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GruVars {
    /// Input weights [3H, in].
    pub w_ih: Var,
    /// Recurrent weights [3H, H].
    pub w_hh: Var,
    /// Input bias [1, 3H].
    pub b_ih: Var,
    /// Recurrent bias [1, 3H].
    pub b_hh: Var,
}

/// The recorded node: its inputs, the packing, and the forward cache (stored as tape nodes so
/// [`Tape::reset`] recycles them).
#[derive(Debug)]
pub(crate) struct GruNode {
    x: Var,
    w: GruVars,
    packing: SeqPacking,
    h_prev: Var,
    gates: Var,
    hn: Var,
}

impl Tape {
    /// h for every valid position of every sequence, each unrolled from a zero state.
    /// x: [K, in] in flat (sequence, time) order with K = packing.total(); result [K, H] in the
    /// same order. Reorders rows around [`Tape::gru_packed`].
    pub fn gru(&mut self, x: Var, w: GruVars, packing: &SeqPacking) -> Var {
        let xp = self.gather_rows(x, packing.packed_to_flat());
        let yp = self.gru_packed(xp, w, packing);
        self.gather_rows(yp, packing.flat_to_packed())
    }

    /// The GRU (PyTorch's `nn.GRU` equations, see `kernels/gru.rs`) over packed sequences: h for
    /// every valid position of every sequence, each unrolled from a zero state, with x: [K, in]
    /// and the result [K, H] in packed order (see [`SeqPacking`]). Panics on inconsistent
    /// shapes.
    pub fn gru_packed(&mut self, x: Var, w: GruVars, packing: &SeqPacking) -> Var {
        let k = self.shape(x).0;
        let h = self.shape(w.w_hh).1;
        assert_eq!(
            k,
            packing.total(),
            "gru: x has {k} rows, the packing {}",
            packing.total()
        );
        let [s_hp, s_g, s_hn] = GruCache::shapes(k, h);
        let mut cache = GruCache {
            h_prev: self.pool().array(s_hp.0, s_hp.1),
            gates: self.pool().array(s_g.0, s_g.1),
            hn: self.pool().array(s_hn.0, s_hn.1),
        };
        let mut y = self.pool().array(k, h);
        {
            let (b_ih, b_hh) = (self.value(w.b_ih), self.value(w.b_hh));
            let weights = GruWeights {
                w_ih: self.value(w.w_ih),
                w_hh: self.value(w.w_hh),
                b_ih: b_ih.as_slice().expect("tape arrays are contiguous"),
                b_hh: b_hh.as_slice().expect("tape arrays are contiguous"),
            };
            gru_forward(self.value(x), &weights, packing, &mut cache, &mut y);
        }
        let node = GruNode {
            x,
            w,
            packing: packing.clone(),
            h_prev: self.push_aux(cache.h_prev),
            gates: self.push_aux(cache.gates),
            hn: self.push_aux(cache.hn),
        };
        self.push_op(
            y,
            Op::Gru(Box::new(node)),
            &[x, w.w_ih, w.w_hh, w.b_ih, w.b_hh],
        )
    }
}

impl GruNode {
    pub(super) fn backward(&self, g: &Array2<f32>, cx: &mut GradCx) {
        let p = &self.packing;
        let (k, h) = (p.total(), g.ncols());
        if k == 0 {
            return;
        }
        let (x, h_prev) = (cx.value(self.x), cx.value(self.h_prev));
        let (w_ih, w_hh) = (cx.value(self.w.w_ih), cx.value(self.w.w_hh));
        let (gates, hn) = (cx.value(self.gates), cx.value(self.hn));
        let input = x.ncols();
        let wants_w = cx.wants(self.w.w_ih) || cx.wants(self.w.w_hh);

        let mut dg = cx.pool.array(k, 4 * h);
        let mut dh_rec = cx.pool.array(p.batch_size(0), h);
        let mut dbias = cx.pool.array(1, 4 * h);
        // W_ih's gate blocks in dg's order (n, r, z), and its gradient in that order.
        let w_ih_nrz = permute_nrz(w_ih.view());
        let mut dw_ih_nrz = cx.pool.array(3 * h, input);
        let mut dw_hh = cx.pool.array(3 * h, h);
        let mut dx = cx.slot(self.x);
        // Each gradient is a product over all steps, dW_ih = dA^T x, dW_hh = dB^T h_prev,
        // dx = dA W_ih, computed chunk by chunk while the chunk's rows are still in cache;
        // dA = dg[:, ..3H], dB = dg[:, H..] (see DG_BLOCKS).
        let mut first = true;
        gru_backward(
            g.view(),
            w_hh.view(),
            p,
            h_prev,
            gates,
            hn,
            &mut dg,
            &mut dh_rec,
            dbias.as_slice_mut().expect("pool arrays are contiguous"),
            |r, dg| {
                let da = dg.slice(s![r.clone(), ..3 * h]);
                if wants_w {
                    let mode = if first {
                        Mode::Overwrite
                    } else {
                        Mode::Accumulate
                    };
                    gemm(
                        da.t(),
                        x.slice(s![r.clone(), ..]),
                        dw_ih_nrz.view_mut(),
                        mode,
                    );
                    gemm(
                        dg.slice(s![r.clone(), h..]).t(),
                        h_prev.slice(s![r.clone(), ..]),
                        dw_hh.view_mut(),
                        mode,
                    );
                }
                first = false;
                if let Some((d, mode)) = dx.as_mut() {
                    gemm(da, w_ih_nrz.view(), d.slice_mut(s![r, ..]), *mode);
                }
            },
        );
        if let Some((d, mode)) = cx.slot(self.w.w_ih) {
            // Back from (n, r, z) to W_ih's (r, z, n) rows.
            super::put!(mode, d.slice_mut(s![..2 * h, ..]), dw_ih_nrz.slice(s![h.., ..]); |g| g);
            super::put!(mode, d.slice_mut(s![2 * h.., ..]), dw_ih_nrz.slice(s![..h, ..]); |g| g);
        }
        if let Some((d, mode)) = cx.slot(self.w.w_hh) {
            super::put!(mode, d, &dw_hh; |g| g);
        }
        // dbias = column sums of dg, blocks [a_n, r, z, b_n]: b_ih gets (r, z, a_n), b_hh gets
        // (r, z, b_n), each in its (r, z, n) order.
        let sums = dbias.as_slice().expect("pool arrays are contiguous");
        if let Some((d, mode)) = cx.slot(self.w.b_ih) {
            let d = d.as_slice_mut().expect("tape arrays are contiguous");
            super::put!(mode, &mut d[..2 * h], &sums[h..3 * h]; |g| g);
            super::put!(mode, &mut d[2 * h..], &sums[..h]; |g| g);
        }
        if let Some((d, mode)) = cx.slot(self.w.b_hh) {
            let d = d.as_slice_mut().expect("tape arrays are contiguous");
            super::put!(mode, d, &sums[h..]; |g| g);
        }
        for a in [dg, dh_rec, dbias, dw_ih_nrz, dw_hh] {
            cx.pool.give_array(a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{assert_close, grad_check, random_inputs, Inputs};
    use super::*;

    /// The GRU written with the public elementary ops, one sequence and one step at a time:
    /// the oracle for the fused op.
    fn unfused(t: &mut Tape, x: Var, w: GruVars, packing: &SeqPacking) -> Var {
        let h = t.shape(w.w_hh).1;
        let ones = t.constant(Array2::ones((1, h)).view());
        let mut outs = Vec::new();
        for (s, &len) in packing.lengths().iter().enumerate() {
            let mut hv = t.constant(Array2::zeros((1, h)).view());
            for step in 0..len {
                let xt = t.gather_rows(x, &[packing.flat_row(s, step)]);
                let a = t.matmul_nt(xt, w.w_ih);
                let a = t.add_bias(a, w.b_ih);
                let b = t.matmul_nt(hv, w.w_hh);
                let b = t.add_bias(b, w.b_hh);
                let (a_r, b_r) = (t.slice_cols(a, 0, h), t.slice_cols(b, 0, h));
                let pre_r = t.add(a_r, b_r);
                let r = t.sigmoid(pre_r);
                let (a_z, b_z) = (t.slice_cols(a, h, 2 * h), t.slice_cols(b, h, 2 * h));
                let pre_z = t.add(a_z, b_z);
                let z = t.sigmoid(pre_z);
                let (a_n, b_n) = (t.slice_cols(a, 2 * h, 3 * h), t.slice_cols(b, 2 * h, 3 * h));
                let rb = t.mul(r, b_n);
                let pre_n = t.add(a_n, rb);
                let n = t.tanh(pre_n);
                // h = (1 - z) n + z h_prev
                let one_minus_z = t.sub(ones, z);
                let keep = t.mul(one_minus_z, n);
                let carry = t.mul(z, hv);
                hv = t.add(keep, carry);
                outs.push(hv);
            }
        }
        t.concat_rows(&outs)
    }

    fn shapes(k: usize, input: usize, h: usize) -> [(usize, usize); 5] {
        [
            (k, input),
            (3 * h, input),
            (3 * h, h),
            (1, 3 * h),
            (1, 3 * h),
        ]
    }

    fn vars(v: &[Var]) -> GruVars {
        GruVars {
            w_ih: v[1],
            w_hh: v[2],
            b_ih: v[3],
            b_hh: v[4],
        }
    }

    #[test]
    fn fused_gru_equals_its_unfused_composition_in_value_and_gradient() {
        // H = 20 exercises both the 16-lane blocks and the one-lane rest of the kernels.
        for (input, h) in [(3, 4), (5, 20)] {
            let lengths = [3, 0, 5, 1, 5, 2];
            let packing = SeqPacking::new(&lengths);
            let inputs = random_inputs(&shapes(packing.total(), input, h), Inputs::Any, 5);
            let seed = random_inputs(&[(packing.total(), h)], Inputs::Any, 6).remove(0);
            let run = |fused: bool| {
                let mut t = Tape::new();
                let v: Vec<Var> = inputs.iter().map(|a| t.param(a.view())).collect();
                let y = if fused {
                    t.gru(v[0], vars(&v), &packing)
                } else {
                    unfused(&mut t, v[0], vars(&v), &packing)
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

    #[test]
    fn gru_matches_finite_differences() {
        let packing = SeqPacking::new(&[2, 4, 1, 4]);
        let k = packing.total();
        grad_check(
            move |t, v| t.gru(v[0], vars(v), &packing),
            &shapes(k, 3, 2),
            Inputs::Any,
        );
    }

    #[test]
    fn gru_fan_out_matches_finite_differences() {
        // Two GRU nodes share every input; the second sees the first's output as its input.
        let packing = SeqPacking::new(&[3, 1, 2]);
        let k = packing.total();
        grad_check(
            move |t, v| {
                let a = t.gru(v[0], vars(v), &packing);
                let b = t.gru(a, vars(v), &packing);
                t.add(a, b)
            },
            &shapes(k, 2, 2),
            Inputs::Any,
        );
    }

    #[test]
    fn gru_with_a_constant_recurrent_weight_matches_finite_differences() {
        let packing = SeqPacking::new(&[3, 3, 1]);
        let k = packing.total();
        let w_hh = random_inputs(&[(6, 2)], Inputs::Any, 9).remove(0);
        grad_check(
            move |t, v| {
                let w_hh = t.constant(w_hh.view());
                let w = GruVars {
                    w_ih: v[1],
                    w_hh,
                    b_ih: v[2],
                    b_hh: v[3],
                };
                t.gru(v[0], w, &packing)
            },
            &[(k, 3), (6, 3), (1, 6), (1, 6)],
            Inputs::Any,
        );
    }

    #[test]
    fn each_sequence_starts_from_a_zero_state() {
        // A sequence's outputs do not depend on which other sequences share the batch.
        let (input, h) = (2, 3);
        let ws = random_inputs(&shapes(0, input, h)[1..], Inputs::Any, 2);
        let xs = random_inputs(&[(7, input)], Inputs::Any, 3).remove(0);
        let run = |lengths: &[usize], x: Array2<f32>| {
            let mut t = Tape::new();
            let xv = t.constant(x.view());
            let v: Vec<Var> = ws.iter().map(|a| t.param(a.view())).collect();
            let w = GruVars {
                w_ih: v[0],
                w_hh: v[1],
                b_ih: v[2],
                b_hh: v[3],
            };
            let y = t.gru(xv, w, &SeqPacking::new(lengths));
            t.value(y).to_owned()
        };
        let both = run(&[3, 4], xs.clone());
        let second = run(&[4], xs.slice(s![3.., ..]).to_owned());
        assert_close(&both.slice(s![3.., ..]).to_owned(), &second, 0.0);
    }
}
