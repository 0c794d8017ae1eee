//! GELU as GPT-2 computes it (HuggingFace's `gelu_new`, the tanh approximation), the
//! activation between GPT-2's two MLP layers:
//!
//! ```text
//! u = sqrt(2 / pi) (x + 0.044715 x^3),  t = tanh(u),  y = 0.5 x (1 + t)
//! dy/dx = 0.5 (1 + t) + 0.5 x (1 - t^2) sqrt(2 / pi) (1 + 3 0.044715 x^2)
//! ```
//!
//! One node (the composition is eight); t is kept for the backward. tanh is the engine's
//! vectorized one (`kernels::activations`, within 3.5e-7 of libm's), so far in the left tail,
//! where 1 + t cancels, y and dy/dx are within a few 1e-6 of PyTorch's in absolute terms (both
//! are tiny there), not relative ones.

use ndarray::Array2;

use super::Op;
use crate::autograd::kernels::activations::tanh_inplace;
use crate::autograd::kernels::elementwise::{gelu_argument, gelu_backward, gelu_output};
use crate::autograd::kernels::gemm::Mode;
use crate::autograd::tape::{GradCx, Tape, Var};
/// Elements per block of the forward.
const BLOCK: usize = 512;

impl Tape {
    /// y = 0.5 x (1 + tanh(sqrt(2 / pi) (x + 0.044715 x^3))) elementwise, x, y: [m, n]
    /// (GPT-2's `gelu_new`; see the module docs).
    pub fn gelu_tanh(&mut self, x: Var) -> Var {
        let (m, n) = self.shape(x);
        let mut t = self.pool().array(m, n);
        let mut y = self.pool().array(m, n);
        // In PyTorch's order: x^3, times the coefficient, plus x, times sqrt(2 / pi); then
        // tanh, then y, a block at a time while the block is in cache (every step is
        // elementwise, so blocking changes no number).
        {
            let contiguous = "tape arrays are contiguous";
            let vx = self.value(x);
            let xs = vx.as_slice().expect(contiguous);
            let ts = t.as_slice_mut().expect(contiguous);
            let ys = y.as_slice_mut().expect(contiguous);
            for ((tb, yb), xb) in ts
                .chunks_mut(BLOCK)
                .zip(ys.chunks_mut(BLOCK))
                .zip(xs.chunks(BLOCK))
            {
                gelu_argument(xb, tb);
                tanh_inplace(tb);
                gelu_output(xb, tb, yb);
            }
        }
        let t = self.push_aux(t);
        self.push_op(y, Op::GeluTanh { x, t }, &[x])
    }
}

// dy/dx = 0.5 (1 + t) + 0.5 x (1 - t^2) sqrt(2 / pi) (1 + 3 c x^2)
pub(super) fn gelu_tanh_backward(x: Var, t: Var, g: &Array2<f32>, cx: &mut GradCx) {
    let (vx, vt) = (cx.value(x), cx.value(t));
    if let Some((d, mode)) = cx.slot(x) {
        let contiguous = "tape arrays are contiguous";
        let (gs, xs, ts) = (
            g.as_slice().expect(contiguous),
            vx.as_slice().expect(contiguous),
            vt.as_slice().expect(contiguous),
        );
        let ds = d.as_slice_mut().expect(contiguous);
        gelu_backward(ds, gs, xs, ts, mode == Mode::Accumulate);
    }
}

#[cfg(test)]
mod tests {
    use ndarray::Array2;

    use super::super::grad_check::{assert_close, grad_check, random_inputs, Inputs};
    use super::*;
    use crate::autograd::kernels::elementwise::{GELU_CUBIC, GELU_SQRT_2_OVER_PI};

    #[test]
    fn gelu_tanh_matches_finite_differences() {
        grad_check(|t, v| t.gelu_tanh(v[0]), &[(3, 5)], Inputs::Any);
        // Inputs of size up to 3, where the cubic term matters.
        grad_check(
            |t, v| {
                let x = t.scale(v[0], 3.0);
                t.gelu_tanh(x)
            },
            &[(4, 4)],
            Inputs::Any,
        );
    }

    #[test]
    fn gelu_tanh_fan_out_matches_finite_differences() {
        grad_check(
            |t, v| {
                let y = t.gelu_tanh(v[0]);
                t.mul(y, v[0])
            },
            &[(3, 3)],
            Inputs::Any,
        );
    }

    #[test]
    fn fused_gelu_equals_its_composition_in_value_and_gradient() {
        let x = random_inputs(&[(6, 7)], Inputs::Any, 5).remove(0) * 4.0;
        let seed = random_inputs(&[(6, 7)], Inputs::Any, 6).remove(0);
        let run = |fused: bool| {
            let mut t = Tape::new();
            let xv = t.param(x.view());
            let y = if fused {
                t.gelu_tanh(xv)
            } else {
                let sq = t.square(xv);
                let cube = t.mul(sq, xv);
                let c = t.scale(cube, GELU_CUBIC);
                let inner = t.add(xv, c);
                let u = t.scale(inner, GELU_SQRT_2_OVER_PI);
                let th = t.tanh(u);
                let one = t.constant(Array2::ones(x.dim()).view());
                let opt = t.add(one, th);
                let half = t.scale(xv, 0.5);
                t.mul(half, opt)
            };
            t.backward_with(y, seed.view());
            (t.value(y).to_owned(), t.grad(xv).unwrap().to_owned())
        };
        let (y1, g1) = run(true);
        let (y2, g2) = run(false);
        assert_close(&y1, &y2, 1e-6);
        assert_close(&g1, &g2, 1e-5);
    }

    #[test]
    fn matches_transformers_gelu_new_values_and_gradients() {
        // The "gelu" case of tests/fixtures/acac_nets_torch.json (ACT2FN["gelu_new"] of
        // transformers 4.40.2 on 3 N(0, 1) values, loss sum(y * c)).
        let fixture: serde_json::Value =
            serde_json::from_str(include_str!("../../../tests/fixtures/acac_nets_torch.json"))
                .unwrap();
        let case = &fixture["gelu"];
        let array = |v: &serde_json::Value| {
            let shape: Vec<usize> = serde_json::from_value(v["shape"].clone()).unwrap();
            let data: Vec<f32> = serde_json::from_value(v["data"].clone()).unwrap();
            Array2::from_shape_vec((shape[0], shape[1]), data).unwrap()
        };
        let mut t = Tape::new();
        let x = t.param(array(&case["x"]).view());
        let y = t.gelu_tanh(x);
        t.backward_with(y, array(&case["loss_weights"]).view());
        // Absolute, not relative: in the left tail (x < -4) 1 + t cancels, and there PyTorch's
        // own f32 value is only as good as tanh's last bit (6e-8 of 1 + t ~ 1e-6), ours as the
        // vectorized tanh (3.5e-7): both are a few 1e-6 from the exact tail, which is itself
        // below 1e-5.
        let close = |ours: ndarray::ArrayView2<f32>, want: Array2<f32>| {
            for (a, b) in ours.iter().zip(want.iter()) {
                assert!((a - b).abs() <= 1e-5, "{a} vs {b}");
            }
        };
        close(t.value(y), array(&case["output"]));
        close(t.grad(x).unwrap(), array(&case["grads"]["x"]));
    }

    #[test]
    fn gelu_tanh_is_close_to_the_exact_gelu_and_passes_large_inputs_through() {
        // Known values of 0.5 x (1 + tanh(...)): gelu(1) = 0.8411920, gelu(-1) = -0.1588080.
        let mut t = Tape::new();
        let x = t.constant(ndarray::arr2(&[[1.0f32, -1.0, 0.0, 20.0, -20.0]]).view());
        let y = t.gelu_tanh(x);
        let want = [0.841_192, -0.158_808, 0.0, 20.0, 0.0];
        for (a, b) in t.value(y).iter().zip(want) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }
}
