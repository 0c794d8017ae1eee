//! PopArt, the value layer of ACAC's critic with `use_popart` (ACAC's `popart.py`, itself MAPPO's
//! `onpolicy/algorithms/utils/popart.py`): a linear layer that predicts normalized returns,
//! plus running statistics of the returns. `learner_acac.py` calls [`PopArt::update`] with each
//! batch's returns before the critic loss and regresses on [`PopArt::normalize`]d returns, and
//! [`PopArt::denormalize`]s the target critic's values for GAE. An update rescales the layer so
//! its denormalized outputs stay what they were ("preserving outputs precisely").
//!
//! ```text
//! update(G):  m <- beta m + (1 - beta) mean(G),  m2 <- beta m2 + (1 - beta) mean(G^2),
//!             c <- beta c + (1 - beta)                      (debiasing term; beta = 0.99999)
//!             mu = m / max(c, eps),  var = max(m2 / max(c, eps) - mu^2, 1e-2)   (eps = 1e-5)
//!             W <- W sigma_old / sigma_new,  b <- (b sigma_old + mu_old - mu_new) / sigma_new
//! normalize(G) = (G - mu) / sqrt(var),  denormalize(v) = v sqrt(var) + mu
//! ```
//!
//! Arithmetic is f32 in the reference's order (beta and 1 - beta are Python floats rounded to
//! f32, as PyTorch uses them). Tensors by the reference's names under the layer's prefix
//! (`value.` in the critic): `weight` [out, in], `bias`, `stddev`, `mean`, `mean_sq` \[out\],
//! `debiasing_term` [] (a scalar).

use ndarray::{Array1, Array2, ArrayView2, ArrayViewD, Axis};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::init::{uniform1, uniform2};
use super::linear::LinearVars;
use super::params::{flat, flat_mut, LinearParams, Params};
use super::state_dict::StateDict;
use super::WeightsError;
use crate::autograd::Tape;

/// The reference's decay of the running statistics.
pub const POPART_BETA: f64 = 0.99999;
/// The reference's floor on the debiasing term.
pub const POPART_EPSILON: f64 = 1e-5;

/// A PopArt value layer and its return statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PopArt {
    /// The layer (trained by the optimizer; the statistics are not).
    pub linear: LinearParams,
    /// sqrt(m2 - m^2) floored at 1e-4 (not debiased), \[out\]: kept as the reference keeps it.
    pub stddev: Array1<f32>,
    /// m, the running mean of the returns, \[out\].
    pub mean: Array1<f32>,
    /// m2, the running mean of their squares, \[out\].
    pub mean_sq: Array1<f32>,
    /// c, the sum of the weights given to the batches so far.
    pub debiasing_term: f32,
    /// Decay of the statistics.
    pub beta: f64,
    /// Floor on c in the debiased statistics.
    pub epsilon: f64,
}

impl PopArt {
    /// The reference's initialization (`reset_parameters`): weight and bias
    /// U(-1/sqrt(in), 1/sqrt(in)) (kaiming_uniform with a = sqrt(5)), zero statistics, stddev 1.
    pub fn new(input: usize, output: usize, rng: &mut ChaCha8Rng) -> Self {
        let bound = 1.0 / (input as f32).sqrt();
        let linear = LinearParams {
            weight: uniform2(output, input, bound, rng),
            bias: uniform1(output, bound, rng),
        };
        Self::with_layer(linear)
    }

    /// `linear` with fresh statistics and the reference's beta and epsilon.
    pub fn with_layer(linear: LinearParams) -> Self {
        let out = linear.output();
        PopArt {
            linear,
            stddev: Array1::ones(out),
            mean: Array1::zeros(out),
            mean_sq: Array1::zeros(out),
            debiasing_term: 0.0,
            beta: POPART_BETA,
            epsilon: POPART_EPSILON,
        }
    }

    /// The layer under `prefix` in a state_dict (`weight` [out, in] and the statistics), with
    /// the reference's beta and epsilon.
    pub fn from_state_dict(sd: &StateDict, prefix: &str) -> Result<Self, WeightsError> {
        let name = |n: &str| format!("{prefix}{n}");
        let (out, input) = sd.shape2(&name("weight"))?;
        let linear = LinearParams {
            weight: sd.array2(&name("weight"), out, input)?,
            bias: sd.array1(&name("bias"), out)?,
        };
        Ok(PopArt {
            stddev: sd.array1(&name("stddev"), out)?,
            mean: sd.array1(&name("mean"), out)?,
            mean_sq: sd.array1(&name("mean_sq"), out)?,
            debiasing_term: sd.scalar(&name("debiasing_term"))?,
            ..Self::with_layer(linear)
        })
    }

    /// Every tensor under `prefix`, in `state_dict` order.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        vec![
            (
                format!("{prefix}weight"),
                self.linear.weight.view().into_dyn(),
            ),
            (format!("{prefix}bias"), self.linear.bias.view().into_dyn()),
            (format!("{prefix}stddev"), self.stddev.view().into_dyn()),
            (format!("{prefix}mean"), self.mean.view().into_dyn()),
            (format!("{prefix}mean_sq"), self.mean_sq.view().into_dyn()),
            (
                format!("{prefix}debiasing_term"),
                ArrayViewD::from_shape(
                    ndarray::IxDyn(&[]),
                    std::slice::from_ref(&self.debiasing_term),
                )
                .expect("one value is a scalar"),
            ),
        ]
    }

    /// The layer on a tape (its forward is the plain linear layer, `F.linear`).
    pub fn bind(&self, tape: &mut Tape) -> LinearVars {
        self.linear.bind(tape)
    }

    /// (mu, var) per output: the debiased mean and variance (see the module docs).
    pub fn debiased_mean_var(&self) -> (Array1<f32>, Array1<f32>) {
        let c = self.debiasing_term.max(self.epsilon as f32);
        let mean = self.mean.mapv(|m| m / c);
        let var = ndarray::Zip::from(&self.mean_sq)
            .and(&mean)
            .map_collect(|&m2, &mu| (m2 / c - mu * mu).max(1e-2));
        (mean, var)
    }

    /// Fold a batch of returns [N, out] into the statistics and rescale the layer so its
    /// denormalized outputs are unchanged (the reference's `update`, under `no_grad`). Panics
    /// if the width differs from the layer's outputs.
    pub fn update(&mut self, returns: ArrayView2<f32>) {
        let out = self.linear.output();
        assert_eq!(returns.ncols(), out, "popart update: returns width");
        let (old_mean, old_var) = self.debiased_mean_var();
        let old_std = old_var.mapv(f32::sqrt);
        let n = returns.nrows() as f32;
        let batch_mean = returns.sum_axis(Axis(0)).mapv(|s| s / n);
        let batch_sq_mean = returns.mapv(|g| g * g).sum_axis(Axis(0)).mapv(|s| s / n);
        let (beta, rest) = (self.beta as f32, (1.0 - self.beta) as f32);
        ndarray::Zip::from(&mut self.mean)
            .and(&batch_mean)
            .for_each(|m, &b| *m = *m * beta + b * rest);
        ndarray::Zip::from(&mut self.mean_sq)
            .and(&batch_sq_mean)
            .for_each(|m, &b| *m = *m * beta + b * rest);
        self.debiasing_term = self.debiasing_term * beta + rest;
        self.stddev = ndarray::Zip::from(&self.mean_sq)
            .and(&self.mean)
            .map_collect(|&m2, &m| clamp_min((m2 - m * m).sqrt(), 1e-4));
        let (new_mean, new_var) = self.debiased_mean_var();
        let new_std = new_var.mapv(f32::sqrt);
        for (o, mut row) in self.linear.weight.rows_mut().into_iter().enumerate() {
            let ratio = old_std[o] / new_std[o];
            row.mapv_inplace(|w| w * ratio);
            let b = &mut self.linear.bias[o];
            *b = (*b * old_std[o] + (old_mean[o] - new_mean[o])) * (1.0 / new_std[o]);
        }
    }

    /// (G - mu) / sqrt(var) for returns G: [N, out] (the critic's regression targets).
    pub fn normalize(&self, returns: ArrayView2<f32>) -> Array2<f32> {
        let (mean, var) = self.debiased_mean_var();
        let mut out = returns.to_owned();
        for mut row in out.rows_mut() {
            for (o, g) in row.iter_mut().enumerate() {
                *g = (*g - mean[o]) / var[o].sqrt();
            }
        }
        out
    }

    /// v sqrt(var) + mu for normalized values v: [N, out] (the critic's values as returns).
    pub fn denormalize(&self, values: ArrayView2<f32>) -> Array2<f32> {
        let (mean, var) = self.debiased_mean_var();
        let mut out = values.to_owned();
        for mut row in out.rows_mut() {
            for (o, v) in row.iter_mut().enumerate() {
                *v = *v * var[o].sqrt() + mean[o];
            }
        }
        out
    }
}

/// PyTorch's `clamp(min=lo)`: NaN stays NaN (f32::max would turn it into lo).
fn clamp_min(v: f32, lo: f32) -> f32 {
    if v < lo {
        lo
    } else {
        v
    }
}

impl Params for PopArt {
    /// The trained tensors only (weight, bias): the statistics change by [`PopArt::update`].
    fn slices(&self) -> Vec<&[f32]> {
        vec![flat(&self.linear.weight), flat(&self.linear.bias)]
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        vec![
            flat_mut(&mut self.linear.weight),
            flat_mut(&mut self.linear.bias),
        ]
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::autograd::Activation;
    use crate::nn::acac_fixture::{assert_close, Fixture};

    fn assert_state(p: &PopArt, want: &serde_json::Value, tol: f32) {
        assert_close("weight", p.linear.weight.view(), &want["weight"], tol);
        assert_close("bias", p.linear.bias.view(), &want["bias"], tol);
        assert_close("stddev", p.stddev.view(), &want["stddev"], tol);
        assert_close("mean", p.mean.view(), &want["mean"], tol);
        assert_close("mean_sq", p.mean_sq.view(), &want["mean_sq"], tol);
        let c = ndarray::arr0(p.debiasing_term);
        assert_close("debiasing_term", c.view(), &want["debiasing_term"], tol);
    }

    #[test]
    fn updates_normalizes_and_denormalizes_as_acacs_popart() {
        // The critic's `value` (PopArt(8, 1)) through two updates, from
        // tests/fixtures/acac_nets_torch.*.
        let f = Fixture::load();
        let case = &f.json["popart"];
        assert_eq!(case["beta"].as_f64().unwrap(), POPART_BETA);
        assert_eq!(case["epsilon"].as_f64().unwrap(), POPART_EPSILON);
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        let mut p = PopArt::from_state_dict(&sd, "critic.value.").unwrap();
        assert_state(&p, &case["before"], 0.0);
        let x = Fixture::array2(&case["x"]);
        let forward = |p: &PopArt| {
            let mut tape = Tape::new();
            let v = p.bind(&mut tape);
            let xv = tape.constant(x.view());
            let y = v.forward(&mut tape, xv, Activation::Identity);
            p.denormalize(tape.value(y))
        };
        for step in case["steps"].as_array().unwrap() {
            let before = forward(&p);
            assert_close(
                "output before",
                before.view(),
                &step["denormalized_output_before"],
                1e-5,
            );
            let g = Fixture::array2(&step["returns"]);
            p.update(g.view());
            assert_state(&p, &step["after"], 1e-5);
            assert_close(
                "normalize",
                p.normalize(g.view()).view(),
                &step["normalized"],
                1e-5,
            );
            let v = Fixture::array2(&step["values"]);
            assert_close(
                "denormalize",
                p.denormalize(v.view()).view(),
                &step["denormalized"],
                1e-5,
            );
            // Outputs preserved: the denormalized output is what it was before the update.
            let after = forward(&p);
            assert_close(
                "output after",
                after.view(),
                &step["denormalized_output_after"],
                1e-5,
            );
            for (a, b) in after.iter().zip(before.iter()) {
                assert!((a - b).abs() <= 1e-4 * (1.0 + b.abs()), "{a} vs {b}");
            }
        }
    }

    #[test]
    fn names_round_trip_with_a_scalar_debiasing_term() {
        let mut rng = <ChaCha8Rng as rand::SeedableRng>::seed_from_u64(2);
        let mut p = PopArt::new(4, 2, &mut rng);
        p.update(ndarray::arr2(&[[1.0f32, 2.0], [3.0, -1.0]]).view());
        let named = p.named("value.");
        assert_eq!(named[5].1.shape(), &[] as &[usize]);
        let bytes = crate::nn::safetensors_io::named_to_safetensors_bytes(&named);
        let sd = StateDict::parse(&bytes, Path::new("f")).unwrap();
        assert_eq!(PopArt::from_state_dict(&sd, "value.").unwrap(), p);
    }
}
