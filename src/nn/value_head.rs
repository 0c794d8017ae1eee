//! How ACAC's critic turns its transformer's per-agent outputs into one value per joint
//! macro-step (`models.py: AgentCentricGRUCritic.forward`, `value_head`): the agents' rows of each
//! sample are pooled, then a value layer (`value`, a Linear or [`PopArt`](super::PopArt)) maps
//! the pooled row to the value.
//!
//! | `value_head` | pooled row of a sample | value layer input |
//! | --- | --- | --- |
//! | `concat` | the n agent rows side by side | n d |
//! | `mean_linear` (ACAC's default) | their mean | d |
//! | `max_linear` | their elementwise maximum | d |
//!
//! The reference also names `share_linear_add`, `add_linear` and `min_linear`, which no
//! published setting uses; they are not offered.

use serde::{Deserialize, Serialize};

use crate::autograd::{Tape, Var};

/// A value head of ACAC's critic (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ValueHead {
    /// The agents' rows side by side.
    Concat,
    /// The mean over agents.
    MeanLinear,
    /// The elementwise maximum over agents.
    MaxLinear,
}

/// A `value_head` name this code does not offer.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("value head `{0}` is not offered; expected concat, mean_linear or max_linear")]
pub struct UnknownValueHead(pub String);

impl ValueHead {
    /// The head the reference's `value_head` string names.
    pub fn from_reference_name(name: &str) -> Result<Self, UnknownValueHead> {
        match name {
            "concat" => Ok(ValueHead::Concat),
            "mean_linear" => Ok(ValueHead::MeanLinear),
            "max_linear" => Ok(ValueHead::MaxLinear),
            other => Err(UnknownValueHead(other.to_string())),
        }
    }

    /// The reference's name.
    pub fn reference_name(self) -> &'static str {
        match self {
            ValueHead::Concat => "concat",
            ValueHead::MeanLinear => "mean_linear",
            ValueHead::MaxLinear => "max_linear",
        }
    }

    /// The value layer's input width for agents' rows of width d and n agents.
    pub fn pooled_width(self, width: usize, n_agents: usize) -> usize {
        match self {
            ValueHead::Concat => n_agents * width,
            ValueHead::MeanLinear | ValueHead::MaxLinear => width,
        }
    }

    /// The pooled rows: h: [B n, d] (B samples of n agents, sample by sample) -> [B,
    /// [`pooled_width`](Self::pooled_width)]. Panics if n does not divide the rows.
    pub fn pool(self, tape: &mut Tape, h: Var, n_agents: usize) -> Var {
        let (rows, d) = tape.shape(h);
        match self {
            ValueHead::Concat => {
                assert!(
                    n_agents > 0 && rows % n_agents == 0,
                    "concat head: {rows} rows are not sets of {n_agents}"
                );
                tape.reshape(h, rows / n_agents, n_agents * d)
            }
            ValueHead::MeanLinear => tape.row_group_mean(h, n_agents),
            ValueHead::MaxLinear => tape.row_group_max(h, n_agents),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::autograd::Activation;
    use crate::nn::acac_fixture::{assert_close, Fixture};
    use crate::nn::params::LinearParams;
    use crate::nn::state_dict::StateDict;
    use crate::nn::PopArt;

    #[test]
    fn heads_match_acacs_critic_values_and_gradients() {
        // concat and max_linear critics hold a Linear `value`; mean_linear, ACAC's default, a
        // PopArt one (whose forward is the same linear layer).
        let f = Fixture::load();
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        let case = &f.json["value_heads"];
        let h = Fixture::array2(&case["h"]);
        let c = Fixture::array2(&case["loss_weights"]);
        for (name, prefix) in [
            ("concat", "concat.value."),
            ("mean_linear", "critic.value."),
            ("max_linear", "max_linear.value."),
        ] {
            let head = ValueHead::from_reference_name(name).unwrap();
            assert_eq!(head.reference_name(), name);
            let layer = if name == "mean_linear" {
                PopArt::from_state_dict(&sd, prefix).unwrap().linear
            } else {
                let (out, input) = sd.shape2(&format!("{prefix}weight")).unwrap();
                LinearParams {
                    weight: sd.array2(&format!("{prefix}weight"), out, input).unwrap(),
                    bias: sd.array1(&format!("{prefix}bias"), out).unwrap(),
                }
            };
            assert_eq!(layer.input(), head.pooled_width(8, 3));
            let mut tape = Tape::new();
            let v = layer.bind(&mut tape);
            let hv = tape.param(h.view());
            let pooled = head.pool(&mut tape, hv, 3);
            let value = v.forward(&mut tape, pooled, Activation::Identity);
            tape.backward_with(value, c.view());
            let want = &case["heads"][name];
            assert_close(name, tape.value(value), &want["value"], 1e-5);
            let mut g = LinearParams::zeros(layer.input(), 1);
            v.grads_into(&tape, &mut g);
            assert_close(
                "dweight",
                g.weight.view(),
                &want["grads"]["value.weight"],
                1e-5,
            );
            assert_close("dbias", g.bias.view(), &want["grads"]["value.bias"], 1e-5);
            assert_close("dh", tape.grad(hv).unwrap(), &want["grads"]["h"], 1e-5);
        }
    }

    #[test]
    fn unknown_heads_are_named_in_the_error() {
        let err = ValueHead::from_reference_name("min_linear").unwrap_err();
        assert!(err.to_string().contains("`min_linear`"), "{err}");
    }
}
