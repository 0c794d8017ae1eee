//! ACAC's critic after its agents' encoders (`models.py: AgentCentricGRUCritic` with
//! `use_attention`): the GPT-2 encoder over the n agents' encodings of each joint macro-step,
//! the value head's pooling, and the value layer (Linear, or PopArt with `use_popart`):
//!
//! ```text
//! features [B n, d] -> centralized_transformer -> pool (value_head) -> value -> [B, 1]
//! ```
//!
//! Loaded from the critic's `state_dict` by its own names (`centralized_transformer.*`,
//! `value.*`; the encoders' `encoders.<i>.*` and `time_embedding.weight` are other modules'),
//! so a converted checkpoint of the reference's critic feeds it as it is. The GRU encoders and
//! the regrouping of their outputs by joint macro-step belong to the ACAC family.

use std::path::Path;

use ndarray::ArrayViewD;
use serde::{Deserialize, Serialize};

use super::gpt2::{Gpt2, Gpt2Vars};
use super::gpt2_dropout::Gpt2Dropout;
use super::linear::LinearVars;
use super::params::LinearParams;
use super::popart::PopArt;
use super::state_dict::StateDict;
use super::value_head::ValueHead;
use super::WeightsError;
use crate::autograd::{Activation, Tape, Var};

/// The critic's value layer: `Linear` or, with `use_popart`, [`PopArt`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ValueLayer {
    /// A plain linear layer (`weight`, `bias`).
    Linear(LinearParams),
    /// PopArt (`weight`, `bias` and its statistics).
    PopArt(PopArt),
}

impl ValueLayer {
    /// The linear layer both kinds run forward.
    pub fn linear(&self) -> &LinearParams {
        match self {
            ValueLayer::Linear(l) => l,
            ValueLayer::PopArt(p) => &p.linear,
        }
    }

    /// The layer under `prefix`: PopArt if the state_dict holds its `stddev`, else Linear.
    pub fn from_state_dict(sd: &StateDict, prefix: &str) -> Result<Self, WeightsError> {
        if sd.has(&format!("{prefix}stddev")) {
            return Ok(ValueLayer::PopArt(PopArt::from_state_dict(sd, prefix)?));
        }
        Ok(ValueLayer::Linear(sd.linear(prefix)?))
    }

    /// Every tensor under `prefix`, in `state_dict` order.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        match self {
            ValueLayer::Linear(l) => l.named(prefix),
            ValueLayer::PopArt(p) => p.named(prefix),
        }
    }
}

/// The critic from its agents' encodings to the joint value (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcacJointValue {
    /// `centralized_transformer`.
    pub transformer: Gpt2,
    /// `value_head`.
    pub head: ValueHead,
    /// `value`.
    pub value: ValueLayer,
}

impl AcacJointValue {
    /// The modules under `prefix` in a critic's state_dict (`{prefix}centralized_transformer.`,
    /// `{prefix}value.`), with the reference's `value_head` and `cc_n_head`, which the file does
    /// not record. The value layer's input must fit the head: d for `mean_linear` and
    /// `max_linear`, a multiple of d for `concat`. Panics if n_head does not divide d.
    pub fn from_state_dict(
        sd: &StateDict,
        prefix: &str,
        head: ValueHead,
        n_head: usize,
    ) -> Result<Self, WeightsError> {
        let transformer =
            Gpt2::from_state_dict(sd, &format!("{prefix}centralized_transformer."), n_head)?;
        let value_prefix = format!("{prefix}value.");
        let value = ValueLayer::from_state_dict(sd, &value_prefix)?;
        let known: Vec<String> = value
            .named(&value_prefix)
            .into_iter()
            .map(|(n, _)| n)
            .collect();
        sd.check_names_under(&value_prefix, &known, &[], "ACAC value layer")?;
        let (d, input) = (transformer.config().width, value.linear().input());
        let fits = match head {
            ValueHead::Concat => d > 0 && input % d == 0,
            ValueHead::MeanLinear | ValueHead::MaxLinear => input == d,
        };
        if !fits {
            let weight = value.linear().weight.view();
            return Err(WeightsError::Shape {
                path: sd.path().to_path_buf(),
                name: format!("{value_prefix}weight"),
                found: weight.shape().to_vec(),
                expected: vec![weight.nrows(), head.pooled_width(d, 1)],
            });
        }
        Ok(AcacJointValue {
            transformer,
            head,
            value,
        })
    }

    /// [`Self::from_state_dict`] on a safetensors file's bytes holding a critic's state_dict
    /// under its own names (prefix ""); `origin` labels errors.
    pub fn from_safetensors_bytes(
        bytes: &[u8],
        origin: &Path,
        head: ValueHead,
        n_head: usize,
    ) -> Result<Self, WeightsError> {
        Self::from_state_dict(&StateDict::parse(bytes, origin)?, "", head, n_head)
    }

    /// Every tensor under `prefix`, by the critic's names.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        let mut out = self
            .transformer
            .named(&format!("{prefix}centralized_transformer."));
        out.extend(self.value.named(&format!("{prefix}value.")));
        out
    }

    /// Put the trained parameters on a tape.
    pub fn bind(&self, tape: &mut Tape) -> AcacJointValueVars {
        AcacJointValueVars {
            transformer: self.transformer.bind(tape),
            head: self.head,
            value: self.value.linear().bind(tape),
        }
    }
}

/// An [`AcacJointValue`]'s parameters on a tape.
#[derive(Debug, Clone, PartialEq)]
pub struct AcacJointValueVars {
    /// The transformer's.
    pub transformer: Gpt2Vars,
    head: ValueHead,
    /// The value layer's.
    pub value: LinearVars,
}

impl AcacJointValueVars {
    /// The values [B, out] of B joint macro-steps from their n agents' encodings
    /// `features` [B n, d] (ACAC's `feature.reshape(B, n_agent, -1)` row-major); with PopArt
    /// they are normalized values. `dropout` replays or draws the transformer's masks (none:
    /// dropout off).
    pub fn forward(
        &self,
        tape: &mut Tape,
        features: Var,
        n_agents: usize,
        dropout: Option<&Gpt2Dropout>,
    ) -> Var {
        let h = self.transformer.forward(tape, features, n_agents, dropout);
        let pooled = self.head.pool(tape, h, n_agents);
        self.value.forward(tape, pooled, Activation::Identity)
    }

    /// Copy the gradients into `into` (PopArt's statistics are left as they are).
    pub fn grads_into(&self, tape: &Tape, into: &mut AcacJointValue) {
        self.transformer.grads_into(tape, &mut into.transformer);
        match &mut into.value {
            ValueLayer::Linear(l) => self.value.grads_into(tape, l),
            ValueLayer::PopArt(p) => self.value.grads_into(tape, &mut p.linear),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::acac_fixture::{assert_close, Fixture};
    use crate::nn::safetensors_io::named_to_safetensors_bytes;

    #[test]
    fn acacs_default_critic_top_matches_pytorch_from_its_state_dict_names() {
        // critic_top: the critic's transformer, then `self.value(out.mean(dim=1))` (PopArt),
        // loss sum(out * c) + sum(value * c_v).
        let f = Fixture::load();
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        let net =
            AcacJointValue::from_state_dict(&sd, "critic.", ValueHead::MeanLinear, 2).unwrap();
        assert!(matches!(net.value, ValueLayer::PopArt(_)));
        let case = &f.json["critic_top"];
        let mut tape = Tape::new();
        let vars = net.bind(&mut tape);
        let x = tape.param(Fixture::array2(&case["x"]).view());
        // The transformer's output is also in the loss: run the two pieces as forward does.
        let h = vars.transformer.forward(&mut tape, x, 3, None);
        let pooled = net.head.pool(&mut tape, h, 3);
        let value = vars.value.forward(&mut tape, pooled, Activation::Identity);
        let (ch, cv) = (
            tape.constant(Fixture::array2(&case["loss_weights"]).view()),
            tape.constant(Fixture::array2(&case["value_loss_weights"]).view()),
        );
        let (lh, lv) = (tape.mul(h, ch), tape.mul(value, cv));
        let (lh, lv) = (tape.sum(lh), tape.sum(lv));
        let loss = tape.add(lh, lv);
        tape.backward(loss);
        assert_close("output", tape.value(h), &case["output"], 2e-5);
        assert_close("value", tape.value(value), &case["value"], 2e-5);
        assert_close("dx", tape.grad(x).unwrap(), &case["grads"]["x"], 2e-5);
        let mut g = net.clone();
        vars.grads_into(&tape, &mut g);
        for (name, a) in g.named("") {
            let key = name
                .strip_prefix("centralized_transformer.")
                .unwrap_or(&name);
            let want = &case["grads"][key];
            if key == "wpe.weight" {
                let rows = a.into_dimensionality::<ndarray::Ix2>().unwrap();
                assert_close(key, rows.slice(ndarray::s![..3, ..]), want, 2e-5);
            } else if want.is_object() {
                assert_close(key, a, want, 2e-5);
            } else {
                // wte (unused) and PopArt's statistics get no gradient.
                assert!(
                    key == "wte.weight" || !name.starts_with("centralized"),
                    "{name}"
                );
            }
        }
        // forward() is the same composition.
        let mut t2 = Tape::new();
        let v2 = net.bind(&mut t2);
        let x2 = t2.constant(Fixture::array2(&case["x"]).view());
        let y2 = v2.forward(&mut t2, x2, 3, None);
        assert_eq!(t2.value(y2), tape.value(value));
    }

    #[test]
    fn a_value_layer_that_does_not_fit_the_head_is_an_error() {
        let f = Fixture::load();
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        // The concat critic's value layer takes 3 d: not a mean_linear layer.
        let transformer = Gpt2::from_state_dict(&sd, "critic.centralized_transformer.", 2).unwrap();
        let mut named = transformer.named("centralized_transformer.");
        let concat = ValueLayer::from_state_dict(&sd, "concat.value.").unwrap();
        named.extend(concat.named("value."));
        let bytes = named_to_safetensors_bytes(&named);
        let err = AcacJointValue::from_safetensors_bytes(
            &bytes,
            Path::new("c"),
            ValueHead::MeanLinear,
            2,
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("value.weight") && err.contains("[1, 24]"),
            "{err}"
        );
        let ok =
            AcacJointValue::from_safetensors_bytes(&bytes, Path::new("c"), ValueHead::Concat, 2)
                .unwrap();
        assert!(matches!(ok.value, ValueLayer::Linear(_)));
        assert_eq!(named_to_safetensors_bytes(&ok.named("")), bytes);
    }
}
