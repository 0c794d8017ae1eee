//! PyTorch's `nn.LayerNorm(d)` as a layer: GPT-2's `ln_1`, `ln_2`, `ln_f` and ACAC's actor
//! `ln` (after fc3, `use_actor_ln`). The arithmetic is the tape's `layer_norm` op; this file
//! holds the parameters, their state_dict names (`weight`, `bias` under the module's prefix) and
//! the binding to a tape.

use ndarray::{Array1, ArrayViewD, Axis};
use serde::{Deserialize, Serialize};

use super::params::{copy_grad, flat, flat_mut, Params};
use super::state_dict::StateDict;
use super::WeightsError;
use crate::autograd::{Tape, Var};

/// PyTorch's default eps, which GPT-2 (`layer_norm_epsilon`) and ACAC's actor use.
pub const LAYER_NORM_EPS: f32 = 1e-5;

/// A layer norm's parameters: gain `weight` \[d\], `bias` \[d\], and eps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayerNormParams {
    /// The gain \[d\] (PyTorch's `weight`).
    pub weight: Array1<f32>,
    /// \[d\].
    pub bias: Array1<f32>,
    /// Added to the variance before the square root.
    pub eps: f32,
}

impl LayerNormParams {
    /// PyTorch's initialization: gain 1, bias 0.
    pub fn new(width: usize, eps: f32) -> Self {
        LayerNormParams {
            weight: Array1::ones(width),
            bias: Array1::zeros(width),
            eps,
        }
    }

    /// All-zero tensors (a gradient buffer).
    pub fn zeros(width: usize, eps: f32) -> Self {
        LayerNormParams {
            weight: Array1::zeros(width),
            bias: Array1::zeros(width),
            eps,
        }
    }

    /// d, the normalized width.
    pub fn width(&self) -> usize {
        self.weight.len()
    }

    /// The tensors under `prefix` (e.g. `h.0.ln_1.`): `weight`, `bias`.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        vec![
            (format!("{prefix}weight"), self.weight.view().into_dyn()),
            (format!("{prefix}bias"), self.bias.view().into_dyn()),
        ]
    }

    /// The layer under `prefix` in a state_dict, of width `width`.
    pub fn from_state_dict(
        sd: &StateDict,
        prefix: &str,
        width: usize,
        eps: f32,
    ) -> Result<Self, WeightsError> {
        Ok(LayerNormParams {
            weight: sd.array1(&format!("{prefix}weight"), width)?,
            bias: sd.array1(&format!("{prefix}bias"), width)?,
            eps,
        })
    }

    /// Put the parameters on a tape as trainable [1, d] rows.
    pub fn bind(&self, tape: &mut Tape) -> LayerNormVars {
        LayerNormVars {
            weight: tape.param(self.weight.view().insert_axis(Axis(0))),
            bias: tape.param(self.bias.view().insert_axis(Axis(0))),
            eps: self.eps,
        }
    }
}

/// A layer norm's parameters on a tape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LayerNormVars {
    /// The gain [1, d].
    pub weight: Var,
    /// The bias [1, d].
    pub bias: Var,
    /// eps.
    pub eps: f32,
}

impl LayerNormVars {
    /// Each row of x: [m, d] normalized, scaled and shifted.
    pub fn forward(&self, tape: &mut Tape, x: Var) -> Var {
        tape.layer_norm(x, self.weight, self.bias, self.eps)
    }

    /// Copy the gradients into `into` (zero where none reached a tensor).
    pub fn grads_into(&self, tape: &Tape, into: &mut LayerNormParams) {
        copy_grad(tape, self.weight, flat_mut(&mut into.weight));
        copy_grad(tape, self.bias, flat_mut(&mut into.bias));
    }
}

impl Params for LayerNormParams {
    fn slices(&self) -> Vec<&[f32]> {
        vec![flat(&self.weight), flat(&self.bias)]
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        vec![flat_mut(&mut self.weight), flat_mut(&mut self.bias)]
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::nn::acac_fixture::{assert_close, Fixture};

    #[test]
    fn matches_pytorch_layer_norm_values_and_gradients() {
        // ACAC's actor `ln` (nn.LayerNorm(8)) from tests/fixtures/acac_nets_torch.*.
        let f = Fixture::load();
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        let case = &f.json["layer_norm"];
        let eps = case["eps"].as_f64().unwrap() as f32;
        assert_eq!(eps, LAYER_NORM_EPS);
        let p = LayerNormParams::from_state_dict(&sd, "actor.ln.", 8, eps).unwrap();
        let mut tape = Tape::new();
        let v = p.bind(&mut tape);
        let x = tape.param(Fixture::array2(&case["x"]).view());
        let y = v.forward(&mut tape, x);
        tape.backward_with(y, Fixture::array2(&case["loss_weights"]).view());
        assert_close("y", tape.value(y), &case["output"], 1e-5);
        let mut g = LayerNormParams::zeros(8, eps);
        v.grads_into(&tape, &mut g);
        assert_close("dweight", g.weight.view(), &case["grads"]["weight"], 1e-5);
        assert_close("dbias", g.bias.view(), &case["grads"]["bias"], 1e-5);
        assert_close("dx", tape.grad(x).unwrap(), &case["grads"]["x"], 1e-5);
    }
}
