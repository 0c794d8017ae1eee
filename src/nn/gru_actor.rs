//! MacroMARL's recurrent actor (`docs/MACROMARL.md` §2.4, `cores/pg_based/mac_iac/models.py:
//! Actor`): the authors' trained actors run here, greedy or sampled, and the actor-critic
//! learners train it. Its history critic (`models.py: Critic`) is the same layers with one output
//! and no log_softmax, so it is this type too ([`GruActor::forward`] gives fc4's output).
//!
//! ```text
//! obs -> fc1 (in -> m0) -> leaky_relu(0.01) -> fc2 (m0 -> m0) -> leaky_relu -> GRU (m0 -> H)
//!     -> fc3 (H -> m1) -> leaky_relu -> fc4 (m1 -> actions) -> log_softmax
//! ```
//!
//! Unlike the ICRA Q-net, fc2 keeps width m0 and the recurrent layer is a GRU. The weight file is
//! the module's `state_dict` under its own names (`fc1.weight`, ..., `gru.weight_ih_l0`, ...), so
//! `scripts/torch_to_safetensors.py` converts the shipped `agent_state_dict*.pt` files as they
//! are. The eps-mixture the reference applies while training is not part of acting
//! (`test_mode`), so it is not here.

use std::path::Path;

use ndarray::{Array2, ArrayView2, ArrayViewD};

use rand_chacha::ChaCha8Rng;

use super::gru::GruState;
use super::init::LEAKY_RELU_GAIN;
use super::linear::LinearVars;
use super::params::{flat, flat_mut, GruParams, LinearParams, Params};
use super::safetensors_io::{read_exact, tensor_shape, WeightsError};
use crate::autograd::kernels::dense::{linear_forward, linear_forward_at, matvec_act_rows};
use crate::autograd::kernels::exp::{sum_exp_f32, sum_exp_f32_rows4};
use crate::autograd::kernels::gru::{gru_step, GruWeights};
use crate::autograd::{Activation, GruVars, SeqPacking, Tape, Var};

/// The actor's tensors, in its `state_dict` order.
pub const GRU_ACTOR_TENSOR_NAMES: [&str; 12] = [
    "fc1.weight",
    "fc1.bias",
    "fc2.weight",
    "fc2.bias",
    "gru.weight_ih_l0",
    "gru.weight_hh_l0",
    "gru.bias_ih_l0",
    "gru.bias_hh_l0",
    "fc3.weight",
    "fc3.bias",
    "fc4.weight",
    "fc4.bias",
];

/// The actor's sizes: its input, the MLP widths m0 (fc1, fc2) and m1 (fc3), the GRU's hidden
/// size H and the number of macro-actions (MacroMARL's `a_mlp_layer_size = [m0, m1]` and
/// `a_rnn_layer_size = H`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GruActorConfig {
    /// Input features: the agent's (or the joint) observation length.
    pub input: usize,
    /// [m0, m1]: widths of fc1 and fc2 (m0) and of fc3 (m1).
    pub mlp: [usize; 2],
    /// H: the GRU's hidden size.
    pub hidden: usize,
    /// One log-probability per (joint) macro-action.
    pub output: usize,
}

impl GruActorConfig {
    /// Each tensor's PyTorch shape, in [`GRU_ACTOR_TENSOR_NAMES`] order.
    pub fn tensor_shapes(&self) -> [Vec<usize>; 12] {
        let ([m0, m1], h) = (self.mlp, self.hidden);
        [
            vec![m0, self.input],
            vec![m0],
            vec![m0, m0],
            vec![m0],
            vec![3 * h, m0],
            vec![3 * h, h],
            vec![3 * h],
            vec![3 * h],
            vec![m1, h],
            vec![m1],
            vec![self.output, m1],
            vec![self.output],
        ]
    }
}

/// The actor's parameters (also the history critic's, with one output).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GruActor {
    fc1: LinearParams,
    fc2: LinearParams,
    gru: GruParams,
    fc3: LinearParams,
    fc4: LinearParams,
}

/// One agent's recurrent state while acting, with the scratch the forward writes into (acting
/// never allocates after the first step).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GruActorState {
    gru: GruState,
    a1: Vec<f32>,
    a2: Vec<f32>,
    a3: Vec<f32>,
    out: Vec<f32>,
}

impl GruActorState {
    /// Back to the zero state, as at the start of an episode.
    pub fn reset(&mut self) {
        self.gru.reset();
    }

    /// The GRU's hidden state h: \[H\].
    pub fn h(&self) -> &[f32] {
        self.gru.h()
    }

    /// Copy `other` (same sizes) into `self`.
    pub fn copy_from(&mut self, other: &GruActorState) {
        self.clone_from(other);
    }
}

const LEAKY: Activation = Activation::LEAKY_001;

impl GruActor {
    /// The sizes.
    pub fn config(&self) -> GruActorConfig {
        GruActorConfig {
            input: self.fc1.input(),
            mlp: [self.fc1.output(), self.fc3.output()],
            hidden: self.gru.hidden(),
            output: self.fc4.output(),
        }
    }

    /// Every tensor with its `state_dict` name, in [`GRU_ACTOR_TENSOR_NAMES`] order.
    pub fn named(&self) -> [(&'static str, ArrayViewD<'_, f32>); 12] {
        let n = GRU_ACTOR_TENSOR_NAMES;
        [
            (n[0], self.fc1.weight.view().into_dyn()),
            (n[1], self.fc1.bias.view().into_dyn()),
            (n[2], self.fc2.weight.view().into_dyn()),
            (n[3], self.fc2.bias.view().into_dyn()),
            (n[4], self.gru.weight_ih.view().into_dyn()),
            (n[5], self.gru.weight_hh.view().into_dyn()),
            (n[6], self.gru.bias_ih.view().into_dyn()),
            (n[7], self.gru.bias_hh.view().into_dyn()),
            (n[8], self.fc3.weight.view().into_dyn()),
            (n[9], self.fc3.bias.view().into_dyn()),
            (n[10], self.fc4.weight.view().into_dyn()),
            (n[11], self.fc4.bias.view().into_dyn()),
        ]
    }

    /// The actor a safetensors file holds, its sizes read from `fc1.weight` [m0, in],
    /// `gru.weight_hh_l0` [3H, H], `fc3.weight` [m1, H] and `fc4.weight` [actions, m1]: exactly
    /// the twelve tensors, F32, of consistent shapes. `origin` labels errors.
    pub fn from_safetensors_bytes(bytes: &[u8], origin: &Path) -> Result<GruActor, WeightsError> {
        let [fc1, hh, fc3, fc4] = ["fc1.weight", "gru.weight_hh_l0", "fc3.weight", "fc4.weight"]
            .map(|name| tensor_shape(bytes, origin, name));
        let (fc1, hh, fc3, fc4) = (fc1?, hh?, fc3?, fc4?);
        let dim = |s: &[usize], k: usize| s.get(k).copied().unwrap_or(0);
        let cfg = GruActorConfig {
            input: dim(&fc1, 1),
            mlp: [dim(&fc1, 0), dim(&fc3, 0)],
            hidden: dim(&hh, 1),
            output: dim(&fc4, 0),
        };
        Self::from_safetensors_bytes_sized(bytes, cfg, origin)
    }

    /// [`Self::from_safetensors_bytes`] for known sizes `cfg`: every shape must match them.
    pub fn from_safetensors_bytes_sized(
        bytes: &[u8],
        cfg: GruActorConfig,
        origin: &Path,
    ) -> Result<GruActor, WeightsError> {
        let expected: Vec<(&'static str, Vec<usize>)> = GRU_ACTOR_TENSOR_NAMES
            .into_iter()
            .zip(cfg.tensor_shapes())
            .collect();
        let mut t = read_exact(bytes, origin, "GRU actor", &expected)?.into_iter();
        let ([m0, m1], h) = (cfg.mlp, cfg.hidden);
        let fc1 = take_linear(&mut t, cfg.input, m0);
        let fc2 = take_linear(&mut t, m0, m0);
        let mut gru = GruParams::zeros(m0, h);
        for slot in [
            gru.weight_ih.as_slice_mut(),
            gru.weight_hh.as_slice_mut(),
            gru.bias_ih.as_slice_mut(),
            gru.bias_hh.as_slice_mut(),
        ] {
            slot.expect("fresh array")
                .copy_from_slice(&t.next().expect("twelve tensors"));
        }
        let fc3 = take_linear(&mut t, h, m1);
        let fc4 = take_linear(&mut t, m1, cfg.output);
        Ok(GruActor {
            fc1,
            fc2,
            gru,
            fc3,
            fc4,
        })
    }

    /// A zero recurrent state sized for this actor.
    pub fn zero_state(&self) -> GruActorState {
        let cfg = self.config();
        GruActorState {
            gru: GruState::zeros(cfg.hidden),
            a1: vec![0.0; cfg.mlp[0]],
            a2: vec![0.0; cfg.mlp[0]],
            a3: vec![0.0; cfg.mlp[1]],
            out: vec![0.0; cfg.output],
        }
    }

    /// One acting step: the log-probabilities of the macro-actions for input x given the
    /// carried state, which advances (the reference's `test_mode` forward with its hidden state
    /// kept between the agent's decisions). Panics if x or the state do not match the sizes.
    pub fn act_step<'s>(&self, x: &[f32], state: &'s mut GruActorState) -> &'s [f32] {
        self.hidden_step(x, state);
        self.fc4
            .forward_row(&state.a3, Activation::Identity, &mut state.out);
        log_softmax_in_place(&mut state.out);
        &state.out
    }

    /// [`Self::act_step`] up to the output layer: fc1, fc2, the GRU step (the state advances)
    /// and fc3, whose output \[m1\] it returns. [`Self::log_probs_rows`] finishes several such
    /// steps at once.
    pub fn hidden_step<'s>(&self, x: &[f32], state: &'s mut GruActorState) -> &'s [f32] {
        assert_eq!(x.len(), self.fc1.input(), "act_step: input length");
        self.fc1.forward_row(x, LEAKY, &mut state.a1);
        self.fc2.forward_row(&state.a1, LEAKY, &mut state.a2);
        self.gru.step(&state.a2, &mut state.gru);
        self.fc3.forward_row(state.gru.h(), LEAKY, &mut state.a3);
        &state.a3
    }

    /// The rest of [`Self::act_step`] for several steps at once: fc4 and the log_softmax of
    /// each row of `hidden` (rows of m1, each a [`Self::hidden_step`] output) into the same row
    /// of `logp` (rows of the output size), each row bit for bit what `act_step` returns. fc4
    /// is read once for all rows: Mac-CAC's is 64 x 3 375 weights, larger than the caches, and
    /// reading it once per deciding lane was a quarter of a 3-agent Overcooked run. Panics if
    /// the lengths are not whole rows of the same count.
    pub fn log_probs_rows(&self, hidden: &[f32], logp: &mut [f32]) {
        let cfg = self.config();
        matvec_act_rows(
            flat(&self.fc4.weight),
            cfg.mlp[1],
            hidden,
            flat(&self.fc4.bias),
            1.0,
            logp,
        );
        log_softmax_rows_in_place(logp, cfg.output);
    }

    /// One acting step like [`Self::act_step`] but giving fc4's raw outputs (no log_softmax):
    /// the Q-values when the net is MacroMARL's value-based `DDRQN`, which has these layers.
    pub fn q_step<'s>(&self, x: &[f32], state: &'s mut GruActorState) -> &'s [f32] {
        assert_eq!(x.len(), self.fc1.input(), "q_step: input length");
        self.fc1.forward_row(x, LEAKY, &mut state.a1);
        self.fc2.forward_row(&state.a1, LEAKY, &mut state.a2);
        self.gru.step(&state.a2, &mut state.gru);
        self.fc3.forward_row(state.gru.h(), LEAKY, &mut state.a3);
        self.fc4
            .forward_row(&state.a3, Activation::Identity, &mut state.out);
        &state.out
    }

    /// The GRU's parameters.
    pub fn gru(&self) -> &GruParams {
        &self.gru
    }
}

/// A [`GruActor`]'s parameters on a tape, from [`GruActor::bind`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GruActorVars {
    fc1: LinearVars,
    fc2: LinearVars,
    gru: GruVars,
    fc3: LinearVars,
    fc4: LinearVars,
}

impl GruActor {
    /// A freshly initialized net (`docs/ALGORITHMS.md` §2.4): Xavier-uniform with the leaky-ReLU gain on fc1..fc3,
    /// gain 1 on fc4, zero Linear biases, PyTorch's GRU default; drawn in module order.
    pub fn new(cfg: GruActorConfig, rng: &mut ChaCha8Rng) -> Self {
        let ([m0, m1], h) = (cfg.mlp, cfg.hidden);
        GruActor {
            fc1: LinearParams::xavier(cfg.input, m0, LEAKY_RELU_GAIN, rng),
            fc2: LinearParams::xavier(m0, m0, LEAKY_RELU_GAIN, rng),
            gru: GruParams::pytorch_default(m0, h, rng),
            fc3: LinearParams::xavier(h, m1, LEAKY_RELU_GAIN, rng),
            fc4: LinearParams::xavier(m1, cfg.output, 1.0, rng),
        }
    }

    /// All-zero tensors of these sizes (a gradient buffer).
    pub fn zeros(cfg: GruActorConfig) -> Self {
        let ([m0, m1], h) = (cfg.mlp, cfg.hidden);
        GruActor {
            fc1: LinearParams::zeros(cfg.input, m0),
            fc2: LinearParams::zeros(m0, m0),
            gru: GruParams::zeros(m0, h),
            fc3: LinearParams::zeros(h, m1),
            fc4: LinearParams::zeros(m1, cfg.output),
        }
    }

    /// Put the parameters on `tape` as trainable leaves.
    pub fn bind(&self, tape: &mut Tape) -> GruActorVars {
        GruActorVars {
            fc1: self.fc1.bind(tape),
            fc2: self.fc2.bind(tape),
            gru: self.gru.bind(tape),
            fc3: self.fc3.bind(tape),
            fc4: self.fc4.bind(tape),
        }
    }

    /// fc4's output [K, out] for every position of a batch of sequences, each unrolled from a
    /// zero state, with x: [K, in] in packed order (see [`SeqPacking`]); the result is in the
    /// same order. The reference runs padded batches; padding sits after each sequence and the
    /// GRU is causal, so the valid positions are the same numbers.
    pub fn forward(
        &self,
        tape: &mut Tape,
        vars: &GruActorVars,
        x: Var,
        packing: &SeqPacking,
    ) -> Var {
        self.forward_with_hidden(tape, vars, x, packing).0
    }

    /// [`Self::forward`]'s output and the GRU's output h: [K, H] it came from (packed order),
    /// from which [`Self::continue_rows`] goes on.
    pub fn forward_with_hidden(
        &self,
        tape: &mut Tape,
        vars: &GruActorVars,
        x: Var,
        packing: &SeqPacking,
    ) -> (Var, Var) {
        let (a3, h) = self.features(tape, vars, x, packing);
        (vars.fc4.forward(tape, a3, Activation::Identity), h)
    }

    /// fc4's output at column `col` for one row `a3` of [`Self::features`]: the bits
    /// [`Self::forward`] gives there, at the cost of one dot product instead of the layer.
    pub fn output_at(&self, a3: &[f32], col: usize) -> f32 {
        let p = &self.fc4;
        linear_forward_at(
            a3,
            p.weight.view(),
            flat(&p.bias),
            Activation::Identity,
            col,
        )
    }

    /// fc4's output at column `cols[r]` of each row r of `a3` ([`Self::features`] on `tape`):
    /// [r, 1], [`Tape::linear_at`] (the value of the action taken, whose gradient reaches one
    /// row of fc4 per row instead of all of them).
    pub fn output_taken(
        &self,
        tape: &mut Tape,
        vars: &GruActorVars,
        a3: Var,
        cols: &[usize],
    ) -> Var {
        tape.linear_at(a3, vars.fc4.weight, vars.fc4.bias, cols)
    }

    /// fc4's output over rows `a3` of [`Self::features`] without the tape: the bits of
    /// [`Self::forward`].
    pub fn output_rows(&self, a3: ArrayView2<f32>) -> Array2<f32> {
        layer_rows(&self.fc4, a3, Activation::Identity)
    }

    /// What fc4 reads, leaky(fc3(h)): [K, m1], and the GRU's output h: [K, H] (packed order):
    /// [`Self::forward_with_hidden`] short of its last layer, for a caller that needs fc4 at one
    /// column per row ([`crate::autograd::kernels::dense::linear_forward_at`] gives the same
    /// bits as the whole layer there).
    pub fn features(
        &self,
        tape: &mut Tape,
        vars: &GruActorVars,
        x: Var,
        packing: &SeqPacking,
    ) -> (Var, Var) {
        let a1 = vars.fc1.forward(tape, x, LEAKY);
        let a2 = vars.fc2.forward(tape, a1, LEAKY);
        let h = vars.gru.forward_packed(tape, a2, packing);
        (vars.fc3.forward(tape, h, LEAKY), h)
    }

    /// fc4's output [n, out] one step past the ends of n sequences, values only (no tape): x:
    /// [n, in] each sequence's next input, h: [n, H] the GRU's output at its last position (from
    /// [`Self::forward_with_hidden`]). It runs the kernels the taped forward runs, each row on
    /// its own, so row i has the bits [`Self::forward`] gives sequence i made one step longer
    /// with that input. Panics if the sizes do not match the net.
    pub fn continue_rows(&self, x: ArrayView2<f32>, h: ArrayView2<f32>) -> Array2<f32> {
        let a1 = layer_rows(&self.fc1, x, LEAKY);
        let a2 = layer_rows(&self.fc2, a1.view(), LEAKY);
        let g = &self.gru;
        let weights = GruWeights {
            w_ih: g.weight_ih.view(),
            w_hh: g.weight_hh.view(),
            b_ih: flat(&g.bias_ih),
            b_hh: flat(&g.bias_hh),
        };
        let mut h_next = Array2::zeros((x.nrows(), self.config().hidden));
        gru_step(a2.view(), &weights, h, &mut h_next);
        let a3 = layer_rows(&self.fc3, h_next.view(), LEAKY);
        self.output_rows(a3.view())
    }
}

/// Layer `p` over rows `x` without the tape (the taped layer's kernel, so its bits).
fn layer_rows(p: &LinearParams, x: ArrayView2<f32>, act: Activation) -> Array2<f32> {
    let mut y = Array2::zeros((x.nrows(), p.output()));
    linear_forward(x, p.weight.view(), flat(&p.bias), act, y.view_mut());
    y
}

impl GruActorVars {
    /// Copy the gradients from the tape into `into` (zero where none reached a tensor).
    pub fn grads_into(&self, tape: &Tape, into: &mut GruActor) {
        self.fc1.grads_into(tape, &mut into.fc1);
        self.fc2.grads_into(tape, &mut into.fc2);
        self.gru.grads_into(tape, &mut into.gru);
        self.fc3.grads_into(tape, &mut into.fc3);
        self.fc4.grads_into(tape, &mut into.fc4);
    }
}

impl Params for GruActor {
    fn slices(&self) -> Vec<&[f32]> {
        let g = &self.gru;
        vec![
            flat(&self.fc1.weight),
            flat(&self.fc1.bias),
            flat(&self.fc2.weight),
            flat(&self.fc2.bias),
            flat(&g.weight_ih),
            flat(&g.weight_hh),
            flat(&g.bias_ih),
            flat(&g.bias_hh),
            flat(&self.fc3.weight),
            flat(&self.fc3.bias),
            flat(&self.fc4.weight),
            flat(&self.fc4.bias),
        ]
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        let g = &mut self.gru;
        vec![
            flat_mut(&mut self.fc1.weight),
            flat_mut(&mut self.fc1.bias),
            flat_mut(&mut self.fc2.weight),
            flat_mut(&mut self.fc2.bias),
            flat_mut(&mut g.weight_ih),
            flat_mut(&mut g.weight_hh),
            flat_mut(&mut g.bias_ih),
            flat_mut(&mut g.bias_hh),
            flat_mut(&mut self.fc3.weight),
            flat_mut(&mut self.fc3.bias),
            flat_mut(&mut self.fc4.weight),
            flat_mut(&mut self.fc4.bias),
        ]
    }
}

/// The next two tensors (weight, bias) of `t` as a layer from `input` to `output` features;
/// their shapes were checked by [`read_exact`].
fn take_linear(
    t: &mut impl Iterator<Item = Vec<f32>>,
    input: usize,
    output: usize,
) -> LinearParams {
    let mut p = LinearParams::zeros(input, output);
    for slot in [p.weight.as_slice_mut(), p.bias.as_slice_mut()] {
        slot.expect("fresh array")
            .copy_from_slice(&t.next().expect("a weight and a bias"));
    }
    p
}

/// x <- x - max - log(sum(exp(x - max))), as `torch.log_softmax` computes it (ACAC's acting
/// actors use it too): the sum in f32, in order, of glibc's `expf` of each difference.
pub(crate) fn log_softmax_in_place(x: &mut [f32]) {
    let max = x.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    finish_log_softmax(x, max, sum_exp_f32(x, max));
}

/// [`log_softmax_in_place`] on each row of `rows` (rows of `n`), four rows' sums side by side
/// (each row's additions in its own order, so each row's bits are the one-row function's).
pub(crate) fn log_softmax_rows_in_place(rows: &mut [f32], n: usize) {
    if n == 0 {
        return;
    }
    let mut quads = rows.chunks_exact_mut(4 * n);
    for quad in &mut quads {
        let (a, rest) = quad.split_at_mut(n);
        let (b, rest) = rest.split_at_mut(n);
        let (c, d) = rest.split_at_mut(n);
        let max = |r: &[f32]| r.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let maxes = [max(a), max(b), max(c), max(d)];
        let sums = sum_exp_f32_rows4([a, b, c, d], maxes);
        for (k, row) in [a, b, c, d].into_iter().enumerate() {
            finish_log_softmax(row, maxes[k], sums[k]);
        }
    }
    for row in quads.into_remainder().chunks_exact_mut(n) {
        log_softmax_in_place(row);
    }
}

/// x <- x - max - ln(sum).
fn finish_log_softmax(x: &mut [f32], max: f32, sum: f32) {
    let lse = sum.ln();
    for v in x.iter_mut() {
        *v = *v - max - lse;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::safetensors_io::named_to_safetensors_bytes;
    use rand::SeedableRng;

    /// An actor whose every element is a small deterministic function of its name and index.
    fn actor(cfg: GruActorConfig) -> Vec<u8> {
        let data: Vec<(&'static str, Vec<usize>, Vec<f32>)> = GRU_ACTOR_TENSOR_NAMES
            .into_iter()
            .zip(cfg.tensor_shapes())
            .enumerate()
            .map(|(k, (name, shape))| {
                let n: usize = shape.iter().product();
                let values = (0..n)
                    .map(|i| (((i * 7 + k * 13) % 17) as f32 - 8.0) / 40.0)
                    .collect();
                (name, shape, values)
            })
            .collect();
        let arrays: Vec<(&'static str, ndarray::ArrayD<f32>)> = data
            .into_iter()
            .map(|(n, s, v)| (n, ndarray::ArrayD::from_shape_vec(s, v).unwrap()))
            .collect();
        let views: Vec<(&'static str, ArrayViewD<'_, f32>)> =
            arrays.iter().map(|(n, a)| (*n, a.view())).collect();
        named_to_safetensors_bytes(&views)
    }

    const CFG: GruActorConfig = GruActorConfig {
        input: 5,
        mlp: [6, 4],
        hidden: 3,
        output: 8,
    };

    #[test]
    fn sizes_come_from_the_file_and_bytes_round_trip() {
        let bytes = actor(CFG);
        let a = GruActor::from_safetensors_bytes(&bytes, Path::new("a")).unwrap();
        assert_eq!(a.config(), CFG);
        assert_eq!(named_to_safetensors_bytes(&a.named()), bytes);
    }

    #[test]
    fn a_step_is_the_layers_composed_and_a_distribution() {
        let a = GruActor::from_safetensors_bytes(&actor(CFG), Path::new("a")).unwrap();
        let mut s = a.zero_state();
        let x = [0.0, 1.0, 0.0, 0.5, -1.0];
        let first = a.act_step(&x, &mut s).to_vec();
        let total: f32 = first.iter().map(|v| v.exp()).sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        // The same layers by hand, with the bare GRU's own step.
        let mut a1 = vec![0.0; 6];
        let mut a2 = vec![0.0; 6];
        a.fc1.forward_row(&x, LEAKY, &mut a1);
        a.fc2.forward_row(&a1, LEAKY, &mut a2);
        let mut g = GruState::zeros(3);
        a.gru().step(&a2, &mut g);
        assert_eq!(s.h(), g.h());
        // The state carries: a second step from it differs from a step from zero.
        let second = a.act_step(&x, &mut s).to_vec();
        let mut fresh = a.zero_state();
        assert_eq!(a.act_step(&x, &mut fresh), first.as_slice());
        assert_ne!(second, first);
        s.reset();
        assert_eq!(a.act_step(&x, &mut s), first.as_slice());
    }

    #[test]
    fn log_softmax_rows_are_the_definition_with_the_platform_expf() {
        use rand::Rng;
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for (n_rows, n) in [(1, 1), (3, 15), (4, 15), (7, 37), (9, 3375)] {
            let x: Vec<f32> = (0..n_rows * n)
                .map(|k| match k % 97 {
                    5 => f32::NEG_INFINITY,
                    9 => -150.0,
                    _ => rng.gen_range(-30.0..30.0),
                })
                .collect();
            let mut want = x.clone();
            for row in want.chunks_exact_mut(n) {
                let max = row.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                let sum: f32 = row.iter().map(|v| (v - max).exp()).sum();
                let lse = sum.ln();
                row.iter_mut().for_each(|v| *v = *v - max - lse);
            }
            let mut got = x.clone();
            log_softmax_rows_in_place(&mut got, n);
            let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&want), "{n_rows} rows of {n}");
            let mut one = x[..n].to_vec();
            log_softmax_in_place(&mut one);
            assert_eq!(bits(&one), bits(&want[..n]), "one row of {n}");
        }
    }

    #[test]
    fn several_steps_finished_together_are_each_act_step_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let cfg = GruActorConfig {
            input: 7,
            mlp: [16, 12],
            hidden: 9,
            output: 45,
        };
        let a = GruActor::new(cfg, &mut rng);
        let xs: Vec<Vec<f32>> = (0..4)
            .map(|l| (0..7).map(|j| ((l * 7 + j) as f32 * 0.37).sin()).collect())
            .collect();
        let (mut one, mut rows) = (Vec::new(), Vec::new());
        let mut hidden = Vec::new();
        for x in &xs {
            // Two steps each, so the carried state matters.
            let (mut s, mut t) = (a.zero_state(), a.zero_state());
            a.act_step(x, &mut s);
            one.extend_from_slice(a.act_step(x, &mut s));
            a.act_step(x, &mut t);
            hidden.extend_from_slice(a.hidden_step(x, &mut t));
            rows.push(t);
        }
        let mut logp = vec![f32::NAN; 4 * 45];
        a.log_probs_rows(&hidden, &mut logp);
        let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&logp), bits(&one));
    }

    #[test]
    fn matches_pytorch_step_by_step_with_the_state_carried() {
        // tests/fixtures/gru_actor_torch.{json,safetensors}, written by
        // scripts/gru_actor_fixture_from_torch.py from a PyTorch module of the actor's shape.
        let want: serde_json::Value =
            serde_json::from_str(include_str!("../../tests/fixtures/gru_actor_torch.json"))
                .unwrap();
        let bytes = include_bytes!("../../tests/fixtures/gru_actor_torch.safetensors");
        let a = GruActor::from_safetensors_bytes(bytes, Path::new("fixture")).unwrap();
        assert_eq!(
            a.config(),
            GruActorConfig {
                input: 5,
                mlp: [6, 4],
                hidden: 3,
                output: 8
            }
        );
        let floats = |v: &serde_json::Value| -> Vec<f32> {
            v.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() as f32)
                .collect()
        };
        let mut s = a.zero_state();
        let steps = want["steps"].as_array().unwrap();
        for (obs, step) in want["obs"].as_array().unwrap().iter().zip(steps) {
            let got = a.act_step(&floats(obs), &mut s).to_vec();
            for (g, w) in got.iter().zip(floats(&step["log_probs"])) {
                assert!(
                    (g - w).abs() < 1e-5,
                    "log-probs {got:?} vs {:?}",
                    step["log_probs"]
                );
            }
            for (g, w) in s.h().iter().zip(floats(&step["h"])) {
                assert!((g - w).abs() < 1e-5, "h {:?} vs {:?}", s.h(), step["h"]);
            }
        }
        assert_eq!(steps.len(), 5);
    }

    #[test]
    fn inconsistent_or_foreign_files_name_the_tensor() {
        let bytes = actor(CFG);
        let other = GruActorConfig { output: 7, ..CFG };
        let err =
            GruActor::from_safetensors_bytes_sized(&bytes, other, Path::new("a")).unwrap_err();
        assert!(err.to_string().contains("fc4.weight"), "{err}");
        let q = crate::nn::safetensors_io::to_safetensors_bytes(&crate::nn::QNetParams::zeros(
            crate::nn::QNetConfig {
                input: 5,
                mlp: 4,
                hidden: 3,
                output: 8,
            },
        ));
        let err = GruActor::from_safetensors_bytes(&q, Path::new("q")).unwrap_err();
        assert!(err.to_string().contains("gru.weight_hh_l0"), "{err}");
    }

    #[test]
    fn continuing_from_the_last_h_gives_the_bits_of_a_longer_unroll() {
        use ndarray::Axis;
        use rand::SeedableRng;
        // Widths past one vector of lanes and not a multiple of it, ragged lengths.
        let cfg = GruActorConfig {
            input: 7,
            mlp: [33, 20],
            hidden: 19,
            output: 5,
        };
        let net = GruActor::new(cfg, &mut ChaCha8Rng::seed_from_u64(5));
        let short = [4, 1, 3, 4];
        let long: Vec<usize> = short.iter().map(|l| l + 1).collect();
        let starts: Vec<usize> = long
            .iter()
            .scan(0, |at, &l| {
                *at += l;
                Some(*at - l)
            })
            .collect();
        let x = Array2::from_shape_fn((long.iter().sum(), cfg.input), |(i, j)| {
            ((i * 31 + j * 7) as f32 * 0.37).sin()
        });
        // Unroll sequences of `lengths`, sequence s from x's row starts[s]: (out, h) in flat order.
        let unroll = |lengths: &[usize]| {
            let mut tape = Tape::new();
            let vars = net.bind(&mut tape);
            let packing = SeqPacking::new(lengths);
            let rows: Vec<usize> = lengths
                .iter()
                .zip(&starts)
                .flat_map(|(&l, &s)| s..s + l)
                .collect();
            let packed: Vec<usize> = packing.packed_to_flat().iter().map(|&f| rows[f]).collect();
            let xv = tape.constant(x.select(Axis(0), &packed).view());
            let (out, h) = net.forward_with_hidden(&mut tape, &vars, xv, &packing);
            let out = tape.gather_rows(out, packing.flat_to_packed());
            let h = tape.gather_rows(h, packing.flat_to_packed());
            (tape.value(out).to_owned(), tape.value(h).to_owned())
        };
        let (out_short, h_short) = unroll(&short);
        let (out_long, _) = unroll(&long);
        let bits = |a: ArrayView2<f32>| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        let (mut at_short, mut next_x, mut last_h, mut want) = (0, vec![], vec![], vec![]);
        for (s, &l) in short.iter().enumerate() {
            let long_rows = starts[s]..starts[s] + l;
            assert_eq!(
                bits(out_short.slice(ndarray::s![at_short..at_short + l, ..])),
                bits(out_long.slice(ndarray::s![long_rows, ..])),
                "sequence {s}: the longer unroll's first {l} outputs"
            );
            next_x.push(starts[s] + l);
            last_h.push(at_short + l - 1);
            want.push(starts[s] + l);
            at_short += l;
        }
        let got = net.continue_rows(
            x.select(Axis(0), &next_x).view(),
            h_short.select(Axis(0), &last_h).view(),
        );
        assert_eq!(
            bits(got.view()),
            bits(out_long.select(Axis(0), &want).view())
        );
    }
}
