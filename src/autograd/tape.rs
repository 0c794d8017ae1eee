//! The tape: an arena of nodes addressed by `Copy` ids ([`Var`]), recorded during the forward
//! pass and replayed in reverse by [`Tape::backward`].
//!
//! Every value is a 2-D `f32` array (a vector is one row, a scalar is [1, 1]), which is all the
//! Q-nets and their losses need. Gradients accumulate with `+=` into one buffer per node.
//! [`Tape::reset`] returns every buffer to the tape's [`Pool`], so an update loop that resets the
//! tape after each step reuses the same memory forever (nothing is left between updates).

use ndarray::{Array2, ArrayView2};

use super::kernels::gemm::Mode;
use super::ops::Op;
use super::pool::Pool;

/// A node on a [`Tape`]: cheap to copy, valid until the tape's next [`Tape::reset`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Var {
    index: u32,
    generation: u32,
}

/// Arena of recorded operations (see the module docs).
#[derive(Debug, Default)]
pub struct Tape {
    values: Vec<Array2<f32>>,
    grads: Vec<Option<Array2<f32>>>,
    ops: Vec<Op>,
    needs_grad: Vec<bool>,
    pool: Pool,
    generation: u32,
}

impl Tape {
    /// An empty tape.
    pub fn new() -> Self {
        Self::default()
    }

    /// Forget every node and recycle its buffers. Vars from before are invalid afterwards
    /// (using one panics).
    pub fn reset(&mut self) {
        for v in self.values.drain(..) {
            self.pool.give_array(v);
        }
        for g in self.grads.drain(..).flatten() {
            self.pool.give_array(g);
        }
        self.ops.clear();
        self.needs_grad.clear();
        self.generation = self.generation.wrapping_add(1);
    }

    /// Number of nodes recorded since the last reset.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Whether no node has been recorded since the last reset.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Memory the tape keeps between updates: (node slots, floats in recycled buffers). Bounded
    /// when the same computation repeats (tested over 100k updates).
    pub fn retained(&self) -> (usize, usize) {
        (self.values.capacity(), self.pool.floats_held())
    }

    /// A trainable leaf: gradients flow into it. Copies `value` into a recycled buffer.
    pub fn param(&mut self, value: ArrayView2<f32>) -> Var {
        let mut a = self.pool.array(value.nrows(), value.ncols());
        copy_into(&mut a, value);
        self.push(a, Op::Leaf, true)
    }

    /// A constant leaf (inputs, targets, masks): no gradient is computed for it.
    pub fn constant(&mut self, value: ArrayView2<f32>) -> Var {
        let mut a = self.pool.array(value.nrows(), value.ncols());
        copy_into(&mut a, value);
        self.push(a, Op::Leaf, false)
    }

    /// A constant leaf taking ownership of `value` (no copy).
    pub fn constant_owned(&mut self, value: Array2<f32>) -> Var {
        self.push(value, Op::Leaf, false)
    }

    /// The forward value of `v`.
    pub fn value(&self, v: Var) -> ArrayView2<'_, f32> {
        self.values[self.index(v)].view()
    }

    /// Shape [rows, cols] of `v`.
    pub fn shape(&self, v: Var) -> (usize, usize) {
        self.values[self.index(v)].dim()
    }

    /// The scalar value of a [1, 1] node. Panics otherwise.
    pub fn scalar(&self, v: Var) -> f32 {
        let a = &self.values[self.index(v)];
        assert_eq!(a.dim(), (1, 1), "scalar() on a node of shape {:?}", a.dim());
        a[[0, 0]]
    }

    /// d(output)/dv after the last [`Tape::backward`]; `None` if no gradient reached `v`
    /// (it does not influence the output, or it is a constant), which means zero.
    pub fn grad(&self, v: Var) -> Option<ArrayView2<'_, f32>> {
        self.grads[self.index(v)].as_ref().map(|g| g.view())
    }

    /// Reverse pass from a scalar loss ([1, 1]). Gradients of an earlier backward are discarded
    /// first. Panics if `loss` is not [1, 1].
    pub fn backward(&mut self, loss: Var) {
        let shape = self.shape(loss);
        assert_eq!(
            shape,
            (1, 1),
            "backward() needs a scalar loss, got shape {shape:?}"
        );
        let one = ndarray::arr2(&[[1.0f32]]);
        self.backward_with(loss, one.view());
    }

    /// Reverse pass from any node, seeded with d(something)/d(output) = `seed` (a
    /// vector-Jacobian product). Panics if `seed`'s shape differs from the output's.
    pub fn backward_with(&mut self, output: Var, seed: ArrayView2<f32>) {
        let out = self.index(output);
        assert_eq!(
            seed.dim(),
            self.values[out].dim(),
            "backward_with: seed shape"
        );
        for g in self.grads.iter_mut() {
            if let Some(g) = g.take() {
                self.pool.give_array(g);
            }
        }
        if !self.needs_grad[out] {
            return;
        }
        let mut s = self.pool.array(seed.nrows(), seed.ncols());
        s.assign(&seed);
        self.grads[out] = Some(s);

        let Tape {
            values,
            grads,
            ops,
            needs_grad,
            pool,
            generation,
        } = self;
        for i in (0..=out).rev() {
            if !needs_grad[i] {
                continue;
            }
            let Some(g) = grads[i].take() else { continue };
            // An op's inputs always precede it, so handing it the grads before `i` suffices.
            let mut cx = GradCx {
                values,
                grads: &mut grads[..i],
                needs_grad,
                pool,
                generation: *generation,
            };
            ops[i].backward(&values[i], &g, &mut cx);
            grads[i] = Some(g);
        }
    }

    /// Buffer pool for an op's outputs and caches.
    pub(crate) fn pool(&mut self) -> &mut Pool {
        &mut self.pool
    }

    /// Whether gradients must flow into any of `vars`.
    pub(crate) fn any_needs_grad(&self, vars: &[Var]) -> bool {
        vars.iter().any(|&v| self.needs_grad[self.index(v)])
    }

    /// Record a node.
    pub(crate) fn push(&mut self, value: Array2<f32>, op: Op, needs_grad: bool) -> Var {
        let index = u32::try_from(self.values.len()).expect("more than 2^32 nodes on one tape");
        self.values.push(value);
        self.grads.push(None);
        self.ops.push(op);
        self.needs_grad.push(needs_grad);
        Var {
            index,
            generation: self.generation,
        }
    }

    /// Record a forward value computed from `inputs` by `op`.
    pub(crate) fn push_op(&mut self, value: Array2<f32>, op: Op, inputs: &[Var]) -> Var {
        let needs = self.any_needs_grad(inputs);
        self.push(value, op, needs)
    }

    /// A cache another op keeps for its backward (never differentiated itself).
    pub(crate) fn push_aux(&mut self, value: Array2<f32>) -> Var {
        self.push(value, Op::Leaf, false)
    }

    pub(crate) fn index(&self, v: Var) -> usize {
        assert_eq!(
            v.generation, self.generation,
            "Var used after Tape::reset (it belongs to an earlier update)"
        );
        v.index as usize
    }
}

/// dst = src for a pool array of src's shape: one memcpy when src is contiguous in row-major
/// order, else element by element.
fn copy_into(dst: &mut Array2<f32>, src: ArrayView2<f32>) {
    match (src.as_slice(), dst.as_slice_mut()) {
        (Some(s), Some(d)) => d.copy_from_slice(s),
        _ => dst.assign(&src),
    }
}

/// What an op's backward sees: every forward value, and the gradient slots of the nodes before it.
pub(crate) struct GradCx<'a> {
    pub values: &'a [Array2<f32>],
    grads: &'a mut [Option<Array2<f32>>],
    needs_grad: &'a [bool],
    pub pool: &'a mut Pool,
    generation: u32,
}

impl<'a> GradCx<'a> {
    /// Forward value of an input.
    pub fn value(&self, v: Var) -> &'a Array2<f32> {
        &self.values[self.idx(v)]
    }

    /// Whether a gradient must be computed for `v`.
    pub fn wants(&self, v: Var) -> bool {
        self.needs_grad[self.idx(v)]
    }

    /// The gradient buffer of `v` and how to write into it: `Overwrite` on the first contribution
    /// (the buffer holds garbage), `Accumulate` afterwards. `None` if `v` needs no gradient.
    pub fn slot(&mut self, v: Var) -> Option<(&mut Array2<f32>, Mode)> {
        let i = self.idx(v);
        if !self.needs_grad[i] {
            return None;
        }
        let mode = if self.grads[i].is_some() {
            Mode::Accumulate
        } else {
            let (r, c) = self.values[i].dim();
            self.grads[i] = Some(self.pool.array(r, c));
            Mode::Overwrite
        };
        self.grads[i].as_mut().map(|g| (g, mode))
    }

    fn idx(&self, v: Var) -> usize {
        debug_assert_eq!(v.generation, self.generation);
        v.index as usize
    }
}
