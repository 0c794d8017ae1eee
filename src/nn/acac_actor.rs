//! ACAC's actor (`models.py: AgentCentricGRUActor`, `share_encoder` false) and the GRU encoder it
//! shares in form with the critic's per-agent encoders (`GRUEncoder`), for acting and training:
//!
//! ```text
//! encoder (GRUEncoder):  x -> fc1 -> leaky_relu -> fc2 -> leaky_relu -> GRU
//! actor i:  [obs_i, temb(step + 1)] -> encoder -> fc3 -> leaky_relu -> ln? -> fc4 -> log_softmax
//! ```
//!
//! Leaky ReLU slope 0.01 (`F.leaky_relu`); fc1..fc3 Xavier-uniform with the leaky-ReLU gain,
//! fc4 gain 1, zero biases; the GRU PyTorch's default. An actor acting in an episode reads the
//! time too: [`TimedAcacActor`] is an actor with its time table, the net a policy file holds,
//! so evaluation, robots and the learner's own acting step it the same way ([`acting_input`]).

use ndarray::ArrayViewD;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::params::{flat, flat_mut};
use crate::autograd::{Activation, GruVars, SeqPacking, Tape, Var};
use crate::nn::init::LEAKY_RELU_GAIN;
use crate::nn::log_softmax_in_place;
use crate::nn::{
    GruParams, GruState, LayerNormParams, LayerNormVars, LinearParams, LinearVars, Params,
    StateDict, TimeEmbedding, WeightsError, LAYER_NORM_EPS,
};

/// The time table ACAC registers in every actor and critic (`time_embedding.weight`): a
/// training run holds it once (beside its nets), so the nets' own loaders skip it; a policy
/// file stores it with the actor ([`TimedAcacActor`]), as ACAC's `state_dict` does.
pub const TIME_TABLE: &str = "time_embedding.weight";

/// Tensor names of [`AcacActor`] in `state_dict` order, without the optional LayerNorm (`ln.*`,
/// between `fc3` and `fc4`) and the time table.
pub const ACAC_ACTOR_TENSOR_NAMES: [&str; 12] = [
    "encoder.fc1.weight",
    "encoder.fc1.bias",
    "encoder.fc2.weight",
    "encoder.fc2.bias",
    "encoder.gru.weight_ih_l0",
    "encoder.gru.weight_hh_l0",
    "encoder.gru.bias_ih_l0",
    "encoder.gru.bias_hh_l0",
    "fc3.weight",
    "fc3.bias",
    "fc4.weight",
    "fc4.bias",
];

const LEAKY: Activation = Activation::LEAKY_001;

/// The row of `time` an observation made after `step` primitive steps of its episode reads:
/// ACAC feeds the actors `t + 1` (its step counter has already advanced when it acts), capped
/// at the table's last row (beyond the horizon, which an episode never reaches).
pub fn time_row(time: &TimeEmbedding, step: usize) -> usize {
    step.saturating_add(1).min(time.table.nrows() - 1)
}

/// An actor's input for `obs` made after `step` primitive steps: the observation, then the
/// time table's row ([`time_row`]) when the actor reads the time. Written into `out`.
pub fn acting_input(obs: &[f32], time: Option<&TimeEmbedding>, step: usize, out: &mut Vec<f32>) {
    out.clear();
    out.extend_from_slice(obs);
    if let Some(t) = time {
        out.extend(t.table.row(time_row(t, step)).iter());
    }
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

    /// All-zero tensors of the same sizes (a gradient buffer).
    pub fn zeros_like(&self) -> Self {
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

    /// Every tensor's values, in `state_dict` order.
    pub fn slices(&self) -> Vec<&[f32]> {
        let mut out = vec![
            flat(&self.fc1.weight),
            flat(&self.fc1.bias),
            flat(&self.fc2.weight),
            flat(&self.fc2.bias),
        ];
        out.extend(self.gru.slices());
        out
    }

    /// Every tensor's values, mutable, in `state_dict` order.
    pub fn slices_mut(&mut self) -> Vec<&mut [f32]> {
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

    /// Copy the gradients into `into` (zero where none reached a tensor).
    pub fn grads_into(&self, tape: &Tape, into: &mut AcacEncoder) {
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
    /// The input row [`AcacActor::act_at`] builds.
    #[serde(skip)]
    input: Vec<f32>,
}

impl AcacActorState {
    /// Back to the zero state of an episode's start.
    pub fn reset(&mut self) {
        self.gru.reset();
    }

    /// Copy `other`'s recurrent state into `self` (same actor; scratch is not state).
    pub fn copy_from(&mut self, other: &AcacActorState) {
        self.gru.clone_from(&other.gru);
    }

    /// The GRU's hidden state.
    pub fn h(&self) -> &[f32] {
        self.gru.h()
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
            input: Vec::new(),
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

    /// One acting step on `obs` made after `step` primitive steps of the episode, reading the
    /// time from `time` when the actor does ([`acting_input`]): the plain log-probabilities;
    /// the state advances. Panics if the input has the wrong length.
    pub fn act_at<'s>(
        &self,
        obs: &[f32],
        time: Option<&TimeEmbedding>,
        step: usize,
        state: &'s mut AcacActorState,
    ) -> &'s [f32] {
        let mut input = std::mem::take(&mut state.input);
        acting_input(obs, time, step, &mut input);
        self.act_step(&input, state);
        state.input = input;
        state.scratch.last().expect("act_step filled the scratch")
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

/// An ACAC actor as a policy file holds it and an agent acts with it: the actor and the time
/// table it appends to every observation (none when the run's `time_emb_actor` is off). Its
/// `state_dict` is ACAC's `AgentCentricGRUActor`'s, time table included, so the file loads into
/// ACAC's module unchanged.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedAcacActor {
    /// The actor; its input is the observation plus the table's width.
    pub actor: AcacActor,
    /// The time table ([`TIME_TABLE`]).
    pub time: Option<TimeEmbedding>,
}

impl TimedAcacActor {
    /// Length of the observation it reads (the actor's input without the time embedding).
    pub fn obs_len(&self) -> usize {
        self.actor.input() - self.time.as_ref().map_or(0, TimeEmbedding::dim)
    }

    /// Macro-actions.
    pub fn n_actions(&self) -> usize {
        self.actor.n_actions()
    }

    /// One decision on `obs` made after `step` primitive steps ([`AcacActor::act_at`]).
    pub fn act_step<'s>(
        &self,
        obs: &[f32],
        step: usize,
        state: &'s mut AcacActorState,
    ) -> &'s [f32] {
        self.actor.act_at(obs, self.time.as_ref(), step, state)
    }

    /// Every tensor by ACAC's names: the actor's, then [`TIME_TABLE`].
    pub fn named(&self) -> Vec<(String, ArrayViewD<'_, f32>)> {
        let mut out = self.actor.named("");
        if let Some(t) = &self.time {
            out.extend(t.named("time_embedding."));
        }
        out
    }

    /// An `AgentCentricGRUActor`'s whole `state_dict` (its time table, when present, is the
    /// actor's). A table without rows is refused: every step reads one.
    pub fn from_state_dict(sd: &StateDict) -> Result<Self, WeightsError> {
        let actor = AcacActor::from_state_dict(sd, "")?;
        let time = if sd.has(TIME_TABLE) {
            let (rows, dim) = sd.shape2(TIME_TABLE)?;
            if rows == 0 || dim >= actor.input() {
                return Err(WeightsError::Shape {
                    path: sd.path().to_path_buf(),
                    name: TIME_TABLE.to_string(),
                    found: vec![rows, dim],
                    expected: vec![rows.max(1), actor.input().saturating_sub(1)],
                });
            }
            Some(TimeEmbedding::from_state_dict(sd, "time_embedding.")?)
        } else {
            None
        };
        Ok(TimedAcacActor { actor, time })
    }

    /// Every tensor's name and PyTorch shape for an actor of these sizes, in `state_dict` order
    /// (`Linear.weight` is `[out, in]`, the GRU stacks its gates in `3H` rows); `time` is the
    /// table's `(rows, dim)`.
    pub fn tensor_shapes(
        obs_len: usize,
        mlp: [usize; 2],
        hidden: usize,
        n_actions: usize,
        layer_norm: bool,
        time: Option<(usize, usize)>,
    ) -> Vec<(&'static str, Vec<usize>)> {
        let input = obs_len + time.map_or(0, |(_, dim)| dim);
        let [m0, m1] = mlp;
        let shapes = [
            vec![m0, input],
            vec![m0],
            vec![m0, m0],
            vec![m0],
            vec![3 * hidden, m0],
            vec![3 * hidden, hidden],
            vec![3 * hidden],
            vec![3 * hidden],
            vec![m1, hidden],
            vec![m1],
            vec![n_actions, m1],
            vec![n_actions],
        ];
        let mut out: Vec<(&'static str, Vec<usize>)> =
            ACAC_ACTOR_TENSOR_NAMES.into_iter().zip(shapes).collect();
        if layer_norm {
            let fc4 = out.split_off(10);
            out.extend([("ln.weight", vec![m1]), ("ln.bias", vec![m1])]);
            out.extend(fc4);
        }
        if let Some((rows, dim)) = time {
            out.push((TIME_TABLE, vec![rows, dim]));
        }
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
    use ndarray::Array2;
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

    fn timed(layer_norm: bool, time: bool) -> TimedAcacActor {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let dim = if time { 4 } else { 0 };
        TimedAcacActor {
            actor: AcacActor::new(3 + dim, [6, 5], 4, 7, layer_norm, &mut rng),
            time: time.then(|| TimeEmbedding::sinusoidal(6, dim).unwrap()),
        }
    }

    #[test]
    fn a_timed_actor_round_trips_through_acacs_state_dict_names_and_shapes() {
        use crate::nn::safetensors_io::named_to_safetensors_bytes;
        for (ln, time) in [(true, true), (false, true), (true, false), (false, false)] {
            let net = timed(ln, time);
            let named = net.named();
            // The shape table the policy files size a file by is the net's own layout.
            let shapes = TimedAcacActor::tensor_shapes(
                3,
                [6, 5],
                4,
                7,
                ln,
                net.time.as_ref().map(|t| (t.table.nrows(), t.dim())),
            );
            let got: Vec<(String, Vec<usize>)> = named
                .iter()
                .map(|(n, v)| (n.clone(), v.shape().to_vec()))
                .collect();
            let want: Vec<(String, Vec<usize>)> = shapes
                .into_iter()
                .map(|(n, s)| (n.to_string(), s))
                .collect();
            assert_eq!(got, want, "ln {ln} time {time}");
            let bytes = named_to_safetensors_bytes(&named);
            let sd = StateDict::parse(&bytes, std::path::Path::new("x")).unwrap();
            let back = TimedAcacActor::from_state_dict(&sd).unwrap();
            assert_eq!(back, net);
            assert_eq!(back.obs_len(), 3);
        }
    }

    #[test]
    fn an_agent_reads_row_step_plus_one_of_the_table_capped_at_its_last() {
        let net = timed(true, true);
        let table = &net.time.as_ref().unwrap().table;
        assert_eq!(table.nrows(), 11);
        let obs = [0.25, -1.0, 0.5];
        for (step, row) in [(0, 1), (3, 4), (9, 10), (10, 10), (500, 10)] {
            let mut by_step = net.actor.zero_state();
            let got = net.act_step(&obs, step, &mut by_step).to_vec();
            let mut by_row = net.actor.zero_state();
            let x: Vec<f32> = obs.iter().chain(table.row(row).iter()).copied().collect();
            assert_eq!(got, net.actor.act_step(&x, &mut by_row), "step {step}");
            // A neighbouring row gives other scores: the step is really read.
            let other: Vec<f32> = obs
                .iter()
                .chain(table.row(row - 1).iter())
                .copied()
                .collect();
            let mut by_other = net.actor.zero_state();
            assert_ne!(
                got,
                net.actor.act_step(&other, &mut by_other),
                "step {step}"
            );
        }
        // Without a table the step is not read.
        let plain = timed(true, false);
        let (mut a, mut b) = (plain.actor.zero_state(), plain.actor.zero_state());
        assert_eq!(
            plain.act_step(&obs, 0, &mut a).to_vec(),
            plain.act_step(&obs, 77, &mut b)
        );
    }

    #[test]
    fn a_state_dict_with_an_empty_or_too_wide_time_table_is_refused() {
        use crate::nn::safetensors_io::named_to_safetensors_bytes;
        let net = timed(true, true);
        let mut named = net.actor.named("");
        let empty = ndarray::Array2::<f32>::zeros((0, 4));
        named.push((TIME_TABLE.to_string(), empty.view().into_dyn()));
        let bytes = named_to_safetensors_bytes(&named);
        let sd = StateDict::parse(&bytes, std::path::Path::new("x")).unwrap();
        let err = TimedAcacActor::from_state_dict(&sd)
            .unwrap_err()
            .to_string();
        assert!(err.contains(TIME_TABLE), "{err}");
        let mut named = net.actor.named("");
        let wide = ndarray::Array2::<f32>::zeros((11, 7));
        named.push((TIME_TABLE.to_string(), wide.view().into_dyn()));
        let bytes = named_to_safetensors_bytes(&named);
        let sd = StateDict::parse(&bytes, std::path::Path::new("x")).unwrap();
        assert!(TimedAcacActor::from_state_dict(&sd).is_err());
    }
}
