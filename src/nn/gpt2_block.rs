//! One GPT-2 block (HuggingFace's `GPT2Block` as ACAC's `transformer_model.py` copies it), over
//! B samples of n agents stored as B n rows, attending within each sample (no causal mask):
//!
//! ```text
//! a = x + drop(c_proj(attn(ln_1(x))))          attn: q, k, v = split(c_attn(.)), see Tape::self_attention
//! y = a + drop(mlp.c_proj(gelu(mlp.c_fc(ln_2(a)))))      c_fc: d -> 4d, gelu_new
//! ```
//!
//! Tensors by the reference's names under the block's prefix (`h.0.`): `ln_1.*`,
//! `attn.c_attn.*` (weight [d, 3d]), `attn.c_proj.*`, `ln_2.*`, `mlp.c_fc.*` ([d, 4d]),
//! `mlp.c_proj.*` ([4d, d]).

use ndarray::ArrayViewD;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::conv1d::{Conv1dParams, Conv1dVars};
use super::gpt2_dropout::BlockDropout;
use super::layer_norm::{LayerNormParams, LayerNormVars, LAYER_NORM_EPS};
use super::params::Params;
use super::state_dict::StateDict;
use super::WeightsError;
use crate::autograd::{AttentionSpec, Tape, Var};

/// The tensor names of a block, after its prefix, in `state_dict` order.
pub const GPT2_BLOCK_TENSOR_NAMES: [&str; 12] = [
    "ln_1.weight",
    "ln_1.bias",
    "attn.c_attn.weight",
    "attn.c_attn.bias",
    "attn.c_proj.weight",
    "attn.c_proj.bias",
    "ln_2.weight",
    "ln_2.bias",
    "mlp.c_fc.weight",
    "mlp.c_fc.bias",
    "mlp.c_proj.weight",
    "mlp.c_proj.bias",
];

/// A block's non-weight buffers a state_dict may hold (the causal mask and its fill value,
/// unused without a causal mask): accepted and ignored on load.
pub const GPT2_BLOCK_BUFFERS: [&str; 2] = ["attn.bias", "attn.masked_bias"];

/// One GPT-2 block's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gpt2Block {
    /// Before attention.
    pub ln_1: LayerNormParams,
    /// q, k, v in one layer: d -> 3d.
    pub c_attn: Conv1dParams,
    /// Attention output: d -> d.
    pub attn_c_proj: Conv1dParams,
    /// Before the MLP.
    pub ln_2: LayerNormParams,
    /// d -> 4d.
    pub c_fc: Conv1dParams,
    /// 4d -> d.
    pub mlp_c_proj: Conv1dParams,
}

impl Gpt2Block {
    /// GPT-2's initialization for a model of `n_layer` blocks (`_init_weights`): Conv1D weights
    /// N(0, 0.02^2), both `c_proj` weights N(0, (0.02 / sqrt(2 n_layer))^2), biases 0, layer
    /// norms 1 and 0; drawn in `state_dict` order.
    pub fn new(width: usize, n_layer: usize, rng: &mut ChaCha8Rng) -> Self {
        let proj_std = 0.02 / (2.0 * n_layer as f32).sqrt();
        Gpt2Block {
            ln_1: LayerNormParams::new(width, LAYER_NORM_EPS),
            c_attn: Conv1dParams::normal(width, 3 * width, 0.02, rng),
            attn_c_proj: Conv1dParams::normal(width, width, proj_std, rng),
            ln_2: LayerNormParams::new(width, LAYER_NORM_EPS),
            c_fc: Conv1dParams::normal(width, 4 * width, 0.02, rng),
            mlp_c_proj: Conv1dParams::normal(4 * width, width, proj_std, rng),
        }
    }

    /// All-zero tensors (a gradient buffer).
    pub fn zeros(width: usize) -> Self {
        Gpt2Block {
            ln_1: LayerNormParams::zeros(width, LAYER_NORM_EPS),
            c_attn: Conv1dParams::zeros(width, 3 * width),
            attn_c_proj: Conv1dParams::zeros(width, width),
            ln_2: LayerNormParams::zeros(width, LAYER_NORM_EPS),
            c_fc: Conv1dParams::zeros(width, 4 * width),
            mlp_c_proj: Conv1dParams::zeros(4 * width, width),
        }
    }

    /// d, the width in and out.
    pub fn width(&self) -> usize {
        self.ln_1.width()
    }

    /// Every tensor under `prefix` (e.g. `h.0.`), in [`GPT2_BLOCK_TENSOR_NAMES`] order.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        let mut out = self.ln_1.named(&format!("{prefix}ln_1."));
        out.extend(self.c_attn.named(&format!("{prefix}attn.c_attn.")));
        out.extend(self.attn_c_proj.named(&format!("{prefix}attn.c_proj.")));
        out.extend(self.ln_2.named(&format!("{prefix}ln_2.")));
        out.extend(self.c_fc.named(&format!("{prefix}mlp.c_fc.")));
        out.extend(self.mlp_c_proj.named(&format!("{prefix}mlp.c_proj.")));
        out
    }

    /// The block under `prefix` in a state_dict, of width `width`.
    pub fn from_state_dict(
        sd: &StateDict,
        prefix: &str,
        width: usize,
    ) -> Result<Self, WeightsError> {
        let conv = |name: &str, i: usize, o: usize| {
            Conv1dParams::from_state_dict(sd, &format!("{prefix}{name}."), i, o)
        };
        let ln = |name: &str| {
            LayerNormParams::from_state_dict(sd, &format!("{prefix}{name}."), width, LAYER_NORM_EPS)
        };
        Ok(Gpt2Block {
            ln_1: ln("ln_1")?,
            c_attn: conv("attn.c_attn", width, 3 * width)?,
            attn_c_proj: conv("attn.c_proj", width, width)?,
            ln_2: ln("ln_2")?,
            c_fc: conv("mlp.c_fc", width, 4 * width)?,
            mlp_c_proj: conv("mlp.c_proj", 4 * width, width)?,
        })
    }

    /// Put the parameters on a tape as trainable leaves.
    pub fn bind(&self, tape: &mut Tape) -> Gpt2BlockVars {
        Gpt2BlockVars {
            ln_1: self.ln_1.bind(tape),
            c_attn: self.c_attn.bind(tape),
            attn_c_proj: self.attn_c_proj.bind(tape),
            ln_2: self.ln_2.bind(tape),
            c_fc: self.c_fc.bind(tape),
            mlp_c_proj: self.mlp_c_proj.bind(tape),
        }
    }
}

/// A [`Gpt2Block`]'s parameters on a tape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gpt2BlockVars {
    ln_1: LayerNormVars,
    c_attn: Conv1dVars,
    attn_c_proj: Conv1dVars,
    ln_2: LayerNormVars,
    c_fc: Conv1dVars,
    mlp_c_proj: Conv1dVars,
}

impl Gpt2BlockVars {
    /// The block on x: [B n, d] (B samples of `set_size` agents) with `n_head` heads; `dropout`
    /// multiplies in the block's masks (none: dropout off, as in `eval()`).
    pub fn forward(
        &self,
        tape: &mut Tape,
        x: Var,
        set_size: usize,
        n_head: usize,
        dropout: Option<&BlockDropout>,
    ) -> Var {
        let d = tape.shape(x).1;
        let h = self.ln_1.forward(tape, x);
        let qkv = self.c_attn.forward(tape, h);
        let (q, k, v) = (
            tape.slice_cols(qkv, 0, d),
            tape.slice_cols(qkv, d, 2 * d),
            tape.slice_cols(qkv, 2 * d, 3 * d),
        );
        let mut spec = AttentionSpec::new(set_size, n_head);
        spec.dropout = dropout.map(|m| tape.constant(m.attn.view()));
        let a = tape.self_attention(q, k, v, spec);
        let mut a = self.attn_c_proj.forward(tape, a);
        if let Some(m) = dropout {
            let m = tape.constant(m.resid.view());
            a = tape.mul(a, m);
        }
        let x = tape.add(a, x);
        let h = self.ln_2.forward(tape, x);
        let h = self.c_fc.forward(tape, h);
        let h = tape.gelu_tanh(h);
        let mut m = self.mlp_c_proj.forward(tape, h);
        if let Some(mask) = dropout {
            let mask = tape.constant(mask.mlp.view());
            m = tape.mul(m, mask);
        }
        tape.add(x, m)
    }

    /// Copy the gradients into `into` (zero where none reached a tensor).
    pub fn grads_into(&self, tape: &Tape, into: &mut Gpt2Block) {
        self.ln_1.grads_into(tape, &mut into.ln_1);
        self.c_attn.grads_into(tape, &mut into.c_attn);
        self.attn_c_proj.grads_into(tape, &mut into.attn_c_proj);
        self.ln_2.grads_into(tape, &mut into.ln_2);
        self.c_fc.grads_into(tape, &mut into.c_fc);
        self.mlp_c_proj.grads_into(tape, &mut into.mlp_c_proj);
    }
}

impl Params for Gpt2Block {
    fn slices(&self) -> Vec<&[f32]> {
        let mut out = self.ln_1.slices();
        out.extend(self.c_attn.slices());
        out.extend(self.attn_c_proj.slices());
        out.extend(self.ln_2.slices());
        out.extend(self.c_fc.slices());
        out.extend(self.mlp_c_proj.slices());
        out
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        let mut out = self.ln_1.slices_mut();
        out.extend(self.c_attn.slices_mut());
        out.extend(self.attn_c_proj.slices_mut());
        out.extend(self.ln_2.slices_mut());
        out.extend(self.c_fc.slices_mut());
        out.extend(self.mlp_c_proj.slices_mut());
        out
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn names_follow_the_reference_and_init_follows_gpt2() {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let b = Gpt2Block::new(16, 2, &mut rng);
        let named = b.named("h.1.");
        let names: Vec<String> = GPT2_BLOCK_TENSOR_NAMES
            .iter()
            .map(|n| format!("h.1.{n}"))
            .collect();
        assert_eq!(
            named.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(),
            names
        );
        assert_eq!(named[2].1.shape(), &[16, 48]);
        assert_eq!(named[10].1.shape(), &[64, 16]);
        let std = |a: &ndarray::Array2<f32>| {
            (a.iter().map(|v| v * v).sum::<f32>() / a.len() as f32).sqrt()
        };
        assert!((std(&b.c_fc.weight) / 0.02 - 1.0).abs() < 0.1);
        assert!((std(&b.mlp_c_proj.weight) / 0.01 - 1.0).abs() < 0.1);
        assert_eq!(b.slices().len(), 12);
    }
}
