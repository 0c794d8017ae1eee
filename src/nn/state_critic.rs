//! MacroMARL's state critic (`cores/pg_based/mac_niasc/models.py: Critic`, `docs/MACROMARL.md`
//! 2.4): a plain MLP on the global state `get_state()`,
//!
//! ```text
//! state -> fc1 (in -> m0) -> fc2 (m0 -> m0) -> fc3 (m1 -> mid) -> fc4 (mid -> m1) -> fc5 (m1 -> 1)
//! ```
//!
//! with leaky ReLU after fc1..fc4. fc3 takes m1 inputs from fc2's m0 outputs, so the reference
//! only runs with m0 = m1 (P12); a config with m0 != m1 is refused by the learner.

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::init::LEAKY_RELU_GAIN;
use super::linear::LinearVars;
use super::params::{flat, flat_mut, LinearParams, Params};
use crate::autograd::{Activation, Tape, Var};

const LEAKY: Activation = Activation::LEAKY_001;

/// The state critic's tensors, in its `state_dict` order.
pub const STATE_CRITIC_TENSOR_NAMES: [&str; 10] = [
    "fc1.weight",
    "fc1.bias",
    "fc2.weight",
    "fc2.bias",
    "fc3.weight",
    "fc3.bias",
    "fc4.weight",
    "fc4.bias",
    "fc5.weight",
    "fc5.bias",
];

/// The state critic's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StateCritic {
    fc: [LinearParams; 5],
}

/// A [`StateCritic`]'s parameters on a tape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateCriticVars {
    fc: [LinearVars; 5],
}

impl StateCritic {
    /// Layer (input, output) sizes for a state of `input` values, widths `m` = m0 = m1 and
    /// `mid`.
    fn shapes(input: usize, m: usize, mid: usize) -> [(usize, usize); 5] {
        [(input, m), (m, m), (m, mid), (mid, m), (m, 1)]
    }

    /// A freshly initialized critic (Xavier-uniform, leaky-ReLU gain on fc1..fc4, gain 1 on
    /// fc5, zero biases), drawn in module order.
    pub fn new(input: usize, m: usize, mid: usize, rng: &mut ChaCha8Rng) -> Self {
        let mut k = 0;
        StateCritic {
            fc: Self::shapes(input, m, mid).map(|(i, o)| {
                k += 1;
                let gain = if k == 5 { 1.0 } else { LEAKY_RELU_GAIN };
                LinearParams::xavier(i, o, gain, rng)
            }),
        }
    }

    /// All zeros (a gradient buffer) of the same sizes as `like`.
    pub fn zeros_like(like: &StateCritic) -> Self {
        StateCritic {
            fc: like
                .fc
                .each_ref()
                .map(|l| LinearParams::zeros(l.input(), l.output())),
        }
    }

    /// Every tensor with its `state_dict` name.
    pub fn named(&self) -> Vec<(&'static str, ndarray::ArrayViewD<'_, f32>)> {
        let mut out = Vec::with_capacity(10);
        for (k, l) in self.fc.iter().enumerate() {
            out.push((STATE_CRITIC_TENSOR_NAMES[2 * k], l.weight.view().into_dyn()));
            out.push((
                STATE_CRITIC_TENSOR_NAMES[2 * k + 1],
                l.bias.view().into_dyn(),
            ));
        }
        out
    }

    /// Put the parameters on `tape` as trainable leaves.
    pub fn bind(&self, tape: &mut Tape) -> StateCriticVars {
        StateCriticVars {
            fc: self.fc.each_ref().map(|l| l.bind(tape)),
        }
    }

    /// V(s) [K, 1] for states x: [K, in].
    pub fn forward(&self, tape: &mut Tape, vars: &StateCriticVars, x: Var) -> Var {
        let mut y = x;
        for (k, l) in vars.fc.iter().enumerate() {
            let act = if k == 4 { Activation::Identity } else { LEAKY };
            y = l.forward(tape, y, act);
        }
        y
    }
}

impl StateCriticVars {
    /// Copy the gradients from the tape into `into`.
    pub fn grads_into(&self, tape: &Tape, into: &mut StateCritic) {
        for (v, p) in self.fc.iter().zip(into.fc.iter_mut()) {
            v.grads_into(tape, p);
        }
    }
}

impl Params for StateCritic {
    fn slices(&self) -> Vec<&[f32]> {
        self.fc
            .iter()
            .flat_map(|l| [flat(&l.weight), flat(&l.bias)])
            .collect()
    }

    fn slices_mut(&mut self) -> Vec<&mut [f32]> {
        self.fc
            .iter_mut()
            .flat_map(|l| [flat_mut(&mut l.weight), flat_mut(&mut l.bias)])
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn the_forward_is_the_five_layers() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let c = StateCritic::new(5, 4, 3, &mut rng);
        let x = crate::nn::init::uniform2(2, 5, 1.0, &mut rng);
        let mut tape = Tape::new();
        let v = c.bind(&mut tape);
        let xv = tape.constant(x.view());
        let y = c.forward(&mut tape, &v, xv);
        assert_eq!(tape.value(y).dim(), (2, 1));
        // By hand for the first row.
        let mut a = x.row(0).to_vec();
        for (k, l) in c.fc.iter().enumerate() {
            let mut out = vec![0.0; l.output()];
            let act = if k == 4 { Activation::Identity } else { LEAKY };
            l.forward_row(&a, act, &mut out);
            a = out;
        }
        assert!((a[0] - tape.value(y)[[0, 0]]).abs() < 1e-6);
    }
}
