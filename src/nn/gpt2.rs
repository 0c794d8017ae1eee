//! The GPT-2 encoder ACAC's critic runs over its agents' encodings (`GPT2Model(config,
//! use_causal_mask=False)` of ACAC's `transformer_model.py`, called with `inputs_embeds`, an
//! all-ones `attention_mask` and `use_position_embedding=True`). B samples of n agents are B n
//! rows; agent slot i gets the learned position embedding `wpe[i]`, every block attends within
//! each sample, and `ln_f` closes:
//!
//! ```text
//! h = drop(x + wpe[0..n] per sample);  h = block_l(h) for l in 0..n_layer;  y = ln_f(h)
//! ```
//!
//! The all-ones attention mask adds 0 to every score (GPT-2 turns it into (1 - 1) * f32::MIN), so
//! no mask is applied. Tensors by the reference's names under the model's prefix
//! (`centralized_transformer.` inside ACAC's critic): `wte.weight` [vocab, d] (unused with
//! `inputs_embeds`, kept so a file round-trips), `wpe.weight` [n_positions, d], `h.<l>.*` (see
//! `gpt2_block.rs`), `ln_f.*`.

use ndarray::{Array2, ArrayViewD};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

use super::gpt2_block::{Gpt2Block, Gpt2BlockVars, GPT2_BLOCK_BUFFERS, GPT2_BLOCK_TENSOR_NAMES};
use super::gpt2_dropout::Gpt2Dropout;
use super::layer_norm::{LayerNormParams, LayerNormVars, LAYER_NORM_EPS};
use super::params::{copy_grad, flat, flat_mut, Params};
use super::state_dict::StateDict;
use super::WeightsError;
use crate::autograd::{Tape, Var};

/// The encoder's sizes (HuggingFace's `GPT2Config` fields that shape tensors, and n_head).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Gpt2Config {
    /// d (`n_embd`): ACAC sets it to the encoders' GRU width (`c_rnn_layer_size`).
    pub width: usize,
    /// Number of blocks (`n_layer`; ACAC: 1).
    pub n_layer: usize,
    /// Attention heads (`n_head`; ACAC's `cc_n_head`, default 2); divides `width`.
    pub n_head: usize,
    /// Rows of `wpe` (`n_positions`; ACAC: 1024): the most agents a sample may have.
    pub n_positions: usize,
    /// Rows of `wte` (`vocab_size`; ACAC: 1).
    pub vocab_size: usize,
}

impl Gpt2Config {
    /// The configuration ACAC's critic builds (`models.py: AgentCentricGRUCritic`): one block,
    /// 1024 positions, a vocabulary of 1.
    pub fn acac(width: usize, n_head: usize) -> Self {
        Gpt2Config {
            width,
            n_layer: 1,
            n_head,
            n_positions: 1024,
            vocab_size: 1,
        }
    }
}

/// The encoder's parameters and its head count.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gpt2 {
    n_head: usize,
    /// Token embeddings [vocab, d]: unused (inputs come as embeddings), kept for the file.
    pub wte: Array2<f32>,
    /// Position embeddings [n_positions, d]; agent slot i adds row i.
    pub wpe: Array2<f32>,
    /// The blocks, in order.
    pub blocks: Vec<Gpt2Block>,
    /// The final layer norm.
    pub ln_f: LayerNormParams,
}

impl Gpt2 {
    /// GPT-2's initialization (`_init_weights`): embeddings N(0, 0.02^2), blocks as
    /// [`Gpt2Block::new`], `ln_f` 1 and 0; drawn in `state_dict` order. Panics if n_head does
    /// not divide the width.
    pub fn new(cfg: Gpt2Config, rng: &mut ChaCha8Rng) -> Self {
        assert!(
            cfg.n_head > 0 && cfg.width.is_multiple_of(cfg.n_head),
            "gpt2: {} heads do not divide width {}",
            cfg.n_head,
            cfg.width
        );
        let normal = Normal::new(0.0, 0.02).expect("a valid normal");
        let mut emb = |rows: usize| {
            Array2::from_shape_simple_fn((rows, cfg.width), || normal.sample(&mut *rng))
        };
        let wte = emb(cfg.vocab_size);
        let wpe = emb(cfg.n_positions);
        Gpt2 {
            n_head: cfg.n_head,
            wte,
            wpe,
            blocks: (0..cfg.n_layer)
                .map(|_| Gpt2Block::new(cfg.width, cfg.n_layer, rng))
                .collect(),
            ln_f: LayerNormParams::new(cfg.width, LAYER_NORM_EPS),
        }
    }

    /// All-zero tensors of these sizes (a gradient buffer).
    pub fn zeros(cfg: Gpt2Config) -> Self {
        Gpt2 {
            n_head: cfg.n_head,
            wte: Array2::zeros((cfg.vocab_size, cfg.width)),
            wpe: Array2::zeros((cfg.n_positions, cfg.width)),
            blocks: (0..cfg.n_layer)
                .map(|_| Gpt2Block::zeros(cfg.width))
                .collect(),
            ln_f: LayerNormParams::zeros(cfg.width, LAYER_NORM_EPS),
        }
    }

    /// The sizes.
    pub fn config(&self) -> Gpt2Config {
        Gpt2Config {
            width: self.wpe.ncols(),
            n_layer: self.blocks.len(),
            n_head: self.n_head,
            n_positions: self.wpe.nrows(),
            vocab_size: self.wte.nrows(),
        }
    }

    /// Every tensor under `prefix` (e.g. `centralized_transformer.`), in `state_dict` order.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        let mut out = vec![
            (format!("{prefix}wte.weight"), self.wte.view().into_dyn()),
            (format!("{prefix}wpe.weight"), self.wpe.view().into_dyn()),
        ];
        for (l, b) in self.blocks.iter().enumerate() {
            out.extend(b.named(&format!("{prefix}h.{l}.")));
        }
        out.extend(self.ln_f.named(&format!("{prefix}ln_f.")));
        out
    }

    /// The encoder under `prefix` in a state_dict, with `n_head` heads (the file does not say;
    /// ACAC's `cc_n_head`). Sizes come from `wte.weight`, `wpe.weight` and the blocks
    /// `h.0.`, `h.1.`, ... present; every other tensor under the prefix is an error, except
    /// the blocks' causal-mask buffers (`attn.bias`, `attn.masked_bias`), which are ignored.
    /// Panics if n_head does not divide the width.
    pub fn from_state_dict(
        sd: &StateDict,
        prefix: &str,
        n_head: usize,
    ) -> Result<Self, WeightsError> {
        let wpe_name = format!("{prefix}wpe.weight");
        let (n_positions, width) = sd.shape2(&wpe_name)?;
        assert!(
            n_head > 0 && width.is_multiple_of(n_head),
            "gpt2: {n_head} heads do not divide width {width}"
        );
        let wte_name = format!("{prefix}wte.weight");
        let vocab_size = sd.shape(&wte_name)?.first().copied().unwrap_or(0);
        let mut blocks = Vec::new();
        while sd.has(&format!("{prefix}h.{}.ln_1.weight", blocks.len())) {
            let l = blocks.len();
            blocks.push(Gpt2Block::from_state_dict(
                sd,
                &format!("{prefix}h.{l}."),
                width,
            )?);
        }
        let model = Gpt2 {
            n_head,
            wte: sd.array2(&wte_name, vocab_size, width)?,
            wpe: sd.array2(&wpe_name, n_positions, width)?,
            blocks,
            ln_f: LayerNormParams::from_state_dict(
                sd,
                &format!("{prefix}ln_f."),
                width,
                LAYER_NORM_EPS,
            )?,
        };
        let known: Vec<String> = model.named(prefix).into_iter().map(|(n, _)| n).collect();
        sd.check_names_under(prefix, &known, &GPT2_BLOCK_BUFFERS, "GPT-2 encoder")?;
        Ok(model)
    }

    /// Put the parameters on a tape as trainable leaves (`wte`, unused, stays off the tape).
    pub fn bind(&self, tape: &mut Tape) -> Gpt2Vars {
        Gpt2Vars {
            n_head: self.n_head,
            wpe: tape.param(self.wpe.view()),
            blocks: self.blocks.iter().map(|b| b.bind(tape)).collect(),
            ln_f: self.ln_f.bind(tape),
        }
    }
}

/// A [`Gpt2`]'s parameters on a tape.
#[derive(Debug, Clone, PartialEq)]
pub struct Gpt2Vars {
    n_head: usize,
    wpe: Var,
    blocks: Vec<Gpt2BlockVars>,
    ln_f: LayerNormVars,
}

impl Gpt2Vars {
    /// The encoder on x: [B n, d], B samples of `set_size` = n agents, sample by sample (ACAC's
    /// `inputs_embeds` [B, n, d] row-major); result [B n, d]. `dropout` multiplies in its masks
    /// (none: dropout off, as in `eval()`). Panics if n exceeds `n_positions` or does not
    /// divide the rows.
    pub fn forward(
        &self,
        tape: &mut Tape,
        x: Var,
        set_size: usize,
        dropout: Option<&Gpt2Dropout>,
    ) -> Var {
        let rows = tape.shape(x).0;
        let positions = tape.shape(self.wpe).0;
        assert!(
            set_size > 0 && set_size <= positions && rows.is_multiple_of(set_size),
            "gpt2: {rows} rows of sets of {set_size} with {positions} positions"
        );
        let slots: Vec<usize> = (0..rows).map(|r| r % set_size).collect();
        let pos = tape.gather_rows(self.wpe, &slots);
        let mut h = tape.add(x, pos);
        if let Some(m) = dropout {
            assert_eq!(
                m.blocks.len(),
                self.blocks.len(),
                "gpt2: one mask set per block"
            );
            let embd = tape.constant(m.embd.view());
            h = tape.mul(h, embd);
        }
        for (l, block) in self.blocks.iter().enumerate() {
            h = block.forward(
                tape,
                h,
                set_size,
                self.n_head,
                dropout.map(|m| &m.blocks[l]),
            );
        }
        self.ln_f.forward(tape, h)
    }

    /// Copy the gradients into `into` (zero where none reached a tensor, `wte` always).
    pub fn grads_into(&self, tape: &Tape, into: &mut Gpt2) {
        into.wte.fill(0.0);
        copy_grad(tape, self.wpe, flat_mut(&mut into.wpe));
        for (v, b) in self.blocks.iter().zip(&mut into.blocks) {
            v.grads_into(tape, b);
        }
        self.ln_f.grads_into(tape, &mut into.ln_f);
    }
}

impl Params for Gpt2 {
    fn slices(&self) -> Vec<&[f32]> {
        let mut out = vec![flat(&self.wte), flat(&self.wpe)];
        for b in &self.blocks {
            out.extend(b.slices());
        }
        out.extend(self.ln_f.slices());
        out
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        let mut out = vec![flat_mut(&mut self.wte), flat_mut(&mut self.wpe)];
        for b in &mut self.blocks {
            out.extend(b.slices_mut());
        }
        out.extend(self.ln_f.slices_mut());
        out
    }
}

/// The tensor names of an encoder of `n_layer` blocks under `prefix`, in `state_dict` order.
pub fn gpt2_tensor_names(prefix: &str, n_layer: usize) -> Vec<String> {
    let mut out = vec![format!("{prefix}wte.weight"), format!("{prefix}wpe.weight")];
    for l in 0..n_layer {
        out.extend(
            GPT2_BLOCK_TENSOR_NAMES
                .iter()
                .map(|n| format!("{prefix}h.{l}.{n}")),
        );
    }
    out.extend([format!("{prefix}ln_f.weight"), format!("{prefix}ln_f.bias")]);
    out
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use rand::SeedableRng;
    use serde_json::Value;

    use super::*;
    use crate::nn::acac_fixture::{assert_close, Fixture};
    use crate::nn::gpt2_dropout::BlockDropout;

    /// Run a fixture case through `model` and compare output and every gradient.
    fn check_case(model: &Gpt2, case: &Value, dropout: Option<&Gpt2Dropout>, tol: f32) {
        let n = 3;
        let mut tape = Tape::new();
        let vars = model.bind(&mut tape);
        let x = tape.param(Fixture::array2(&case["x"]).view());
        let y = vars.forward(&mut tape, x, n, dropout);
        tape.backward_with(y, Fixture::array2(&case["loss_weights"]).view());
        assert_close("output", tape.value(y), &case["output"], tol);
        assert_close("dx", tape.grad(x).unwrap(), &case["grads"]["x"], tol);
        let mut g = Gpt2::zeros(model.config());
        vars.grads_into(&tape, &mut g);
        let grads = &case["grads"];
        for (name, a) in g.named("") {
            if name == "wte.weight" {
                assert!(grads.get(&name).is_none() && a.iter().all(|&v| v == 0.0));
            } else if name == "wpe.weight" {
                // Only the n agent slots receive a gradient.
                let rows = a.view().into_dimensionality::<ndarray::Ix2>().unwrap();
                assert_close(&name, rows.slice(ndarray::s![..n, ..]), &grads[&name], tol);
                assert!(rows.slice(ndarray::s![n.., ..]).iter().all(|&v| v == 0.0));
            } else {
                assert_close(&name, a, &grads[&name], tol);
            }
        }
    }

    fn acac_critic_transformer(f: &Fixture) -> Gpt2 {
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        Gpt2::from_state_dict(&sd, "critic.centralized_transformer.", 2).unwrap()
    }

    #[test]
    fn acac_critic_transformer_matches_pytorch_with_dropout_off() {
        let f = Fixture::load();
        let model = acac_critic_transformer(&f);
        assert_eq!(model.config(), Gpt2Config::acac(8, 2));
        check_case(&model, &f.json["gpt2"], None, 2e-5);
    }

    #[test]
    fn acac_critic_transformer_replays_pytorch_dropout_masks() {
        let f = Fixture::load();
        let model = acac_critic_transformer(&f);
        let case = &f.json["gpt2_dropout"];
        let m = |k: &str| Fixture::array2(&case["dropout"][k]);
        let masks = Gpt2Dropout {
            embd: m("drop"),
            blocks: vec![BlockDropout {
                attn: m("h.0.attn.attn_dropout"),
                resid: m("h.0.attn.resid_dropout"),
                mlp: m("h.0.mlp.dropout"),
            }],
        };
        check_case(&model, case, Some(&masks), 2e-5);
        // The masks matter: without them the output differs.
        let mut tape = Tape::new();
        let vars = model.bind(&mut tape);
        let x = tape.constant(Fixture::array2(&case["x"]).view());
        let y = vars.forward(&mut tape, x, 3, None);
        let (_, want) = Fixture::tensor(&case["output"]);
        assert!(tape
            .value(y)
            .iter()
            .zip(&want)
            .any(|(a, b)| (a - b).abs() > 1e-3));
    }

    #[test]
    fn two_blocks_of_four_heads_match_pytorch() {
        let f = Fixture::load();
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        let model = Gpt2::from_state_dict(&sd, "gpt2_two_layers.", 4).unwrap();
        assert_eq!(
            model.config(),
            Gpt2Config {
                width: 8,
                n_layer: 2,
                n_head: 4,
                n_positions: 16,
                vocab_size: 1
            }
        );
        check_case(&model, &f.json["gpt2_two_layers"], None, 2e-5);
    }

    #[test]
    fn names_round_trip_and_strangers_under_the_prefix_are_errors() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let cfg = Gpt2Config {
            width: 4,
            n_layer: 2,
            n_head: 2,
            n_positions: 5,
            vocab_size: 1,
        };
        let model = Gpt2::new(cfg, &mut rng);
        let named = model.named("t.");
        assert_eq!(
            named.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>(),
            gpt2_tensor_names("t.", 2)
        );
        let bytes = crate::nn::safetensors_io::named_to_safetensors_bytes(&named);
        let sd = StateDict::parse(&bytes, Path::new("f")).unwrap();
        assert_eq!(Gpt2::from_state_dict(&sd, "t.", 2).unwrap(), model);

        let extra = ndarray::ArrayD::zeros(vec![2]);
        let mut with_extra = named.clone();
        with_extra.push(("t.h.0.attn.masked_bias".to_string(), extra.view()));
        with_extra.push(("other.thing".to_string(), extra.view()));
        let bytes = crate::nn::safetensors_io::named_to_safetensors_bytes(&with_extra);
        let sd = StateDict::parse(&bytes, Path::new("f")).unwrap();
        assert_eq!(Gpt2::from_state_dict(&sd, "t.", 2).unwrap(), model);
        with_extra.push(("t.h.0.attn.q_attn.weight".to_string(), extra.view()));
        let bytes = crate::nn::safetensors_io::named_to_safetensors_bytes(&with_extra);
        let sd = StateDict::parse(&bytes, Path::new("f")).unwrap();
        let err = Gpt2::from_state_dict(&sd, "t.", 2).unwrap_err().to_string();
        assert!(err.contains("t.h.0.attn.q_attn.weight"), "{err}");
    }
}
