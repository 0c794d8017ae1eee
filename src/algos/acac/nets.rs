//! ACAC's critic as its `models.py` builds it (`share_encoder` false, `use_attention` true); the
//! actors and the encoder both share in form are in [`crate::nn::AcacActor`] (policy files hold
//! actors, and `nn` is all they may read):
//!
//! ```text
//! critic (AgentCentricGRUCritic):  per agent i, encoder_i over [obs_i, temb(t)] of agent i's own
//!                                  macro-steps; regrouped by joint macro-step; GPT-2 over the n
//!                                  agents; value head; Linear or PopArt
//! ```
//!
//! The value layer has gain 1 and a zero bias. The time embedding is the fixed sinusoidal table
//! (`time_emb_alg` sinu) of `env_terminate_step + 5` rows.

use ndarray::{Array1, Array2, ArrayViewD};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::autograd::{SeqPacking, Tape, Var};
use crate::nn::{flat, flat_mut};
use crate::nn::{
    AcacEncoder, AcacEncoderVars, AcacJointValue, AcacJointValueVars, Gpt2, Gpt2Config,
    Gpt2Dropout, LinearParams, Params, PopArt, StateDict, ValueHead, ValueLayer, WeightsError,
    GPT2_BLOCK_BUFFERS, TIME_TABLE,
};

/// `AgentCentricGRUCritic` with `use_attention`: one encoder per agent and the joint value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcacCritic {
    /// `encoders.<i>`.
    pub encoders: Vec<AcacEncoder>,
    /// `centralized_transformer` and `value`.
    pub top: AcacJointValue,
}

/// An [`AcacCritic`] on a tape.
#[derive(Debug, Clone)]
pub struct AcacCriticVars {
    encoders: Vec<AcacEncoderVars>,
    top: AcacJointValueVars,
}

/// What the critic reads for a batch of episodes: R joint rows in all, episode by episode.
/// Agent i's encoder runs over the rows where `step_of[i]` is set, each episode from a zero
/// state; every row then takes agent i's latest encoding (`recover_joint_feature`).
#[derive(Debug, Clone, PartialEq)]
pub struct CriticInput {
    /// Joint rows per episode.
    pub rows_per_episode: Vec<usize>,
    /// Per agent: its input rows [K_i, in_i] (observation and time embedding) in flat order.
    pub x: Vec<Array2<f32>>,
    /// Per agent: its sequence length per episode.
    pub lengths: Vec<Vec<usize>>,
    /// Per agent: for each joint row (all episodes), the flat index of its latest input row.
    pub latest: Vec<Vec<usize>>,
}

impl AcacCritic {
    /// Fresh weights: the encoders in agent order, then the GPT-2 block, then the value layer
    /// (`Linear` or PopArt), as the module registers them.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        inputs: &[usize],
        m0: usize,
        hidden: usize,
        n_head: usize,
        head: crate::nn::ValueHead,
        popart: bool,
        rng: &mut ChaCha8Rng,
    ) -> Self {
        let encoders = inputs
            .iter()
            .map(|&i| AcacEncoder::new(i, m0, hidden, rng))
            .collect::<Vec<_>>();
        let transformer = Gpt2::new(Gpt2Config::acac(hidden, n_head), rng);
        let pooled = head.pooled_width(hidden, inputs.len());
        let value = if popart {
            ValueLayer::PopArt(PopArt::new(pooled, 1, rng))
        } else {
            ValueLayer::Linear(LinearParams::xavier(pooled, 1, 1.0, rng))
        };
        AcacCritic {
            encoders,
            top: AcacJointValue {
                transformer,
                head,
                value,
            },
        }
    }

    /// The critic's `state_dict` under `prefix` (`AgentCentricGRUCritic` with `use_attention`:
    /// `encoders.<i>.*` for every agent, `centralized_transformer.*`, `value.*`; the time
    /// table and GPT-2's causal-mask buffers are skipped), with ACAC's `value_head` and
    /// `cc_n_head`, which the file does not record. Any other tensor under the prefix is an
    /// error. Panics if n_head does not divide the encoders' width.
    pub fn from_state_dict(
        sd: &StateDict,
        prefix: &str,
        head: ValueHead,
        n_head: usize,
    ) -> Result<Self, WeightsError> {
        let mut encoders = Vec::new();
        while sd.has(&format!("{prefix}encoders.{}.fc1.weight", encoders.len())) {
            let i = encoders.len();
            encoders.push(AcacEncoder::from_state_dict(
                sd,
                &format!("{prefix}encoders.{i}."),
            )?);
        }
        let critic = AcacCritic {
            encoders,
            top: AcacJointValue::from_state_dict(sd, prefix, head, n_head)?,
        };
        let known: Vec<String> = critic.named(prefix).into_iter().map(|(n, _)| n).collect();
        let mut ignored = vec![TIME_TABLE];
        ignored.extend(GPT2_BLOCK_BUFFERS);
        sd.check_names_under(prefix, &known, &ignored, "ACAC critic")?;
        Ok(critic)
    }

    /// Every tensor under `prefix`, by ACAC's names, in `state_dict` order (without the time
    /// table).
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        let mut out = Vec::new();
        for (i, e) in self.encoders.iter().enumerate() {
            out.extend(e.named(&format!("{prefix}encoders.{i}.")));
        }
        out.extend(self.top.named(prefix));
        out
    }

    /// All-zero tensors of the same sizes (a gradient buffer).
    pub fn zeros_like(&self) -> Self {
        let value = match &self.top.value {
            ValueLayer::Linear(l) => ValueLayer::Linear(LinearParams::zeros(l.input(), 1)),
            ValueLayer::PopArt(p) => ValueLayer::PopArt(PopArt::with_layer(LinearParams::zeros(
                p.linear.input(),
                p.linear.output(),
            ))),
        };
        AcacCritic {
            encoders: self.encoders.iter().map(AcacEncoder::zeros_like).collect(),
            top: AcacJointValue {
                transformer: Gpt2::zeros(self.top.transformer.config()),
                head: self.top.head,
                value,
            },
        }
    }

    /// The PopArt layer, if the critic normalizes its values.
    pub fn popart(&self) -> Option<&PopArt> {
        match &self.top.value {
            ValueLayer::PopArt(p) => Some(p),
            ValueLayer::Linear(_) => None,
        }
    }

    /// The PopArt layer, mutable.
    pub fn popart_mut(&mut self) -> Option<&mut PopArt> {
        match &mut self.top.value {
            ValueLayer::PopArt(p) => Some(p),
            ValueLayer::Linear(_) => None,
        }
    }

    /// Put the weights on a tape.
    pub fn bind(&self, tape: &mut Tape) -> AcacCriticVars {
        AcacCriticVars {
            encoders: self.encoders.iter().map(|e| e.bind(tape)).collect(),
            top: self.top.bind(tape),
        }
    }

    /// The values [R, 1] (normalized with PopArt) of `input`'s joint rows, computed on `tape`
    /// (reset first, so a learner reuses one tape's buffers) and taken off it.
    pub fn values(
        &self,
        tape: &mut Tape,
        input: &CriticInput,
        dropout: Option<&Gpt2Dropout>,
    ) -> Array1<f32> {
        tape.reset();
        let vars = self.bind(tape);
        let v = vars.forward(tape, input, dropout);
        tape.value(v).column(0).to_owned()
    }
}

impl AcacCriticVars {
    /// The values [R, 1] of the joint rows of `input` (see [`CriticInput`]).
    pub fn forward(
        &self,
        tape: &mut Tape,
        input: &CriticInput,
        dropout: Option<&Gpt2Dropout>,
    ) -> Var {
        let n = self.encoders.len();
        let rows: usize = input.rows_per_episode.iter().sum();
        let mut per_agent = Vec::with_capacity(n);
        for (i, enc) in self.encoders.iter().enumerate() {
            let packing = SeqPacking::new(&input.lengths[i]);
            let x = tape.constant(input.x[i].view());
            let h = enc.forward(tape, x, &packing);
            per_agent.push(tape.gather_rows(h, &input.latest[i]));
        }
        // Rows agent-major ([agent 0's R rows], [agent 1's], ...) to sample-major (r n + i).
        let stacked = tape.concat_rows(&per_agent);
        let order: Vec<usize> = (0..rows * n).map(|k| (k % n) * rows + k / n).collect();
        let features = tape.gather_rows(stacked, &order);
        self.top.forward(tape, features, n, dropout)
    }

    /// Copy the gradients into `into` (PopArt's statistics untouched).
    pub fn grads_into(&self, tape: &Tape, into: &mut AcacCritic) {
        for (v, e) in self.encoders.iter().zip(&mut into.encoders) {
            v.grads_into(tape, e);
        }
        self.top.grads_into(tape, &mut into.top);
    }
}

impl Params for AcacCritic {
    fn slices(&self) -> Vec<&[f32]> {
        let mut out: Vec<&[f32]> = self.encoders.iter().flat_map(|e| e.slices()).collect();
        out.extend(self.top.transformer.slices());
        let l = self.top.value.linear();
        out.extend([flat(&l.weight), flat(&l.bias)]);
        out
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        let mut out: Vec<&mut [f32]> = self
            .encoders
            .iter_mut()
            .flat_map(|e| e.slices_mut())
            .collect();
        out.extend(self.top.transformer.slices_mut());
        let l = match &mut self.top.value {
            ValueLayer::Linear(l) => l,
            ValueLayer::PopArt(p) => &mut p.linear,
        };
        out.extend([flat_mut(&mut l.weight), flat_mut(&mut l.bias)]);
        out
    }
}
