//! Multi-head self-attention within sets of rows: GPT-2's attention (`_attn` of HuggingFace's
//! `GPT2Attention`) over the n agents of each sample, as ACAC's critic runs it (no causal
//! mask). The tape is 2-D, so a batch of B samples of n agents is B n rows, sample by sample,
//! and head h owns columns h hd..(h + 1) hd of q, k, v and of the output (GPT-2's
//! `_split_heads` / `_merge_heads`). For each sample b and head h:
//!
//! ```text
//! S = Q K^T / sqrt(hd) + M,   P = softmax_rows(S),   O = (P * D) V
//! ```
//!
//! with M an optional additive mask and D optional dropout multipliers on the probabilities
//! (GPT-2's `attn_dropout`), supplied from outside so a run can replay a reference's masks.
//! One fused node with its own backward: n is a handful of agents, so the per-sample products
//! are tiny and run as plain dot products, never through the GEMM. The tests keep the
//! composition of elementary ops as the oracle.

use ndarray::Array2;

use super::Op;
use crate::autograd::kernels::dense::dot;
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};

/// What [`Tape::self_attention`] attends within and what it masks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AttentionSpec {
    /// n: how many consecutive rows form one set (the agents of one sample); the row count
    /// must be a multiple of it.
    pub set_size: usize,
    /// Number of heads; divides the width d.
    pub n_head: usize,
    /// Optional additive mask [B n, n]: entry (b n + i, j) is added to query i's score for key
    /// j of sample b, in every head (GPT-2 turns its 0/1 `attention_mask` into 0 / f32::MIN).
    pub mask: Option<Var>,
    /// Optional dropout multipliers [B n, n_head n] on the probabilities: entry
    /// (b n + i, h n + j) scales P[i, j] of head h of sample b (0 or 1 / (1 - p) for dropout
    /// with rate p, as PyTorch's `nn.Dropout` in training).
    pub dropout: Option<Var>,
}

impl AttentionSpec {
    /// Attention over sets of `set_size` rows with `n_head` heads, no mask, no dropout.
    pub fn new(set_size: usize, n_head: usize) -> Self {
        AttentionSpec {
            set_size,
            n_head,
            mask: None,
            dropout: None,
        }
    }
}

/// The recorded node: its inputs and the probabilities P (before dropout), [B n, n_head n].
#[derive(Debug)]
pub(crate) struct AttentionNode {
    q: Var,
    k: Var,
    v: Var,
    spec: AttentionSpec,
    probs: Var,
}

/// Row-major index helpers for one node's shapes.
#[derive(Clone, Copy)]
struct Dims {
    n: usize,
    heads: usize,
    hd: usize,
    d: usize,
}

impl Dims {
    /// Head h's columns of row `row` of a [B n, d] array.
    fn head(&self, row: usize, h: usize) -> std::ops::Range<usize> {
        let at = row * self.d + h * self.hd;
        at..at + self.hd
    }

    /// Head h's n entries of row `row` of a [B n, n_head n] array.
    fn keys(&self, row: usize, h: usize) -> std::ops::Range<usize> {
        let at = (row * self.heads + h) * self.n;
        at..at + self.n
    }
}

const CONTIGUOUS: &str = "tape arrays are contiguous";

impl Tape {
    /// Multi-head self-attention within each set of `spec.set_size` consecutive rows (see the
    /// module docs): q, k, v: [B n, d] -> [B n, d], heads merged back in column blocks. Panics
    /// if the shapes differ, n does not divide the rows, n_head does not divide d, or a mask
    /// or dropout array has the wrong shape.
    pub fn self_attention(&mut self, q: Var, k: Var, v: Var, spec: AttentionSpec) -> Var {
        let (rows, d) = self.shape(q);
        assert!(
            self.shape(k) == (rows, d) && self.shape(v) == (rows, d),
            "self_attention: q, k, v must have one shape, got {:?}, {:?}, {:?}",
            (rows, d),
            self.shape(k),
            self.shape(v)
        );
        let (n, heads) = (spec.set_size, spec.n_head);
        assert!(
            n > 0 && rows % n == 0,
            "self_attention: {rows} rows are not sets of {n}"
        );
        assert!(
            heads > 0 && d % heads == 0,
            "self_attention: {heads} heads do not divide width {d}"
        );
        if let Some(m) = spec.mask {
            let s = self.shape(m);
            assert_eq!(s, (rows, n), "self_attention: mask must be [{rows}, {n}]");
        }
        if let Some(m) = spec.dropout {
            let s = self.shape(m);
            assert_eq!(
                s,
                (rows, heads * n),
                "self_attention: dropout must be [{rows}, {}]",
                heads * n
            );
        }
        let dims = Dims {
            n,
            heads,
            hd: d / heads,
            d,
        };
        let mut y = self.pool().array(rows, d);
        let mut probs = self.pool().array(rows, heads * n);
        {
            let (qs, ks, vs) = (self.value(q), self.value(k), self.value(v));
            let mask = spec.mask.map(|m| self.value(m));
            let drop = spec.dropout.map(|m| self.value(m));
            forward(
                dims,
                [
                    qs.as_slice().expect(CONTIGUOUS),
                    ks.as_slice().expect(CONTIGUOUS),
                    vs.as_slice().expect(CONTIGUOUS),
                ],
                mask.as_ref().map(|m| m.as_slice().expect(CONTIGUOUS)),
                drop.as_ref().map(|m| m.as_slice().expect(CONTIGUOUS)),
                probs.as_slice_mut().expect(CONTIGUOUS),
                y.as_slice_mut().expect(CONTIGUOUS),
            );
        }
        let probs = self.push_aux(probs);
        let node = AttentionNode {
            q,
            k,
            v,
            spec,
            probs,
        };
        self.push_op(y, Op::SelfAttention(Box::new(node)), &[q, k, v])
    }
}

/// P and O for every sample, head and query (see the module docs).
fn forward(
    dims: Dims,
    [q, k, v]: [&[f32]; 3],
    mask: Option<&[f32]>,
    drop: Option<&[f32]>,
    probs: &mut [f32],
    y: &mut [f32],
) {
    let Dims { n, heads, hd, d } = dims;
    // GPT-2 divides by sqrt(hd) as an f32 tensor.
    let scale = (hd as f32).sqrt();
    y.fill(0.0);
    for base in (0..q.len() / d).step_by(n) {
        for h in 0..heads {
            for i in 0..n {
                let row = base + i;
                let p = &mut probs[dims.keys(row, h)];
                let qi = &q[dims.head(row, h)];
                for (j, s) in p.iter_mut().enumerate() {
                    *s = dot(qi, &k[dims.head(base + j, h)]) / scale;
                    if let Some(m) = mask {
                        *s += m[row * n + j];
                    }
                }
                softmax_in_place(p);
                let out = &mut y[dims.head(row, h)];
                for (j, &pj) in p.iter().enumerate() {
                    let w = drop.map_or(pj, |m| pj * m[dims.keys(row, h)][j]);
                    for (o, &vv) in out.iter_mut().zip(&v[dims.head(base + j, h)]) {
                        *o += w * vv;
                    }
                }
            }
        }
    }
}

/// s <- softmax(s), shifted by the maximum (PyTorch's order: exp(s - max), then divide by
/// the sum).
fn softmax_in_place(s: &mut [f32]) {
    let max = s.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let mut sum = 0.0;
    for v in s.iter_mut() {
        *v = (*v - max).exp();
        sum += *v;
    }
    for v in s.iter_mut() {
        *v /= sum;
    }
}

impl AttentionNode {
    // Per sample and head, with W = P * D: dW = dO V^T, dV = W^T dO, dP = dW * D,
    // dS = P * (dP - rowsum(dP * P)), dQ = dS K / sqrt(hd), dK = dS^T Q / sqrt(hd).
    pub(super) fn backward(&self, g: &Array2<f32>, cx: &mut GradCx) {
        let (rows, d) = g.dim();
        let (n, heads) = (self.spec.set_size, self.spec.n_head);
        let dims = Dims {
            n,
            heads,
            hd: d / heads,
            d,
        };
        let scale = (dims.hd as f32).sqrt();
        let (qv, kv, vv) = (cx.value(self.q), cx.value(self.k), cx.value(self.v));
        let (q, k, v) = (
            qv.as_slice().expect(CONTIGUOUS),
            kv.as_slice().expect(CONTIGUOUS),
            vv.as_slice().expect(CONTIGUOUS),
        );
        let probs = cx.value(self.probs).as_slice().expect(CONTIGUOUS);
        let drop = self
            .spec
            .dropout
            .map(|m| cx.value(m).as_slice().expect(CONTIGUOUS));
        let gs = g.as_slice().expect(CONTIGUOUS);
        // Scratch: dQ, dK, dV (the inputs may be one node, so each is handed over at the end)
        // and one row of dS.
        let mut grads = [0, 1, 2].map(|_| cx.pool.zeros(rows, d));
        let mut ds_buf = cx.pool.array(1, n);
        {
            let [dq, dk, dv] = &mut grads;
            let (dq, dk, dv) = (
                dq.as_slice_mut().expect(CONTIGUOUS),
                dk.as_slice_mut().expect(CONTIGUOUS),
                dv.as_slice_mut().expect(CONTIGUOUS),
            );
            let ds = ds_buf.as_slice_mut().expect(CONTIGUOUS);
            for base in (0..rows).step_by(n) {
                for h in 0..heads {
                    for i in 0..n {
                        let row = base + i;
                        let p = &probs[dims.keys(row, h)];
                        let go = &gs[dims.head(row, h)];
                        let mut p_dot_dp = 0.0;
                        for j in 0..n {
                            let m = drop.map_or(1.0, |m| m[dims.keys(row, h)][j]);
                            let vj = dims.head(base + j, h);
                            // dV_j += W_ij dO_i
                            let w = p[j] * m;
                            for (dvv, &o) in dv[vj.clone()].iter_mut().zip(go) {
                                *dvv += w * o;
                            }
                            // dP_ij = (dO_i . V_j) D_ij
                            ds[j] = dot(go, &v[vj]) * m;
                            p_dot_dp += ds[j] * p[j];
                        }
                        let qi = dims.head(row, h);
                        for j in 0..n {
                            let s = p[j] * (ds[j] - p_dot_dp) / scale;
                            let kj = dims.head(base + j, h);
                            for (dqq, &kk) in dq[qi.clone()].iter_mut().zip(&k[kj.clone()]) {
                                *dqq += s * kk;
                            }
                            for (dkk, &qq) in dk[kj].iter_mut().zip(&q[qi.clone()]) {
                                *dkk += s * qq;
                            }
                        }
                    }
                }
            }
        }
        for (var, grad) in [self.q, self.k, self.v].into_iter().zip(&grads) {
            if let Some((dst, mode)) = cx.slot(var) {
                match mode {
                    Mode::Overwrite => dst.assign(grad),
                    Mode::Accumulate => *dst += grad,
                }
            }
        }
        for a in grads {
            cx.pool.give_array(a);
        }
        cx.pool.give_array(ds_buf);
    }
}

#[cfg(test)]
mod tests {
    use super::super::grad_check::{assert_close, grad_check, random_inputs, Inputs};
    use super::*;

    /// Attention from the public elementary ops, one sample and head at a time: the oracle.
    fn unfused(t: &mut Tape, q: Var, k: Var, v: Var, spec: AttentionSpec) -> Var {
        let (rows, d) = t.shape(q);
        let (n, heads) = (spec.set_size, spec.n_head);
        let hd = d / heads;
        let mut samples = Vec::new();
        for base in (0..rows).step_by(n) {
            let idx: Vec<usize> = (base..base + n).collect();
            let (qb, kb, vb) = (
                t.gather_rows(q, &idx),
                t.gather_rows(k, &idx),
                t.gather_rows(v, &idx),
            );
            let mut outs = Vec::new();
            for h in 0..heads {
                let (c0, c1) = (h * hd, (h + 1) * hd);
                let (qh, kh, vh) = (
                    t.slice_cols(qb, c0, c1),
                    t.slice_cols(kb, c0, c1),
                    t.slice_cols(vb, c0, c1),
                );
                let s = t.matmul_nt(qh, kh);
                let mut s = t.scale(s, 1.0 / (hd as f32).sqrt());
                if let Some(m) = spec.mask {
                    let mb = t.gather_rows(m, &idx);
                    s = t.add(s, mb);
                }
                let mut p = t.softmax(s);
                if let Some(m) = spec.dropout {
                    let mb = t.gather_rows(m, &idx);
                    let mh = t.slice_cols(mb, h * n, (h + 1) * n);
                    p = t.mul(p, mh);
                }
                outs.push(t.matmul(p, vh));
            }
            samples.push(t.concat_cols(&outs));
        }
        t.concat_rows(&samples)
    }

    /// A mask with some keys pushed far down, and dropout multipliers of 0 and 1 / 0.9.
    fn mask_and_dropout(rows: usize, n: usize, heads: usize) -> (Array2<f32>, Array2<f32>) {
        let mask = Array2::from_shape_fn((rows, n), |(r, j)| {
            if (r + 2 * j) % 5 == 0 {
                -1e4
            } else {
                0.1 * j as f32
            }
        });
        let drop = Array2::from_shape_fn((rows, heads * n), |(r, c)| {
            if (3 * r + c) % 7 == 0 {
                0.0
            } else {
                1.0 / 0.9
            }
        });
        (mask, drop)
    }

    #[test]
    fn self_attention_matches_finite_differences() {
        // B = 2 samples of n = 3 agents, width 4 in 2 heads.
        grad_check(
            |t, v| t.self_attention(v[0], v[1], v[2], AttentionSpec::new(3, 2)),
            &[(6, 4), (6, 4), (6, 4)],
            Inputs::Any,
        );
    }

    #[test]
    fn self_attention_with_mask_and_dropout_matches_finite_differences() {
        let (mask, drop) = mask_and_dropout(6, 3, 2);
        grad_check(
            move |t, v| {
                let spec = AttentionSpec {
                    mask: Some(t.constant(mask.view())),
                    dropout: Some(t.constant(drop.view())),
                    ..AttentionSpec::new(3, 2)
                };
                t.self_attention(v[0], v[1], v[2], spec)
            },
            &[(6, 4), (6, 4), (6, 4)],
            Inputs::Any,
        );
    }

    #[test]
    fn self_attention_fan_out_matches_finite_differences() {
        // q = k = v = x, and x again as a residual: four contributions to one gradient.
        grad_check(
            |t, v| {
                let y = t.self_attention(v[0], v[0], v[0], AttentionSpec::new(2, 1));
                t.add(y, v[0])
            },
            &[(4, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn fused_attention_equals_its_composition_in_value_and_gradient() {
        // B = 3, n = 4, d = 12 in 3 heads; plain, then masked with dropout.
        let (rows, n, heads, d) = (12, 4, 3, 12);
        let inputs = random_inputs(&[(rows, d), (rows, d), (rows, d)], Inputs::Any, 8);
        let seed = random_inputs(&[(rows, d)], Inputs::Any, 9).remove(0);
        let (mask, drop) = mask_and_dropout(rows, n, heads);
        for masked in [false, true] {
            let run = |fused: bool| {
                let mut t = Tape::new();
                let v: Vec<Var> = inputs.iter().map(|a| t.param(a.view())).collect();
                let mut spec = AttentionSpec::new(n, heads);
                if masked {
                    spec.mask = Some(t.constant(mask.view()));
                    spec.dropout = Some(t.constant(drop.view()));
                }
                let y = if fused {
                    t.self_attention(v[0], v[1], v[2], spec)
                } else {
                    unfused(&mut t, v[0], v[1], v[2], spec)
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
    fn samples_do_not_attend_to_each_other() {
        // Changing sample 1's rows leaves sample 0's outputs exactly as they were.
        let x = random_inputs(&[(4, 2)], Inputs::Any, 1).remove(0);
        let run = |x: &Array2<f32>| {
            let mut t = Tape::new();
            let xv = t.constant(x.view());
            let y = t.self_attention(xv, xv, xv, AttentionSpec::new(2, 2));
            t.value(y).to_owned()
        };
        let mut other = x.clone();
        other.row_mut(3).fill(5.0);
        let (a, b) = (run(&x), run(&other));
        assert_eq!(a.row(0), b.row(0));
        assert_eq!(a.row(1), b.row(1));
        assert_ne!(a.row(2), b.row(2));
    }
}
