//! The fused LSTM op over a batch of variable-length sequences. Forward and backward live in
//! `kernels/lstm.rs`; this file records the node and turns gate gradients into parameter and
//! input gradients. Checked against the unfused composition of the elementary ops and by finite
//! differences (tests below).

use ndarray::{s, Array2};

use super::Op;
use crate::autograd::kernels::gemm::{gemm, Mode};
use crate::autograd::kernels::lstm::{
    lstm_backward, lstm_backward_scratch_rows, lstm_forward, LstmCache, LstmWeights,
};
use crate::autograd::tape::{GradCx, Tape, Var};
use crate::autograd::SeqPacking;

/// The LSTM's parameters on a tape: w_ih [4H, in], w_hh [4H, H], b_ih [1, 4H], b_hh [1, 4H]
/// (PyTorch names and gate order i, f, g, o).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LstmVars {
    /// Input weights [4H, in].
    pub w_ih: Var,
    /// Recurrent weights [4H, H].
    pub w_hh: Var,
    /// Input bias [1, 4H].
    pub b_ih: Var,
    /// Recurrent bias [1, 4H].
    pub b_hh: Var,
}

/// The recorded node: its inputs, the packing, and the forward cache (stored as tape nodes so
/// [`Tape::reset`] recycles them).
#[derive(Debug)]
pub(crate) struct LstmNode {
    x: Var,
    w: LstmVars,
    packing: SeqPacking,
    h_prev: Var,
    gates: Var,
    c: Var,
    tanh_c: Var,
}

impl Tape {
    /// h for every valid position of every sequence, each unrolled from a zero state
    /// (`docs/ALGORITHMS.md` §2.3). x: [K, in] in flat (sequence, time) order with
    /// K = packing.total(); result [K, H] in the same order. Reorders rows around
    /// [`Tape::lstm_packed`] (the Q-net stays in packed order throughout and calls
    /// `lstm_packed` itself, saving the two gathers).
    pub fn lstm(&mut self, x: Var, w: LstmVars, packing: &SeqPacking) -> Var {
        let xp = self.gather_rows(x, packing.packed_to_flat());
        let yp = self.lstm_packed(xp, w, packing);
        self.gather_rows(yp, packing.flat_to_packed())
    }

    /// The LSTM over packed sequences: h for every valid position of every sequence, each
    /// unrolled from a zero state (`docs/ALGORITHMS.md` §2.3), with x: [K, in] and the result
    /// [K, H] in packed order (see [`SeqPacking`]), where every step reads and writes contiguous
    /// rows. Panics on inconsistent shapes.
    pub fn lstm_packed(&mut self, x: Var, w: LstmVars, packing: &SeqPacking) -> Var {
        let k = self.shape(x).0;
        let h = self.shape(w.w_hh).1;
        assert_eq!(
            k,
            packing.total(),
            "lstm: x has {k} rows, the packing {}",
            packing.total()
        );
        let [s_hp, s_g, s_c, s_tc] = LstmCache::shapes(k, h);
        let mut cache = LstmCache {
            h_prev: self.pool().array(s_hp.0, s_hp.1),
            gates: self.pool().array(s_g.0, s_g.1),
            c: self.pool().array(s_c.0, s_c.1),
            tanh_c: self.pool().array(s_tc.0, s_tc.1),
        };
        let mut y = self.pool().array(k, h);
        {
            let (b_ih, b_hh) = (self.value(w.b_ih), self.value(w.b_hh));
            let weights = LstmWeights {
                w_ih: self.value(w.w_ih),
                w_hh: self.value(w.w_hh),
                b_ih: b_ih.as_slice().expect("tape arrays are contiguous"),
                b_hh: b_hh.as_slice().expect("tape arrays are contiguous"),
            };
            lstm_forward(self.value(x), &weights, packing, &mut cache, &mut y);
        }
        let node = LstmNode {
            x,
            w,
            packing: packing.clone(),
            h_prev: self.push_aux(cache.h_prev),
            gates: self.push_aux(cache.gates),
            c: self.push_aux(cache.c),
            tanh_c: self.push_aux(cache.tanh_c),
        };
        self.push_op(
            y,
            Op::Lstm(Box::new(node)),
            &[x, w.w_ih, w.w_hh, w.b_ih, w.b_hh],
        )
    }
}

impl LstmNode {
    pub(super) fn backward(&self, g: &Array2<f32>, cx: &mut GradCx) {
        let p = &self.packing;
        let (k, h) = (p.total(), g.ncols());
        if k == 0 {
            return;
        }
        let (x, h_prev) = (cx.value(self.x), cx.value(self.h_prev));
        let (w_ih, w_hh) = (cx.value(self.w.w_ih), cx.value(self.w.w_hh));
        let (gates, c, tanh_c) = (
            cx.value(self.gates),
            cx.value(self.c),
            cx.value(self.tanh_c),
        );
        let input = x.ncols();
        let wants_w = cx.wants(self.w.w_ih) || cx.wants(self.w.w_hh);

        let mut dgates = cx.pool.array(k, 4 * h);
        let rows = lstm_backward_scratch_rows(p);
        let mut dh_rec = cx.pool.array(rows, h);
        let mut dc = cx.pool.array(rows, h);
        let mut db = cx.pool.array(1, 4 * h);
        let mut dw_ih = cx.pool.array(4 * h, input);
        let mut dw_hh = cx.pool.array(4 * h, h);
        let mut dx = cx.slot(self.x);
        // Each gradient is a product over all steps, dW_ih = dG^T x, dW_hh = dG^T h_prev,
        // dx = dG W_ih, computed chunk by chunk while the chunk's dG is still in cache.
        let mut first = true;
        lstm_backward(
            g.view(),
            w_hh.view(),
            p,
            gates,
            c,
            tanh_c,
            &mut dgates,
            &mut dh_rec,
            &mut dc,
            db.as_slice_mut().expect("pool arrays are contiguous"),
            |r, dg| {
                let dg = dg.slice(s![r.clone(), ..]);
                if wants_w {
                    let mode = if first {
                        Mode::Overwrite
                    } else {
                        Mode::Accumulate
                    };
                    gemm(dg.t(), x.slice(s![r.clone(), ..]), dw_ih.view_mut(), mode);
                    gemm(
                        dg.t(),
                        h_prev.slice(s![r.clone(), ..]),
                        dw_hh.view_mut(),
                        mode,
                    );
                }
                first = false;
                if let Some((d, mode)) = dx.as_mut() {
                    gemm(dg, w_ih.view(), d.slice_mut(s![r, ..]), *mode);
                }
            },
        );
        for (v, dw) in [(self.w.w_ih, &dw_ih), (self.w.w_hh, &dw_hh)] {
            if let Some((d, mode)) = cx.slot(v) {
                super::put!(mode, d, dw; |g| g);
            }
        }
        // Both biases get the column sums of dG.
        for v in [self.w.b_ih, self.w.b_hh] {
            if let Some((d, mode)) = cx.slot(v) {
                super::put!(mode, d, &db; |g| g);
            }
        }
        for a in [dgates, dh_rec, dc, db, dw_ih, dw_hh] {
            cx.pool.give_array(a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{assert_close, grad_check, random_inputs, Inputs};
    use super::*;

    /// The LSTM written with elementary ops, one sequence and one step at a time: the oracle.
    fn unfused(t: &mut Tape, x: Var, w: LstmVars, packing: &SeqPacking) -> Var {
        let h = t.shape(w.w_hh).1;
        let mut outs = Vec::new();
        for (s, &len) in packing.lengths().iter().enumerate() {
            let mut hv = t.constant(Array2::zeros((1, h)).view());
            let mut cv = t.constant(Array2::zeros((1, h)).view());
            for step in 0..len {
                let xt = t.gather_rows(x, &[packing.flat_row(s, step)]);
                let a = t.matmul_nt(xt, w.w_ih);
                let a = t.add_bias(a, w.b_ih);
                let b = t.matmul_nt(hv, w.w_hh);
                let b = t.add_bias(b, w.b_hh);
                let z = t.add(a, b);
                let i = t.slice_cols(z, 0, h);
                let i = t.sigmoid(i);
                let f = t.slice_cols(z, h, 2 * h);
                let f = t.sigmoid(f);
                let g = t.slice_cols(z, 2 * h, 3 * h);
                let g = t.tanh(g);
                let o = t.slice_cols(z, 3 * h, 4 * h);
                let o = t.sigmoid(o);
                let fc = t.mul(f, cv);
                let ig = t.mul(i, g);
                cv = t.add(fc, ig);
                let tc = t.tanh(cv);
                hv = t.mul(o, tc);
                outs.push(hv);
            }
        }
        t.concat_rows(&outs)
    }

    fn shapes(k: usize, input: usize, h: usize) -> [(usize, usize); 5] {
        [
            (k, input),
            (4 * h, input),
            (4 * h, h),
            (1, 4 * h),
            (1, 4 * h),
        ]
    }

    fn vars(v: &[Var]) -> LstmVars {
        LstmVars {
            w_ih: v[1],
            w_hh: v[2],
            b_ih: v[3],
            b_hh: v[4],
        }
    }

    #[test]
    fn fused_lstm_equals_its_unfused_composition_in_value_and_gradient() {
        let lengths = [3, 0, 5, 1, 5, 2];
        let packing = SeqPacking::new(&lengths);
        let (input, h) = (3, 4);
        let inputs = random_inputs(&shapes(packing.total(), input, h), Inputs::Any, 5);
        let seed = random_inputs(&[(packing.total(), h)], Inputs::Any, 6).remove(0);
        let run = |fused: bool| {
            let mut t = Tape::new();
            let v: Vec<Var> = inputs.iter().map(|a| t.param(a.view())).collect();
            let y = if fused {
                t.lstm(v[0], vars(&v), &packing)
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

    #[test]
    fn lstm_matches_finite_differences() {
        let packing = SeqPacking::new(&[2, 4, 1, 4]);
        let k = packing.total();
        grad_check(
            move |t, v| t.lstm(v[0], vars(v), &packing),
            &shapes(k, 3, 2),
            Inputs::Any,
        );
    }

    #[test]
    fn lstm_fan_out_matches_finite_differences() {
        // Two LSTM nodes share every input; the second sees the first's output as its input.
        let packing = SeqPacking::new(&[3, 1, 2]);
        let k = packing.total();
        grad_check(
            move |t, v| {
                let a = t.lstm(v[0], vars(v), &packing);
                let b = t.lstm(a, vars(v), &packing);
                t.add(a, b)
            },
            &shapes(k, 2, 2),
            Inputs::Any,
        );
    }

    #[test]
    fn lstm_with_a_constant_recurrent_weight_matches_finite_differences() {
        let packing = SeqPacking::new(&[3, 3, 1]);
        let k = packing.total();
        let w_hh = random_inputs(&[(8, 2)], Inputs::Any, 9).remove(0);
        grad_check(
            move |t, v| {
                let w_hh = t.constant(w_hh.view());
                let w = LstmVars {
                    w_ih: v[1],
                    w_hh,
                    b_ih: v[2],
                    b_hh: v[3],
                };
                t.lstm(v[0], w, &packing)
            },
            &[(k, 3), (8, 3), (1, 8), (1, 8)],
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
            let w = LstmVars {
                w_ih: v[0],
                w_hh: v[1],
                b_ih: v[2],
                b_hh: v[3],
            };
            let y = t.lstm(xv, w, &SeqPacking::new(lengths));
            t.value(y).to_owned()
        };
        let both = run(&[3, 4], xs.clone());
        let second = run(&[4], xs.slice(s![3.., ..]).to_owned());
        assert_close(&both.slice(s![3.., ..]).to_owned(), &second, 0.0);
    }
}
