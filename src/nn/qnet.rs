//! The reference's recurrent Q-net (`docs/ALGORITHMS.md` §2.1), used for every decentralized and
//! centralized net of every method:
//!
//! ```text
//! x -> fc1 (in -> M) -> leaky(0.01) -> fc2 (M -> H) -> leaky(0.01)
//!   -> LSTM(H, H) -> fc3 (H -> M) -> leaky(0.01) -> fc4 (M -> out)
//! ```
//!
//! Three ways to run it: on a tape over a batch of sequences (training), the same without a tape
//! (targets, next-state values), and one step at a time with a carried state (acting).

use ndarray::{s, Array2, ArrayView2, ArrayView3, ArrayViewD};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::init::LEAKY_RELU_GAIN;
use super::linear::LinearVars;
use super::lstm::LstmState;
use super::params::{flat, flat_mut, LinearParams, LstmParams, Params};
use crate::autograd::kernels::dense::linear_forward;
use crate::autograd::kernels::lstm::{lstm_forward, LstmCache, LstmWeights};
use crate::autograd::{Activation, LstmVars, Pool, SeqPacking, Tape, Var};

/// Layer sizes of a Q-net: `input` features, MLP width M (fc1, fc3), LSTM hidden size H (fc2's
/// output and the LSTM), `output` Q-values (one per (joint) macro-action).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QNetConfig {
    /// Input features: the agent's (or the joint) macro-observation length.
    pub input: usize,
    /// M: width of fc1 and fc3.
    pub mlp: usize,
    /// H: fc2's output and the LSTM's hidden size.
    pub hidden: usize,
    /// Q-values: one per (joint) macro-action.
    pub output: usize,
}

/// A size a tensor dimension takes from a [`QNetConfig`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dim {
    /// `input`.
    Input,
    /// M (`mlp`).
    Mlp,
    /// H (`hidden`).
    Hidden,
    /// 4H: the LSTM's four stacked gates i, f, g, o.
    Gates,
    /// `output`.
    Output,
}

/// One parameter tensor: its PyTorch state_dict name and its shape in [`Dim`]s
/// (`nn.Linear.weight` is `[out, in]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TensorSpec {
    /// The state_dict name, e.g. `lstm.weight_ih_l0`.
    pub name: &'static str,
    /// The shape, resolved against a [`QNetConfig`].
    pub dims: &'static [Dim],
}

/// The one table of the Q-net's parameter tensors, in state_dict order (fc1, fc2, lstm, fc3,
/// fc4, as the reference's module). Names, shapes, the flat parameter order (gradients, Adam,
/// target copies) and safetensors I/O all follow it; [`QNetParams`]'s field list
/// (`qnet_tensors!`) is checked against it by a test.
pub const TENSORS: [TensorSpec; 12] = {
    use Dim::*;
    const fn t(name: &'static str, dims: &'static [Dim]) -> TensorSpec {
        TensorSpec { name, dims }
    }
    [
        t("fc1.weight", &[Mlp, Input]),
        t("fc1.bias", &[Mlp]),
        t("fc2.weight", &[Hidden, Mlp]),
        t("fc2.bias", &[Hidden]),
        t("lstm.weight_ih_l0", &[Gates, Hidden]),
        t("lstm.weight_hh_l0", &[Gates, Hidden]),
        t("lstm.bias_ih_l0", &[Gates]),
        t("lstm.bias_hh_l0", &[Gates]),
        t("fc3.weight", &[Mlp, Hidden]),
        t("fc3.bias", &[Mlp]),
        t("fc4.weight", &[Output, Mlp]),
        t("fc4.bias", &[Output]),
    ]
};

/// The parameter tensors' names, in [`TENSORS`] order.
pub const TENSOR_NAMES: [&str; 12] = {
    let mut names = [""; 12];
    let mut i = 0;
    while i < TENSORS.len() {
        names[i] = TENSORS[i].name;
        i += 1;
    }
    names
};

/// `[f(&p.fc1.weight), f(&p.fc1.bias), ...]` for `qnet_tensors!(f, &p)` (or `&mut p`): the
/// parameter arrays of a [`QNetParams`] in [`TENSORS`] order, the one place the fields are listed.
macro_rules! qnet_tensors {
    ($f:path, $($r:tt)+) => {
        [
            $f($($r)+.fc1.weight),
            $f($($r)+.fc1.bias),
            $f($($r)+.fc2.weight),
            $f($($r)+.fc2.bias),
            $f($($r)+.lstm.weight_ih),
            $f($($r)+.lstm.weight_hh),
            $f($($r)+.lstm.bias_ih),
            $f($($r)+.lstm.bias_hh),
            $f($($r)+.fc3.weight),
            $f($($r)+.fc3.bias),
            $f($($r)+.fc4.weight),
            $f($($r)+.fc4.bias),
        ]
    };
}

/// A tensor of any rank as a dynamic-rank view (for [`QNetParams::named`]).
fn dyn_view<D: ndarray::Dimension>(a: &ndarray::Array<f32, D>) -> ArrayViewD<'_, f32> {
    a.view().into_dyn()
}

impl QNetConfig {
    /// The size `dim` stands for.
    pub fn size(&self, dim: Dim) -> usize {
        match dim {
            Dim::Input => self.input,
            Dim::Mlp => self.mlp,
            Dim::Hidden => self.hidden,
            Dim::Gates => 4 * self.hidden,
            Dim::Output => self.output,
        }
    }

    /// The shape of each tensor of [`TENSORS`], in the same order.
    pub fn tensor_shapes(&self) -> [Vec<usize>; 12] {
        TENSORS.map(|t| t.dims.iter().map(|&d| self.size(d)).collect())
    }

    /// Number of trainable scalars.
    pub fn n_params(&self) -> usize {
        self.tensor_shapes()
            .iter()
            .map(|s| s.iter().product::<usize>())
            .sum()
    }
}

/// The Q-net's parameters, named as the reference's PyTorch module (fc1, fc2, lstm, fc3, fc4).
/// Also the container for its gradients and Adam moments.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QNetParams {
    /// Input to M.
    pub fc1: LinearParams,
    /// M to H.
    pub fc2: LinearParams,
    /// The LSTM, H to H.
    pub lstm: LstmParams,
    /// H to M.
    pub fc3: LinearParams,
    /// M to the Q-values.
    pub fc4: LinearParams,
}

impl QNetParams {
    /// All zeros (a gradient buffer).
    pub fn zeros(cfg: QNetConfig) -> Self {
        QNetParams {
            fc1: LinearParams::zeros(cfg.input, cfg.mlp),
            fc2: LinearParams::zeros(cfg.mlp, cfg.hidden),
            lstm: LstmParams::zeros(cfg.hidden, cfg.hidden),
            fc3: LinearParams::zeros(cfg.hidden, cfg.mlp),
            fc4: LinearParams::zeros(cfg.mlp, cfg.output),
        }
    }

    /// The reference's initialization (`docs/ALGORITHMS.md` §2.2): Xavier-uniform with the leaky-ReLU gain on
    /// fc1..fc3, gain 1 on fc4, zero Linear biases, PyTorch's LSTM default; drawn in module
    /// order fc1, fc2, lstm, fc3, fc4.
    pub fn init(cfg: QNetConfig, rng: &mut ChaCha8Rng) -> Self {
        let fc1 = LinearParams::xavier(cfg.input, cfg.mlp, LEAKY_RELU_GAIN, rng);
        let fc2 = LinearParams::xavier(cfg.mlp, cfg.hidden, LEAKY_RELU_GAIN, rng);
        let lstm = LstmParams::pytorch_default(cfg.hidden, cfg.hidden, rng);
        let fc3 = LinearParams::xavier(cfg.hidden, cfg.mlp, LEAKY_RELU_GAIN, rng);
        let fc4 = LinearParams::xavier(cfg.mlp, cfg.output, 1.0, rng);
        QNetParams {
            fc1,
            fc2,
            lstm,
            fc3,
            fc4,
        }
    }

    /// The sizes these tensors have.
    pub fn config(&self) -> QNetConfig {
        QNetConfig {
            input: self.fc1.input(),
            mlp: self.fc1.output(),
            hidden: self.lstm.hidden(),
            output: self.fc4.output(),
        }
    }

    /// Every tensor with its state_dict name, in [`TENSOR_NAMES`] order.
    pub fn named(&self) -> [(&'static str, ArrayViewD<'_, f32>); 12] {
        let views = qnet_tensors!(dyn_view, &self);
        let mut i = 0;
        views.map(|v| {
            i += 1;
            (TENSOR_NAMES[i - 1], v)
        })
    }

    /// The tensor called `name` (state_dict naming), if there is one.
    pub fn get(&self, name: &str) -> Option<ArrayViewD<'_, f32>> {
        self.named()
            .into_iter()
            .find(|(n, _)| *n == name)
            .map(|(_, a)| a)
    }

    /// Overwrite with `other`'s values (same config) without allocating: the hard target copy.
    pub fn copy_from(&mut self, other: &QNetParams) {
        assert_eq!(
            self.config(),
            other.config(),
            "copy_from: different net sizes"
        );
        for (d, s) in self.slices_mut().into_iter().zip(other.slices()) {
            d.copy_from_slice(s);
        }
    }
}

impl Params for QNetParams {
    fn slices(&self) -> Vec<&[f32]> {
        Vec::from(qnet_tensors!(flat, &self))
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        Vec::from(qnet_tensors!(flat_mut, &mut self))
    }
}

/// The hidden layers' activation: PyTorch's default leaky ReLU (slope 0.01).
const LEAKY: Activation = Activation::LEAKY_001;

/// A recurrent Q-net. `Clone` (or [`QNet::copy_from`]) makes the target net.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QNet {
    /// The parameters.
    pub params: QNetParams,
}

/// A Q-net's parameters on a tape, from [`QNet::bind`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QNetVars {
    /// fc1's weight and bias.
    pub fc1: LinearVars,
    /// fc2's weight and bias.
    pub fc2: LinearVars,
    /// The LSTM's weights and biases.
    pub lstm: LstmVars,
    /// fc3's weight and bias.
    pub fc3: LinearVars,
    /// fc4's weight and bias.
    pub fc4: LinearVars,
}

impl QNetVars {
    /// The gradients after [`Tape::backward`], as a parameter set (allocates; see
    /// [`QNetVars::grads_into`]).
    pub fn grads(&self, tape: &Tape, cfg: QNetConfig) -> QNetParams {
        let mut g = QNetParams::zeros(cfg);
        self.grads_into(tape, &mut g);
        g
    }

    /// Copy the gradients into an existing buffer (zero where no gradient reached a tensor).
    pub fn grads_into(&self, tape: &Tape, into: &mut QNetParams) {
        self.fc1.grads_into(tape, &mut into.fc1);
        self.fc2.grads_into(tape, &mut into.fc2);
        self.lstm.grads_into(tape, &mut into.lstm);
        self.fc3.grads_into(tape, &mut into.fc3);
        self.fc4.grads_into(tape, &mut into.fc4);
    }
}

impl QNet {
    /// A freshly initialized net (`docs/ALGORITHMS.md` §2.2), drawn from `rng`.
    pub fn new(cfg: QNetConfig, rng: &mut ChaCha8Rng) -> Self {
        QNet {
            params: QNetParams::init(cfg, rng),
        }
    }

    /// Its layer sizes.
    pub fn config(&self) -> QNetConfig {
        self.params.config()
    }

    /// Hard target update: become a copy of `online` (no allocation).
    pub fn copy_from(&mut self, online: &QNet) {
        self.params.copy_from(&online.params);
    }

    /// Put the parameters on `tape` as trainable leaves (once per update, before
    /// [`QNet::forward`]).
    pub fn bind(&self, tape: &mut Tape) -> QNetVars {
        let p = &self.params;
        QNetVars {
            fc1: p.fc1.bind(tape),
            fc2: p.fc2.bind(tape),
            lstm: p.lstm.bind(tape),
            fc3: p.fc3.bind(tape),
            fc4: p.fc4.bind(tape),
        }
    }

    /// Training forward: Q-values [K, out] for every valid position of every sequence, each
    /// sequence unrolled from a zero state. x: [K, in] in flat (sequence, time) order, with
    /// K = packing.total(); the result has the same row order. Panics on a shape mismatch.
    pub fn forward(
        &self,
        tape: &mut Tape,
        vars: &QNetVars,
        x: ArrayView2<f32>,
        packing: &SeqPacking,
    ) -> Var {
        self.check_input(x, packing);
        // The whole net runs in packed order (each LSTM step then touches contiguous rows);
        // only the input and the Q-values are reordered.
        let xp = gather_rows(x, packing.packed_to_flat(), tape.pool());
        let xp = tape.constant_owned(xp);
        let a1 = vars.fc1.forward(tape, xp, LEAKY);
        let a2 = vars.fc2.forward(tape, a1, LEAKY);
        let h = tape.lstm_packed(a2, vars.lstm, packing);
        let a3 = vars.fc3.forward(tape, h, LEAKY);
        let q = vars.fc4.forward(tape, a3, Activation::Identity);
        tape.gather_rows(q, packing.flat_to_packed())
    }

    /// [`QNet::forward`] for a padded batch x: [B, T, in] whose row b is valid for its first
    /// `lengths[b]` steps. Result rows: row-major over valid positions (sequence, then time).
    pub fn forward_padded(
        &self,
        tape: &mut Tape,
        vars: &QNetVars,
        x: ArrayView3<f32>,
        lengths: &[usize],
    ) -> Var {
        let packing = SeqPacking::new(lengths);
        let flat = flatten_padded(x, lengths, tape.pool());
        let q = self.forward(tape, vars, flat.view(), &packing);
        tape.pool().give_array(flat);
        q
    }

    /// The same values as [`QNet::forward`] without recording anything (target and next-state
    /// Q-values). Scratch comes from and returns to `pool`; so does the result's buffer if the
    /// caller gives it back.
    pub fn forward_nograd_in(
        &self,
        x: ArrayView2<f32>,
        packing: &SeqPacking,
        pool: &mut Pool,
    ) -> Array2<f32> {
        self.check_input(x, packing);
        let cfg = self.config();
        let p = &self.params;
        let k = packing.total();
        let xp = gather_rows(x, packing.packed_to_flat(), pool);
        let mut a1 = pool.array(k, cfg.mlp);
        linear_forward(
            xp.view(),
            p.fc1.weight.view(),
            flat(&p.fc1.bias),
            LEAKY,
            a1.view_mut(),
        );
        let mut a2 = pool.array(k, cfg.hidden);
        linear_forward(
            a1.view(),
            p.fc2.weight.view(),
            flat(&p.fc2.bias),
            LEAKY,
            a2.view_mut(),
        );
        let [s_hp, s_g, s_c, s_tc] = LstmCache::shapes(k, cfg.hidden);
        let mut cache = LstmCache {
            h_prev: pool.array(s_hp.0, s_hp.1),
            gates: pool.array(s_g.0, s_g.1),
            c: pool.array(s_c.0, s_c.1),
            tanh_c: pool.array(s_tc.0, s_tc.1),
        };
        let mut h = pool.array(k, cfg.hidden);
        let w = LstmWeights {
            w_ih: p.lstm.weight_ih.view(),
            w_hh: p.lstm.weight_hh.view(),
            b_ih: flat(&p.lstm.bias_ih),
            b_hh: flat(&p.lstm.bias_hh),
        };
        lstm_forward(a2.view(), &w, packing, &mut cache, &mut h);
        linear_forward(
            h.view(),
            p.fc3.weight.view(),
            flat(&p.fc3.bias),
            LEAKY,
            a1.view_mut(),
        );
        let mut qp = pool.array(k, cfg.output);
        let fc4 = &p.fc4;
        linear_forward(
            a1.view(),
            fc4.weight.view(),
            flat(&fc4.bias),
            Activation::Identity,
            qp.view_mut(),
        );
        let q = gather_rows(qp.view(), packing.flat_to_packed(), pool);
        for a in [
            xp,
            a1,
            a2,
            h,
            qp,
            cache.h_prev,
            cache.gates,
            cache.c,
            cache.tanh_c,
        ] {
            pool.give_array(a);
        }
        q
    }

    /// [`QNet::forward_nograd_in`] with this thread's scratch pool, so repeated calls reuse
    /// their buffers (fresh multi-megabyte allocations cost more than the forward itself at the
    /// paper's shapes). The pool never changes a result: every buffer is fully overwritten.
    pub fn forward_nograd(&self, x: ArrayView2<f32>, packing: &SeqPacking) -> Array2<f32> {
        with_scratch(|pool| self.forward_nograd_in(x, packing, pool))
    }

    /// [`QNet::forward_nograd`] for a padded batch x: [B, T, in] (see [`QNet::forward_padded`]).
    pub fn forward_nograd_padded(&self, x: ArrayView3<f32>, lengths: &[usize]) -> Array2<f32> {
        with_scratch(|pool| {
            let flat = flatten_padded(x, lengths, pool);
            let q = self.forward_nograd_in(flat.view(), &SeqPacking::new(lengths), pool);
            pool.give_array(flat);
            q
        })
    }

    /// One acting step: Q-values for input x given the carried state, which advances
    /// (`docs/ALGORITHMS.md` §2.3). No tape, no allocation after the state's first use. The slice lives in
    /// `state`'s scratch. Panics if x or the state do not match the net's sizes.
    pub fn act_step<'s>(&self, x: &[f32], state: &'s mut LstmState) -> &'s [f32] {
        let cfg = self.config();
        assert_eq!(
            x.len(),
            cfg.input,
            "act_step: input has {} values, the net {}",
            x.len(),
            cfg.input
        );
        let p = &self.params;
        let mut sc = std::mem::take(&mut state.scratch);
        sc[0].resize(cfg.mlp, 0.0);
        sc[1].resize(cfg.hidden, 0.0);
        sc[2].resize(cfg.mlp, 0.0);
        sc[3].resize(cfg.output, 0.0);
        let [a1, a2, a3, q] = &mut sc;
        p.fc1.forward_row(x, LEAKY, a1);
        p.fc2.forward_row(a1, LEAKY, a2);
        p.lstm.step(a2, state);
        p.fc3.forward_row(state.h(), LEAKY, a3);
        p.fc4.forward_row(a3, Activation::Identity, q);
        state.scratch = sc;
        &state.scratch[3]
    }

    /// A zero recurrent state sized for this net.
    pub fn zero_state(&self) -> LstmState {
        LstmState::zeros(self.config().hidden)
    }

    fn check_input(&self, x: ArrayView2<f32>, packing: &SeqPacking) {
        let cfg = self.config();
        assert_eq!(
            x.ncols(),
            cfg.input,
            "q-net input has {} features, the net {}",
            x.ncols(),
            cfg.input
        );
        assert_eq!(
            x.nrows(),
            packing.total(),
            "q-net input rows differ from the packing's total"
        );
    }
}

thread_local! {
    /// Scratch buffers of the no-tape forwards on this thread (see [`QNet::forward_nograd`]).
    static SCRATCH: std::cell::RefCell<Pool> = std::cell::RefCell::new(Pool::default());
}

/// Run `f` with this thread's scratch pool.
fn with_scratch<T>(f: impl FnOnce(&mut Pool) -> T) -> T {
    SCRATCH.with(|p| f(&mut p.borrow_mut()))
}

/// out[k] = x[index[k]] (rows), in a buffer from `pool`.
fn gather_rows(x: ArrayView2<f32>, index: &[usize], pool: &mut Pool) -> Array2<f32> {
    let mut out = pool.array(index.len(), x.ncols());
    for (mut row, &i) in out.rows_mut().into_iter().zip(index) {
        row.assign(&x.row(i));
    }
    out
}

/// The valid rows of a padded [B, T, in] batch, flattened in (sequence, time) order.
/// Panics if `lengths` does not have B entries or one exceeds T.
pub fn flatten_padded(x: ArrayView3<f32>, lengths: &[usize], pool: &mut Pool) -> Array2<f32> {
    let (b, t, input) = x.dim();
    assert_eq!(lengths.len(), b, "one length per sequence");
    let k: usize = lengths.iter().sum();
    let mut out = pool.array(k, input);
    let mut at = 0;
    for (s, &len) in lengths.iter().enumerate() {
        assert!(
            len <= t,
            "sequence {s} has length {len} > padded length {t}"
        );
        out.slice_mut(s![at..at + len, ..])
            .assign(&x.slice(s![s, ..len, ..]));
        at += len;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::loss::hysteretic_td_loss;
    use ndarray::{Array1, Array3};
    use rand::{Rng, SeedableRng};

    const CFG: QNetConfig = QNetConfig {
        input: 5,
        mlp: 7,
        hidden: 4,
        output: 3,
    };

    /// The field list (`qnet_tensors!`) and the table agree: every array has its table shape,
    /// named and flat views list the same values in the same order, and sizes are all distinct
    /// here so a swapped dimension or field would show.
    #[test]
    fn the_tensor_table_describes_the_fields_in_order() {
        let net = QNet::new(CFG, &mut ChaCha8Rng::seed_from_u64(3));
        let named = net.params.named();
        let slices = net.params.slices();
        assert_eq!(slices.len(), TENSORS.len());
        for (((name, view), shape), (spec, flat)) in named
            .iter()
            .zip(CFG.tensor_shapes())
            .zip(TENSORS.iter().zip(&slices))
        {
            assert_eq!(*name, spec.name);
            assert_eq!(view.shape(), shape.as_slice(), "{name}");
            assert_eq!(view.iter().copied().collect::<Vec<f32>>(), flat.to_vec());
        }
        assert_eq!(
            CFG.n_params(),
            slices.iter().map(|s| s.len()).sum::<usize>()
        );
        assert_eq!(TENSOR_NAMES[4], "lstm.weight_ih_l0");
    }

    fn setup(lengths: &[usize], seed: u64) -> (QNet, Array2<f32>, SeqPacking) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let net = QNet::new(CFG, &mut rng);
        let packing = SeqPacking::new(lengths);
        let x =
            Array2::from_shape_simple_fn((packing.total(), CFG.input), || rng.gen_range(-1.0..1.0));
        (net, x, packing)
    }

    #[test]
    fn init_follows_the_reference() {
        let (net, _, _) = setup(&[1], 0);
        let p = &net.params;
        for l in [&p.fc1, &p.fc2, &p.fc3, &p.fc4] {
            assert!(
                l.bias.iter().all(|&b| b == 0.0),
                "Linear biases start at zero"
            );
        }
        let bound = |l: &LinearParams, gain: f64| {
            (gain * (6.0 / (l.input() + l.output()) as f64).sqrt()) as f32
        };
        assert!(p
            .fc1
            .weight
            .iter()
            .all(|w| w.abs() <= bound(&p.fc1, LEAKY_RELU_GAIN)));
        assert!(p.fc4.weight.iter().all(|w| w.abs() <= bound(&p.fc4, 1.0)));
        // fc4's gain-1 bound is below fc1's leaky gain bound scaled to fc4's fans: some fc4
        // weight would exceed it if the leaky gain were used by mistake (checked on a big net).
        let big = QNet::new(
            QNetConfig {
                input: 8,
                mlp: 64,
                hidden: 64,
                output: 64,
            },
            &mut ChaCha8Rng::seed_from_u64(1),
        );
        let b1 = bound(&big.params.fc4, 1.0);
        let max4 = big
            .params
            .fc4
            .weight
            .iter()
            .fold(0.0f32, |m, w| m.max(w.abs()));
        assert!(max4 <= b1 && max4 > 0.95 * b1);
        assert_eq!(net.config(), CFG);
        assert_eq!(
            CFG.n_params(),
            net.params.slices().iter().map(|s| s.len()).sum::<usize>()
        );
    }

    #[test]
    fn acting_step_by_step_matches_the_batch_forward() {
        let lengths = [4, 6, 1];
        let (net, x, packing) = setup(&lengths, 2);
        let q = net.forward_nograd(x.view(), &packing);
        let mut state = net.zero_state();
        for (s, &len) in lengths.iter().enumerate() {
            state.reset();
            for t in 0..len {
                let row = packing.flat_row(s, t);
                let qs = net.act_step(x.row(row).as_slice().unwrap(), &mut state);
                for (a, b) in qs.iter().zip(q.row(row).iter()) {
                    assert!((a - b).abs() < 1e-5, "seq {s} step {t}: {a} vs {b}");
                }
            }
        }
    }

    #[test]
    fn no_grad_forward_equals_the_taped_forward() {
        let (net, x, packing) = setup(&[3, 0, 5, 5, 2], 3);
        let mut tape = Tape::new();
        let vars = net.bind(&mut tape);
        let q = net.forward(&mut tape, &vars, x.view(), &packing);
        assert_eq!(tape.value(q), net.forward_nograd(x.view(), &packing));
    }

    #[test]
    fn padded_input_gives_the_flat_rows_in_sequence_time_order() {
        let lengths = [2, 4, 3];
        let (net, x, packing) = setup(&lengths, 4);
        let mut padded = Array3::from_elem((3, 4, CFG.input), f32::NAN);
        for (s, &len) in lengths.iter().enumerate() {
            for t in 0..len {
                padded
                    .slice_mut(s![s, t, ..])
                    .assign(&x.row(packing.flat_row(s, t)));
            }
        }
        let flat_q = net.forward_nograd(x.view(), &packing);
        assert_eq!(net.forward_nograd_padded(padded.view(), &lengths), flat_q);
        let mut tape = Tape::new();
        let vars = net.bind(&mut tape);
        let q = net.forward_padded(&mut tape, &vars, padded.view(), &lengths);
        assert_eq!(tape.value(q), flat_q);
    }

    #[test]
    fn parameter_gradients_match_finite_differences() {
        // The TD loss through the whole net, perturbing entries of every tensor.
        let (net, x, packing) = setup(&[3, 1, 4], 5);
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let k = packing.total();
        let actions: Vec<usize> = (0..k).map(|_| rng.gen_range(0..CFG.output)).collect();
        let y = Array1::from_shape_simple_fn(k, || rng.gen_range(-1.0..1.0));
        let loss_of = |net: &QNet, grads: Option<&mut QNetParams>| -> f64 {
            let mut tape = Tape::new();
            let vars = net.bind(&mut tape);
            let q = net.forward(&mut tape, &vars, x.view(), &packing);
            let loss = hysteretic_td_loss(&mut tape, q, &actions, y.view(), 0.5);
            if let Some(g) = grads {
                tape.backward(loss);
                vars.grads_into(&tape, g);
            }
            tape.scalar(loss) as f64
        };
        let mut grads = QNetParams::zeros(CFG);
        loss_of(&net, Some(&mut grads));
        let step = 1e-2f32;
        for (t, name) in TENSOR_NAMES.iter().enumerate() {
            let len = net.params.slices()[t].len();
            for e in [0, len / 2, len - 1] {
                let mut plus = net.clone();
                plus.params.slices_mut()[t][e] += step;
                let mut minus = net.clone();
                minus.params.slices_mut()[t][e] -= step;
                let numeric = (loss_of(&plus, None) - loss_of(&minus, None)) / (2.0 * step as f64);
                let analytic = grads.slices()[t][e] as f64;
                assert!(
                    (numeric - analytic).abs() <= 2e-3 + 2e-2 * numeric.abs().max(analytic.abs()),
                    "{name} element {e}: analytic {analytic}, numeric {numeric}"
                );
            }
        }
    }

    #[test]
    fn copy_from_makes_an_identical_target() {
        let (online, _, _) = setup(&[1], 7);
        let (mut target, _, _) = setup(&[1], 8);
        assert_ne!(target, online);
        target.copy_from(&online);
        assert_eq!(target, online);
    }

    #[test]
    fn params_are_reachable_by_state_dict_name() {
        let (net, _, _) = setup(&[1], 9);
        assert_eq!(
            net.params.get("lstm.weight_hh_l0").unwrap().shape(),
            &[16, 4]
        );
        assert_eq!(net.params.get("fc4.bias").unwrap().shape(), &[3]);
        assert!(net.params.get("fc5.bias").is_none());
    }
}
