//! ACAC's nets as its `models.py` builds them (`share_encoder` false, `use_attention` true):
//!
//! ```text
//! encoder (GRUEncoder):  x -> fc1 -> leaky_relu -> fc2 -> leaky_relu -> GRU
//! actor i (AgentCentricGRUActor):  [obs_i, temb(t)] -> encoder -> fc3 -> leaky_relu -> ln? -> fc4
//!                                  -> log_softmax (-> eps-mixture while training)
//! critic (AgentCentricGRUCritic):  per agent i, encoder_i over [obs_i, temb(t)] of agent i's own
//!                                  macro-steps; regrouped by joint macro-step; GPT-2 over the n
//!                                  agents; value head; Linear or PopArt
//! ```
//!
//! Leaky ReLU slope 0.01 (`F.leaky_relu`); fc1..fc3 Xavier-uniform with the leaky-ReLU gain,
//! fc4 and the value layer gain 1, zero biases; the GRU PyTorch's default. The time embedding
//! is the fixed sinusoidal table (`time_emb_alg` sinu) of `env_terminate_step + 5` rows.

use ndarray::{Array1, Array2, ArrayViewD};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::autograd::{Activation, GruVars, SeqPacking, Tape, Var};
use crate::nn::init::LEAKY_RELU_GAIN;
use crate::nn::log_softmax_in_place;
use crate::nn::{
    AcacJointValue, AcacJointValueVars, Gpt2, Gpt2Config, Gpt2Dropout, GruParams, GruState,
    LayerNormParams, LayerNormVars, LinearParams, LinearVars, Params, PopArt, StateDict, ValueHead,
    ValueLayer, WeightsError, GPT2_BLOCK_BUFFERS, LAYER_NORM_EPS,
};

/// The time table ACAC registers in every actor and critic (`time_embedding.weight`): one
/// fixed table, held once by [`super::update::AcacNets`], so the nets' own loaders skip it.
pub const TIME_TABLE: &str = "time_embedding.weight";

const LEAKY: Activation = Activation::LEAKY_001;

/// Flat view of an owned, contiguous array.
fn flat<D: ndarray::Dimension>(a: &ndarray::Array<f32, D>) -> &[f32] {
    a.as_slice_memory_order()
        .expect("owned parameter arrays are contiguous")
}

fn flat_mut<D: ndarray::Dimension>(a: &mut ndarray::Array<f32, D>) -> &mut [f32] {
    a.as_slice_memory_order_mut()
        .expect("owned parameter arrays are contiguous")
}

/// `GRUEncoder`: fc1 (in -> m0), fc2 (m0 -> m0), GRU (m0 -> H).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcacEncoder {
    /// `fc1`.
    pub fc1: LinearParams,
    /// `fc2`.
    pub fc2: LinearParams,
    /// `gru`.
    pub gru: GruParams,
}

/// An [`AcacEncoder`] on a tape.
#[derive(Debug, Clone, Copy)]
pub struct AcacEncoderVars {
    fc1: LinearVars,
    fc2: LinearVars,
    gru: GruVars,
}

impl AcacEncoder {
    /// Fresh weights, drawn in module order (fc1, fc2, gru).
    pub fn new(input: usize, m0: usize, hidden: usize, rng: &mut ChaCha8Rng) -> Self {
        AcacEncoder {
            fc1: LinearParams::xavier(input, m0, LEAKY_RELU_GAIN, rng),
            fc2: LinearParams::xavier(m0, m0, LEAKY_RELU_GAIN, rng),
            gru: GruParams::pytorch_default(m0, hidden, rng),
        }
    }

    /// The encoder under `prefix` in a state_dict (`encoder.` of an actor, `encoders.<i>.`
    /// of the critic), sizes from the file.
    pub fn from_state_dict(sd: &StateDict, prefix: &str) -> Result<Self, WeightsError> {
        Ok(AcacEncoder {
            fc1: sd.linear(&format!("{prefix}fc1."))?,
            fc2: sd.linear(&format!("{prefix}fc2."))?,
            gru: sd.gru(&format!("{prefix}gru."))?,
        })
    }

    /// Every tensor under `prefix`, by ACAC's names, in `state_dict` order.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        let mut out = self.fc1.named(&format!("{prefix}fc1."));
        out.extend(self.fc2.named(&format!("{prefix}fc2.")));
        out.extend(
            self.gru
                .named()
                .map(|(n, v)| (format!("{prefix}gru.{n}"), v)),
        );
        out
    }

    fn zeros_like(&self) -> Self {
        AcacEncoder {
            fc1: LinearParams::zeros(self.fc1.input(), self.fc1.output()),
            fc2: LinearParams::zeros(self.fc2.input(), self.fc2.output()),
            gru: GruParams::zeros(self.gru.input(), self.gru.hidden()),
        }
    }

    /// Put the weights on a tape.
    pub fn bind(&self, tape: &mut Tape) -> AcacEncoderVars {
        AcacEncoderVars {
            fc1: self.fc1.bind(tape),
            fc2: self.fc2.bind(tape),
            gru: self.gru.bind(tape),
        }
    }

    fn slices(&self) -> Vec<&[f32]> {
        let mut out = vec![
            flat(&self.fc1.weight),
            flat(&self.fc1.bias),
            flat(&self.fc2.weight),
            flat(&self.fc2.bias),
        ];
        out.extend(self.gru.slices());
        out
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        let mut out = vec![
            flat_mut(&mut self.fc1.weight),
            flat_mut(&mut self.fc1.bias),
            flat_mut(&mut self.fc2.weight),
            flat_mut(&mut self.fc2.bias),
        ];
        out.extend(self.gru.slices_mut());
        out
    }
}

impl AcacEncoderVars {
    /// The GRU's output [K, H] for x: [K, in] in flat (sequence, time) order of `packing`.
    pub fn forward(&self, tape: &mut Tape, x: Var, packing: &SeqPacking) -> Var {
        let a1 = self.fc1.forward(tape, x, LEAKY);
        let a2 = self.fc2.forward(tape, a1, LEAKY);
        tape.gru(a2, self.gru, packing)
    }

    fn grads_into(&self, tape: &Tape, into: &mut AcacEncoder) {
        self.fc1.grads_into(tape, &mut into.fc1);
        self.fc2.grads_into(tape, &mut into.fc2);
        self.gru.grads_into(tape, &mut into.gru);
    }
}

/// `AgentCentricGRUActor` (one agent's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcacActor {
    /// `encoder`.
    pub encoder: AcacEncoder,
    /// `fc3` (H -> m1).
    pub fc3: LinearParams,
    /// `ln` (`use_actor_ln`).
    pub ln: Option<LayerNormParams>,
    /// `fc4` (m1 -> actions).
    pub fc4: LinearParams,
}

/// An [`AcacActor`] on a tape.
#[derive(Debug, Clone, Copy)]
pub struct AcacActorVars {
    encoder: AcacEncoderVars,
    fc3: LinearVars,
    ln: Option<LayerNormVars>,
    fc4: LinearVars,
}

/// One agent's recurrent state while acting, with the scratch its step writes into.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcacActorState {
    gru: GruState,
    #[serde(skip)]
    scratch: Vec<Vec<f32>>,
}

impl AcacActorState {
    /// Back to the zero state of an episode's start.
    pub fn reset(&mut self) {
        self.gru.reset();
    }
}

impl AcacActor {
    /// Fresh weights for an input of `input` features (observation plus time embedding), drawn
    /// in module order (encoder, fc3, fc4; the LayerNorm starts at gain 1, bias 0).
    pub fn new(
        input: usize,
        mlp: [usize; 2],
        hidden: usize,
        n_actions: usize,
        layer_norm: bool,
        rng: &mut ChaCha8Rng,
    ) -> Self {
        let encoder = AcacEncoder::new(input, mlp[0], hidden, rng);
        let fc3 = LinearParams::xavier(hidden, mlp[1], LEAKY_RELU_GAIN, rng);
        let ln = layer_norm.then(|| LayerNormParams::new(mlp[1], LAYER_NORM_EPS));
        let fc4 = LinearParams::xavier(mlp[1], n_actions, 1.0, rng);
        AcacActor {
            encoder,
            fc3,
            ln,
            fc4,
        }
    }

    /// An actor's `state_dict` under `prefix` (`AgentCentricGRUActor`: `encoder.*`, `fc3.*`,
    /// `ln.*` when `use_actor_ln`, `fc4.*`; its `time_embedding.weight` is skipped, see
    /// [`TIME_TABLE`]). Any other tensor under the prefix is an error.
    pub fn from_state_dict(sd: &StateDict, prefix: &str) -> Result<Self, WeightsError> {
        let fc3 = sd.linear(&format!("{prefix}fc3."))?;
        let ln_prefix = format!("{prefix}ln.");
        let ln = if sd.has(&format!("{ln_prefix}weight")) {
            Some(LayerNormParams::from_state_dict(
                sd,
                &ln_prefix,
                fc3.output(),
                LAYER_NORM_EPS,
            )?)
        } else {
            None
        };
        let actor = AcacActor {
            encoder: AcacEncoder::from_state_dict(sd, &format!("{prefix}encoder."))?,
            fc3,
            ln,
            fc4: sd.linear(&format!("{prefix}fc4."))?,
        };
        let known: Vec<String> = actor.named(prefix).into_iter().map(|(n, _)| n).collect();
        sd.check_names_under(prefix, &known, &[TIME_TABLE], "ACAC actor")?;
        Ok(actor)
    }

    /// Every tensor under `prefix`, by ACAC's names, in `state_dict` order (without the time
    /// table).
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        let mut out = self.encoder.named(&format!("{prefix}encoder."));
        out.extend(self.fc3.named(&format!("{prefix}fc3.")));
        if let Some(ln) = &self.ln {
            out.extend(ln.named(&format!("{prefix}ln.")));
        }
        out.extend(self.fc4.named(&format!("{prefix}fc4.")));
        out
    }

    /// All-zero tensors of the same sizes (a gradient buffer).
    pub fn zeros_like(&self) -> Self {
        AcacActor {
            encoder: self.encoder.zeros_like(),
            fc3: LinearParams::zeros(self.fc3.input(), self.fc3.output()),
            ln: self
                .ln
                .as_ref()
                .map(|l| LayerNormParams::zeros(l.width(), l.eps)),
            fc4: LinearParams::zeros(self.fc4.input(), self.fc4.output()),
        }
    }

    /// Macro-actions.
    pub fn n_actions(&self) -> usize {
        self.fc4.output()
    }

    /// Input features.
    pub fn input(&self) -> usize {
        self.encoder.fc1.input()
    }

    /// Put the weights on a tape.
    pub fn bind(&self, tape: &mut Tape) -> AcacActorVars {
        AcacActorVars {
            encoder: self.encoder.bind(tape),
            fc3: self.fc3.bind(tape),
            ln: self.ln.as_ref().map(|l| l.bind(tape)),
            fc4: self.fc4.bind(tape),
        }
    }

    /// The zero state of an episode's start.
    pub fn zero_state(&self) -> AcacActorState {
        AcacActorState {
            gru: GruState::zeros(self.encoder.gru.hidden()),
            scratch: Vec::new(),
        }
    }

    /// One acting step on input x (observation and time embedding): the plain log-probabilities
    /// (`test_mode`) of the macro-actions; the state advances. Panics if x has the wrong length.
    pub fn act_step<'s>(&self, x: &[f32], state: &'s mut AcacActorState) -> &'s [f32] {
        let m0 = self.encoder.fc1.output();
        let m1 = self.fc3.output();
        let widths = [m0, m0, m1, m1, self.n_actions()];
        if state.scratch.len() != widths.len() {
            state.scratch = widths.iter().map(|&w| vec![0.0; w]).collect();
        }
        let [a1, a2, a3, a4, out] = &mut state.scratch[..] else {
            unreachable!("five scratch rows were just made")
        };
        self.encoder.fc1.forward_row(x, LEAKY, a1);
        self.encoder.fc2.forward_row(a1, LEAKY, a2);
        self.encoder.gru.step(a2, &mut state.gru);
        self.fc3.forward_row(state.gru.h(), LEAKY, a3);
        let normed: &[f32] = match &self.ln {
            Some(ln) => {
                layer_norm_row(a3, ln, a4);
                a4
            }
            None => a3,
        };
        self.fc4.forward_row(normed, Activation::Identity, out);
        log_softmax_in_place(out);
        out
    }
}

impl AcacActorVars {
    /// log_softmax(fc4) [K, actions] for x: [K, in] in flat order of `packing`.
    pub fn forward(&self, tape: &mut Tape, x: Var, packing: &SeqPacking) -> Var {
        let h = self.encoder.forward(tape, x, packing);
        let mut a3 = self.fc3.forward(tape, h, LEAKY);
        if let Some(ln) = &self.ln {
            a3 = ln.forward(tape, a3);
        }
        let logits = self.fc4.forward(tape, a3, Activation::Identity);
        tape.log_softmax(logits)
    }

    /// Copy the gradients into `into` (zero where none reached a tensor).
    pub fn grads_into(&self, tape: &Tape, into: &mut AcacActor) {
        self.encoder.grads_into(tape, &mut into.encoder);
        self.fc3.grads_into(tape, &mut into.fc3);
        if let (Some(v), Some(p)) = (&self.ln, &mut into.ln) {
            v.grads_into(tape, p);
        }
        self.fc4.grads_into(tape, &mut into.fc4);
    }
}

impl Params for AcacActor {
    fn slices(&self) -> Vec<&[f32]> {
        let mut out = self.encoder.slices();
        out.extend([flat(&self.fc3.weight), flat(&self.fc3.bias)]);
        if let Some(ln) = &self.ln {
            out.extend(ln.slices());
        }
        out.extend([flat(&self.fc4.weight), flat(&self.fc4.bias)]);
        out
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        let mut out = self.encoder.slices_mut();
        out.extend([flat_mut(&mut self.fc3.weight), flat_mut(&mut self.fc3.bias)]);
        if let Some(ln) = &mut self.ln {
            out.extend(ln.slices_mut());
        }
        out.extend([flat_mut(&mut self.fc4.weight), flat_mut(&mut self.fc4.bias)]);
        out
    }
}

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

/// PyTorch's `LayerNorm` on one row: (x - mean) / sqrt(var + eps) * weight + bias, biased var.
fn layer_norm_row(x: &[f32], ln: &LayerNormParams, out: &mut [f32]) {
    let n = x.len() as f32;
    let mean = x.iter().sum::<f32>() / n;
    let var = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / n;
    let inv = 1.0 / (var + ln.eps).sqrt();
    for (k, o) in out.iter_mut().enumerate() {
        *o = (x[k] - mean) * inv * ln.weight[k] + ln.bias[k];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn acting_steps_match_the_taped_forward() {
        // The one-row acting path (GRU state carried) against the taped sequence forward.
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let actor = AcacActor::new(5, [6, 4], 3, 7, true, &mut rng);
        let xs = Array2::from_shape_fn((4, 5), |(r, c)| ((r * 5 + c) as f32 * 0.37).sin());
        let mut tape = Tape::new();
        let vars = actor.bind(&mut tape);
        let x = tape.constant(xs.view());
        let y = vars.forward(&mut tape, x, &SeqPacking::new(&[4]));
        let taped = tape.value(y).to_owned();
        let mut state = actor.zero_state();
        for r in 0..4 {
            let row: Vec<f32> = xs.row(r).to_vec();
            let got = actor.act_step(&row, &mut state).to_vec();
            for (a, b) in got.iter().zip(taped.row(r)) {
                assert!((a - b).abs() < 1e-5, "row {r}: {a} vs {b}");
            }
        }
    }
}
