//! One gradient step of a Q-net on a TD loss: forward over the sequence batch on the tape, loss,
//! backward, Adam. The learners' inner step, the benchmark's unit of work and the demo's loop.

use ndarray::{Array1, Array2};

use super::adam::Adam;
use super::loss::hysteretic_td_loss;
use super::qnet::{QNet, QNetParams};
use crate::autograd::{SeqPacking, Tape};

/// A batch of sequences with one chosen action and one (constant) target per valid position.
/// x: [K, in] in flat (sequence, time) order; `actions`, `targets`: K entries, same order.
#[derive(Debug, Clone, PartialEq)]
pub struct TdBatch {
    /// The inputs, [K, in].
    pub x: Array2<f32>,
    /// Which rows belong to which sequence and time step.
    pub packing: SeqPacking,
    /// The chosen action at each of the K positions.
    pub actions: Vec<usize>,
    /// The TD target at each of the K positions (no gradient flows into it).
    pub targets: Array1<f32>,
}

/// Reusable state of an update loop: the tape and the gradient buffer.
#[derive(Debug)]
pub struct Updater {
    /// The tape, cleared and reused each update.
    pub tape: Tape,
    /// The gradient buffer, zeroed and reused each update.
    pub grads: QNetParams,
}

impl Updater {
    /// Buffers for updating nets shaped like `net`.
    pub fn new(net: &QNet) -> Self {
        Updater {
            tape: Tape::new(),
            grads: QNetParams::zeros(net.config()),
        }
    }

    /// One Adam step on mean_k (max(h d_k, d_k))^2, d_k = y_k - Q(h_k, a_k) (`docs/ALGORITHMS.md` §5; h = 1 is
    /// the plain MSE). Returns the loss before the step. The tape is reset afterwards, so
    /// nothing accumulates across updates.
    pub fn td_step(&mut self, net: &mut QNet, adam: &mut Adam, batch: &TdBatch, h: f32) -> f32 {
        let tape = &mut self.tape;
        let vars = net.bind(tape);
        let q = net.forward(tape, &vars, batch.x.view(), &batch.packing);
        let loss = hysteretic_td_loss(tape, q, &batch.actions, batch.targets.view(), h);
        let value = tape.scalar(loss);
        tape.backward(loss);
        vars.grads_into(tape, &mut self.grads);
        tape.reset();
        adam.step(&mut net.params, &self.grads);
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::{AdamConfig, QNetConfig};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn batch(cfg: QNetConfig, lengths: &[usize], rng: &mut ChaCha8Rng) -> TdBatch {
        let packing = SeqPacking::new(lengths);
        let k = packing.total();
        TdBatch {
            x: Array2::from_shape_simple_fn((k, cfg.input), || rng.gen_range(-1.0..1.0)),
            packing,
            actions: (0..k).map(|_| rng.gen_range(0..cfg.output)).collect(),
            targets: Array1::from_shape_simple_fn(k, || rng.gen_range(-1.0..1.0)),
        }
    }

    fn train(seed: u64, updates: usize) -> QNet {
        let cfg = QNetConfig {
            input: 4,
            mlp: 8,
            hidden: 6,
            output: 3,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut net = QNet::new(cfg, &mut rng);
        let mut adam = Adam::new(AdamConfig::with_lr(1e-2), &net.params);
        let mut up = Updater::new(&net);
        for _ in 0..updates {
            let b = batch(cfg, &[5, 2, 0, 7, 7], &mut rng);
            up.td_step(&mut net, &mut adam, &b, 0.4);
        }
        net
    }

    fn bits(net: &QNet) -> Vec<u32> {
        use crate::nn::Params;
        net.params
            .slices()
            .iter()
            .flat_map(|s| s.iter().map(|v| v.to_bits()))
            .collect()
    }

    #[test]
    fn same_seed_gives_bit_identical_parameters_whatever_the_thread_count() {
        let in_pool = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| bits(&train(17, 30)))
        };
        let one = in_pool(1);
        assert_eq!(one, in_pool(2));
        assert_eq!(one, bits(&train(17, 30)));
        assert_ne!(
            one,
            bits(&train(18, 30)),
            "a different seed must give different parameters"
        );
    }

    #[test]
    fn loss_falls_on_a_fixed_batch() {
        let cfg = QNetConfig {
            input: 4,
            mlp: 16,
            hidden: 8,
            output: 3,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut net = QNet::new(cfg, &mut rng);
        let mut adam = Adam::new(AdamConfig::with_lr(1e-2), &net.params);
        let mut up = Updater::new(&net);
        let b = batch(cfg, &[6, 3, 6], &mut rng);
        let first = up.td_step(&mut net, &mut adam, &b, 1.0);
        let mut last = first;
        for _ in 0..200 {
            last = up.td_step(&mut net, &mut adam, &b, 1.0);
        }
        assert!(last < 0.2 * first, "loss {first} -> {last}");
    }

    #[test]
    fn no_memory_growth_across_100k_updates() {
        let cfg = QNetConfig {
            input: 2,
            mlp: 3,
            hidden: 2,
            output: 2,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut net = QNet::new(cfg, &mut rng);
        let mut adam = Adam::new(AdamConfig::with_lr(1e-3), &net.params);
        let mut up = Updater::new(&net);
        let b = batch(cfg, &[3, 1], &mut rng);
        for _ in 0..100 {
            up.td_step(&mut net, &mut adam, &b, 1.0);
        }
        let after_100 = up.tape.retained();
        for _ in 100..100_000 {
            up.td_step(&mut net, &mut adam, &b, 1.0);
        }
        assert_eq!(up.tape.retained(), after_100);
        assert!(up.tape.is_empty());
    }
}
