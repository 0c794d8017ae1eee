//! GPT-2's `Conv1D` (HuggingFace `pytorch_utils.Conv1D`): a fully connected layer whose weight
//! is stored [in, out], transposed against `nn.Linear`'s [out, in], so y = x W + b. Kept in that
//! layout (not transposed on load) so its tensors, gradients and Adam moments line up with the
//! reference's `state_dict` entry by entry.

use ndarray::{Array1, Array2, ArrayViewD, Axis};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use super::params::{copy_grad, flat, flat_mut, Params};
use super::state_dict::StateDict;
use super::WeightsError;
use crate::autograd::{Tape, Var};

/// A `Conv1D` layer's parameters: weight [in, out], bias \[out\].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Conv1dParams {
    /// [in, out].
    pub weight: Array2<f32>,
    /// \[out\].
    pub bias: Array1<f32>,
}

impl Conv1dParams {
    /// All-zero parameters (a gradient buffer).
    pub fn zeros(input: usize, output: usize) -> Self {
        Conv1dParams {
            weight: Array2::zeros((input, output)),
            bias: Array1::zeros(output),
        }
    }

    /// GPT-2's initialization (`_init_weights`): weight N(0, std^2), bias 0.
    pub fn normal(input: usize, output: usize, std: f32, rng: &mut ChaCha8Rng) -> Self {
        let d = Normal::new(0.0, std).expect("std is finite and >= 0");
        Conv1dParams {
            weight: Array2::from_shape_simple_fn((input, output), || d.sample(rng)),
            bias: Array1::zeros(output),
        }
    }

    /// Input size.
    pub fn input(&self) -> usize {
        self.weight.nrows()
    }

    /// Output size.
    pub fn output(&self) -> usize {
        self.weight.ncols()
    }

    /// The tensors under `prefix` (e.g. `h.0.attn.c_attn.`): `weight` [in, out], `bias`.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        vec![
            (format!("{prefix}weight"), self.weight.view().into_dyn()),
            (format!("{prefix}bias"), self.bias.view().into_dyn()),
        ]
    }

    /// The layer under `prefix` in a state_dict, from `input` to `output` features.
    pub fn from_state_dict(
        sd: &StateDict,
        prefix: &str,
        input: usize,
        output: usize,
    ) -> Result<Self, WeightsError> {
        Ok(Conv1dParams {
            weight: sd.array2(&format!("{prefix}weight"), input, output)?,
            bias: sd.array1(&format!("{prefix}bias"), output)?,
        })
    }

    /// Put the parameters on a tape as trainable leaves (bias as a [1, out] row).
    pub fn bind(&self, tape: &mut Tape) -> Conv1dVars {
        Conv1dVars {
            weight: tape.param(self.weight.view()),
            bias: tape.param(self.bias.view().insert_axis(Axis(0))),
        }
    }
}

/// A `Conv1D` layer's parameters on a tape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Conv1dVars {
    /// [in, out].
    pub weight: Var,
    /// [1, out].
    pub bias: Var,
}

impl Conv1dVars {
    /// y = x W + b for x: [rows, in].
    pub fn forward(&self, tape: &mut Tape, x: Var) -> Var {
        tape.matmul_bias(x, self.weight, self.bias)
    }

    /// Copy the gradients into `into` (zero where none reached a tensor).
    pub fn grads_into(&self, tape: &Tape, into: &mut Conv1dParams) {
        copy_grad(tape, self.weight, flat_mut(&mut into.weight));
        copy_grad(tape, self.bias, flat_mut(&mut into.bias));
    }
}

impl Params for Conv1dParams {
    fn slices(&self) -> Vec<&[f32]> {
        vec![flat(&self.weight), flat(&self.bias)]
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        vec![flat_mut(&mut self.weight), flat_mut(&mut self.bias)]
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn the_weight_is_in_by_out_and_multiplies_from_the_right() {
        // x [1, 2] times W [2, 3]: [1, 2] [[1, 2, 3], [4, 5, 6]] + b = [9, 12, 15] + b.
        let p = Conv1dParams {
            weight: ndarray::arr2(&[[1.0f32, 2.0, 3.0], [4.0, 5.0, 6.0]]),
            bias: ndarray::arr1(&[0.5f32, 0.0, -0.5]),
        };
        assert_eq!((p.input(), p.output()), (2, 3));
        let mut tape = Tape::new();
        let v = p.bind(&mut tape);
        let x = tape.constant(ndarray::arr2(&[[1.0f32, 2.0]]).view());
        let y = v.forward(&mut tape, x);
        assert_eq!(tape.value(y), ndarray::arr2(&[[9.5f32, 12.0, 14.5]]));
    }

    #[test]
    fn normal_init_has_the_asked_spread_and_zero_bias() {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let p = Conv1dParams::normal(64, 96, 0.02, &mut rng);
        let var = p.weight.iter().map(|v| v * v).sum::<f32>() / p.weight.len() as f32;
        assert!((var.sqrt() / 0.02 - 1.0).abs() < 0.05, "std {}", var.sqrt());
        assert!(p.bias.iter().all(|&b| b == 0.0));
    }
}
