//! The GRU layer (PyTorch's `nn.GRU`, one layer): its default initialization, binding to a tape
//! (training over packed sequences, `Tape::gru_packed`), and the one-step update with a carried
//! h used when acting. Weight files use `nn.GRU`'s state_dict names (`safetensors_io.rs`).
//!
//! ```text
//! r = sigmoid(W_ir x + b_ir + W_hr h + b_hr)
//! z = sigmoid(W_iz x + b_iz + W_hz h + b_hz)
//! n = tanh(W_in x + b_in + r * (W_hn h + b_hn))
//! h' = (1 - z) * n + z * h
//! ```

use ndarray::ArrayViewD;
use serde::{Deserialize, Serialize};

use super::params::{flat, GruParams};
use crate::autograd::kernels::dense::matvec_act;
use crate::autograd::kernels::gru::forward_cells;
use crate::autograd::{GruVars, SeqPacking, Tape, Var};

/// A one-layer `nn.GRU`'s state_dict names: weight_ih [3H, in], weight_hh [3H, H], bias_ih
/// \[3H\], bias_hh \[3H\]. (Inside a module they get its prefix, e.g. `gru.weight_ih_l0`.)
pub const GRU_TENSOR_NAMES: [&str; 4] =
    ["weight_ih_l0", "weight_hh_l0", "bias_ih_l0", "bias_hh_l0"];

impl GruParams {
    /// Every tensor with its `nn.GRU` state_dict name, in [`GRU_TENSOR_NAMES`] order.
    pub fn named(&self) -> [(&'static str, ArrayViewD<'_, f32>); 4] {
        let n = GRU_TENSOR_NAMES;
        [
            (n[0], self.weight_ih.view().into_dyn()),
            (n[1], self.weight_hh.view().into_dyn()),
            (n[2], self.bias_ih.view().into_dyn()),
            (n[3], self.bias_hh.view().into_dyn()),
        ]
    }

    /// Put the parameters on a tape as trainable leaves (biases as [1, 3H] rows).
    pub fn bind(&self, tape: &mut Tape) -> GruVars {
        let [w_ih, w_hh, b_ih, b_hh] = self.leaves(tape);
        GruVars {
            w_ih,
            w_hh,
            b_ih,
            b_hh,
        }
    }

    /// Advance `state` by one input row x: [in] (acting: no tape, no allocation); the new h is
    /// in `state.h()`. The same kernel as the taped op, so a step equals that op's row to
    /// within rounding. Panics if the sizes do not match.
    pub fn step(&self, x: &[f32], state: &mut GruState) {
        let h = self.hidden();
        assert_eq!(x.len(), self.input(), "gru step: input length");
        assert_eq!(
            state.h.len(),
            h,
            "gru step: state was made for another hidden size"
        );
        // a = W_ih x + b_ih and b = W_hh h + b_hh with their biases (so the cell kernel gets
        // zero biases); slope 1 makes matvec_act the identity.
        matvec_act(
            flat(&self.weight_ih),
            x,
            flat(&self.bias_ih),
            1.0,
            &mut state.a,
        );
        matvec_act(
            flat(&self.weight_hh),
            &state.h,
            flat(&self.bias_hh),
            1.0,
            &mut state.b,
        );
        forward_cells(
            &mut state.a,
            &state.b,
            &state.zero_bias,
            &state.h,
            &mut state.hn,
            &mut state.h_next,
            h,
        );
        std::mem::swap(&mut state.h, &mut state.h_next);
    }
}

/// A GRU's recurrent state h, zero at the start of each episode, plus the scratch the acting
/// forward writes into so that acting never allocates. Saved (in checkpoints) as h alone; the
/// scratch is rebuilt on load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "SavedGruState", into = "SavedGruState")]
pub struct GruState {
    h: Vec<f32>,
    h_next: Vec<f32>,
    a: Vec<f32>,
    b: Vec<f32>,
    hn: Vec<f32>,
    zero_bias: Vec<f32>,
}

/// What a [`GruState`] saves.
#[derive(Serialize, Deserialize)]
struct SavedGruState {
    h: Vec<f32>,
}

impl From<SavedGruState> for GruState {
    fn from(s: SavedGruState) -> Self {
        GruState::from_h(&s.h)
    }
}

impl From<GruState> for SavedGruState {
    fn from(s: GruState) -> Self {
        SavedGruState { h: s.h }
    }
}

impl GruState {
    /// The zero state of a GRU with hidden size `hidden` (PyTorch's `None` hidden state).
    pub fn zeros(hidden: usize) -> Self {
        GruState {
            h: vec![0.0; hidden],
            h_next: vec![0.0; hidden],
            a: vec![0.0; 3 * hidden],
            b: vec![0.0; 3 * hidden],
            hn: vec![0.0; hidden],
            zero_bias: vec![0.0; 4 * hidden],
        }
    }

    /// A state holding `h` (e.g. a hidden state handed over from elsewhere).
    pub fn from_h(h: &[f32]) -> Self {
        let mut s = GruState::zeros(h.len());
        s.h.copy_from_slice(h);
        s
    }

    /// Back to the zero state.
    pub fn reset(&mut self) {
        self.h.fill(0.0);
    }

    /// The hidden state h: \[H\].
    pub fn h(&self) -> &[f32] {
        &self.h
    }
}

impl GruVars {
    /// The GRU over a batch of sequences on the tape: x: [K, in] in packed order (see
    /// [`SeqPacking`]) -> h: [K, H] in the same order, each sequence from a zero state.
    pub fn forward_packed(&self, tape: &mut Tape, x: Var, packing: &SeqPacking) -> Var {
        tape.gru_packed(x, *self, packing)
    }

    /// Copy the GRU's gradients from the tape into `into` (zero where none reached it).
    pub fn grads_into(&self, tape: &Tape, into: &mut GruParams) {
        into.copy_grads(tape, [self.w_ih, self.w_hh, self.b_ih, self.b_hh]);
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use ndarray::{Array1, Array2};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use serde_json::Value;

    use super::*;
    use crate::nn::safetensors_io::{gru_from_safetensors_bytes, gru_to_safetensors_bytes};

    #[test]
    fn stepping_matches_the_sequence_op() {
        // H = 18: both the 16-lane block and the one-lane rest of the cell kernel.
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let p = GruParams::pytorch_default(3, 18, &mut rng);
        let x = super::super::init::uniform2(6, 3, 1.0, &mut rng);
        let mut tape = Tape::new();
        let v = p.bind(&mut tape);
        let xv = tape.constant(x.view());
        let y = tape.gru(xv, v, &SeqPacking::new(&[6]));
        let mut state = GruState::zeros(18);
        for t in 0..6 {
            p.step(x.row(t).as_slice().unwrap(), &mut state);
            for (a, b) in state.h().iter().zip(tape.value(y).row(t).iter()) {
                assert!((a - b).abs() < 1e-6, "step {t}: {a} vs {b}");
            }
        }
        state.reset();
        assert!(state.h().iter().all(|&v| v == 0.0));
    }

    #[test]
    fn default_init_stays_within_one_over_sqrt_hidden() {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let p = GruParams::pytorch_default(8, 16, &mut rng);
        assert_eq!(p.weight_ih.dim(), (48, 8));
        assert_eq!(p.weight_hh.dim(), (48, 16));
        let k = 0.25;
        for a in [&p.weight_ih, &p.weight_hh] {
            assert!(a.iter().all(|v| v.abs() <= k));
        }
        assert!(p
            .bias_ih
            .iter()
            .chain(p.bias_hh.iter())
            .all(|v| v.abs() <= k));
        assert!(p.weight_hh.iter().any(|v| v.abs() > 0.9 * k));
    }

    /// A `{"shape": [...], "data": [...]}` tensor of the fixture, flattened.
    fn data(v: &Value) -> (Vec<usize>, Vec<f32>) {
        let shape = v["shape"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d.as_u64().unwrap() as usize)
            .collect();
        let data = v["data"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d.as_f64().unwrap() as f32)
            .collect();
        (shape, data)
    }

    fn assert_all_close(what: &str, ours: &[f32], torch: &[f32]) {
        assert_eq!(ours.len(), torch.len(), "{what}: length");
        for (i, (a, b)) in ours.iter().zip(torch).enumerate() {
            assert!((a - b).abs() <= 1e-5, "{what}[{i}]: ours {a}, torch {b}");
        }
    }

    #[test]
    fn matches_pytorch_nn_gru_values_and_gradients() {
        // tests/fixtures/gru_torch.{json,safetensors}, written by
        // scripts/gru_fixture_from_torch.py from torch.nn.GRU(5, 4).
        let fixture: Value =
            serde_json::from_str(include_str!("../../tests/fixtures/gru_torch.json")).unwrap();
        let params = gru_from_safetensors_bytes(
            include_bytes!("../../tests/fixtures/gru_torch.safetensors"),
            Path::new("tests/fixtures/gru_torch.safetensors"),
        )
        .unwrap();
        // The safetensors file and the JSON hold the same state_dict.
        for (name, a) in params.named() {
            let (shape, want) = data(&fixture["state_dict"][name]);
            assert_eq!(a.shape(), shape.as_slice(), "{name}");
            assert_eq!(a.iter().copied().collect::<Vec<_>>(), want, "{name}");
        }
        let (input, hidden) = (params.input(), params.hidden());
        assert_eq!((input, hidden), (5, 4));
        let (xs, x) = data(&fixture["x"]);
        let (_, c) = data(&fixture["loss_weights"]);
        let (batch, seq) = (xs[0], xs[1]);
        let padded = |s: usize, t: usize| (s * seq + t) * hidden..(s * seq + t + 1) * hidden;

        for case in ["full", "packed"] {
            let f = &fixture["cases"][case];
            let lengths: Vec<usize> = f["lengths"]
                .as_array()
                .unwrap()
                .iter()
                .map(|l| l.as_u64().unwrap() as usize)
                .collect();
            let packing = SeqPacking::new(&lengths);
            // Flat rows (sequence-major over valid steps) of x and of the loss weights.
            let k = packing.total();
            let (mut xf, mut seed) = (Array2::zeros((k, input)), Array2::zeros((k, hidden)));
            for (s, &len) in lengths.iter().enumerate() {
                for t in 0..len {
                    let row = packing.flat_row(s, t);
                    for i in 0..input {
                        xf[[row, i]] = x[(s * seq + t) * input + i];
                    }
                    for (j, &cv) in c[padded(s, t)].iter().enumerate() {
                        seed[[row, j]] = cv;
                    }
                }
            }
            let mut tape = Tape::new();
            let vars = params.bind(&mut tape);
            let xv = tape.param(xf.view());
            let y = tape.gru(xv, vars, &packing);
            tape.backward_with(y, seed.view());

            // Outputs: torch's are zero past a sequence's end, so compare the padded layout.
            let mut out = vec![0.0; batch * seq * hidden];
            let mut h_n = vec![0.0; batch * hidden];
            for (s, &len) in lengths.iter().enumerate() {
                for t in 0..len {
                    let row = tape.value(y).row(packing.flat_row(s, t)).to_vec();
                    out[padded(s, t)].copy_from_slice(&row);
                    if t + 1 == len {
                        h_n[s * hidden..(s + 1) * hidden].copy_from_slice(&row);
                    }
                }
            }
            assert_all_close(&format!("{case} output"), &out, &data(&f["output"]).1);
            assert_all_close(&format!("{case} h_n"), &h_n, &data(&f["h_n"]).1);

            let mut grads = GruParams::zeros(input, hidden);
            vars.grads_into(&tape, &mut grads);
            for (name, g) in grads.named() {
                let g: Vec<f32> = g.iter().copied().collect();
                let want = data(&f["grads"][name]).1;
                assert_all_close(&format!("{case} d{name}"), &g, &want);
            }
            let mut dx = vec![0.0; batch * seq * input];
            let gx = tape.grad(xv).unwrap();
            for (s, &len) in lengths.iter().enumerate() {
                for t in 0..len {
                    let at = (s * seq + t) * input;
                    for (i, &g) in gx.row(packing.flat_row(s, t)).iter().enumerate() {
                        dx[at + i] = g;
                    }
                }
            }
            assert_all_close(&format!("{case} dx"), &dx, &data(&f["grads"]["x"]).1);
        }
    }

    #[test]
    fn safetensors_round_trip_keeps_names_shapes_and_values() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let p = GruParams::pytorch_default(7, 5, &mut rng);
        let bytes = gru_to_safetensors_bytes(&p);
        let st = safetensors::SafeTensors::deserialize(&bytes).unwrap();
        let shape = |n: &str| st.tensor(n).unwrap().shape().to_vec();
        assert_eq!(shape("weight_ih_l0"), vec![15, 7]);
        assert_eq!(shape("weight_hh_l0"), vec![15, 5]);
        assert_eq!(shape("bias_ih_l0"), vec![15]);
        assert_eq!(shape("bias_hh_l0"), vec![15]);
        assert_eq!(st.names().len(), 4);
        let back = gru_from_safetensors_bytes(&bytes, Path::new("x")).unwrap();
        assert_eq!(back, p);

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("gru.safetensors");
        p.save_safetensors(&path).unwrap();
        assert_eq!(GruParams::load_safetensors(&path).unwrap(), p);
    }

    #[test]
    fn a_file_with_a_wrong_bias_length_is_an_error_naming_the_tensor() {
        let mut p = GruParams::zeros(3, 2);
        p.bias_hh = Array1::zeros(5);
        let err =
            gru_from_safetensors_bytes(&gru_to_safetensors_bytes(&p), Path::new("x")).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("bias_hh_l0") && msg.contains("[6]"), "{msg}");
    }

    #[test]
    fn an_lstm_file_is_not_a_gru() {
        // An nn.LSTM state_dict has the same names with 4H rows: H would not divide.
        let mut p = GruParams::zeros(3, 2);
        p.weight_hh = Array2::zeros((8, 2));
        let err =
            gru_from_safetensors_bytes(&gru_to_safetensors_bytes(&p), Path::new("x")).unwrap_err();
        assert!(err.to_string().contains("weight_hh_l0"), "{err}");
    }

    #[test]
    fn adam_trains_a_gru_to_fit_a_target_sequence() {
        // One sequence of 6 steps; the loss is the mean squared error to a fixed target.
        use crate::nn::{Adam, AdamConfig};
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut p = GruParams::pytorch_default(2, 3, &mut rng);
        let x = super::super::init::uniform2(6, 2, 1.0, &mut rng);
        let target = super::super::init::uniform2(6, 3, 0.5, &mut rng);
        let mut adam = Adam::new(AdamConfig::with_lr(0.05), &p);
        let mut grads = GruParams::zeros(2, 3);
        let packing = SeqPacking::new(&[6]);
        let mut tape = Tape::new();
        let loss = |p: &GruParams, grads: &mut GruParams, tape: &mut Tape| {
            tape.reset();
            let v = p.bind(tape);
            let xv = tape.constant(x.view());
            let tv = tape.constant(target.view());
            let y = v.forward_packed(tape, xv, &packing);
            let d = tape.sub(y, tv);
            let sq = tape.square(d);
            let l = tape.mean(sq);
            tape.backward(l);
            v.grads_into(tape, grads);
            tape.scalar(l)
        };
        let first = loss(&p, &mut grads, &mut tape);
        for _ in 0..200 {
            loss(&p, &mut grads, &mut tape);
            adam.step(&mut p, &grads);
        }
        let last = loss(&p, &mut grads, &mut tape);
        assert!(last < 0.1 * first, "loss {first} -> {last}");
    }
}
