//! `macdec demo`: the learning engine on a toy memory task, until the trainer exists.
//!
//! Delayed recall: each sequence (length 2..=10) shows one of 4 symbols per step, with a flag on
//! the first step. At every step the net must say which symbol came *first*: Q(h_t, a) is
//! regressed towards 1 if a was the first symbol and 0 otherwise, for a random action a per step,
//! through the same gather / TD-error / square / mean loss the learners use. A net without memory
//! cannot beat a loss of 3/16 = 0.1875 (it would predict 1/4 everywhere after the first step);
//! the LSTM Q-net drives it towards 0.

use ndarray::{Array1, Array2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{Adam, AdamConfig, QNet, QNetConfig, TdBatch, Updater};
use crate::autograd::SeqPacking;

/// Number of symbols (and of actions).
const SYMBOLS: usize = 4;
/// Shortest and longest sequence.
const LENGTHS: std::ops::RangeInclusive<usize> = 2..=10;
/// The loss of the best predictor without memory: P(first) = 1/4 after step 0.
pub const MEMORYLESS_LOSS: f32 = 0.1875;

/// Settings of the demo run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DemoConfig {
    /// Number of Adam steps.
    pub steps: usize,
    /// Seed of the run's single random stream (net init and data).
    pub seed: u64,
    /// Sequences per batch.
    pub batch: usize,
    /// Report the mean loss every this many steps.
    pub report_every: usize,
    /// Adam learning rate.
    pub lr: f64,
}

impl Default for DemoConfig {
    fn default() -> Self {
        DemoConfig {
            steps: 1500,
            seed: 0,
            batch: 32,
            report_every: 100,
            lr: 3e-3,
        }
    }
}

/// Why the demo refused its settings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DemoError {
    /// A count that must be positive was 0.
    #[error("demo: `{name}` must be > 0")]
    NotPositive {
        /// The setting.
        name: &'static str,
    },
}

/// (step, mean loss over the last `report_every` steps) at every report.
pub type LossCurve = Vec<(usize, f32)>;

/// Train the Q-net on delayed recall, calling `report(step, mean_loss)` every `report_every`
/// steps; returns every reported point.
pub fn run(cfg: &DemoConfig, mut report: impl FnMut(usize, f32)) -> Result<LossCurve, DemoError> {
    for (name, v) in [
        ("steps", cfg.steps),
        ("batch", cfg.batch),
        ("report_every", cfg.report_every),
    ] {
        if v == 0 {
            return Err(DemoError::NotPositive { name });
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let net_cfg = QNetConfig {
        input: SYMBOLS + 1,
        mlp: 32,
        hidden: 32,
        output: SYMBOLS,
    };
    let mut net = QNet::new(net_cfg, &mut rng);
    let mut adam = Adam::new(AdamConfig::with_lr(cfg.lr), &net.params);
    let mut updater = Updater::new(&net);
    let mut curve = Vec::new();
    let mut window = 0.0f64;
    for step in 1..=cfg.steps {
        let batch = recall_batch(cfg.batch, &mut rng);
        window += updater.td_step(&mut net, &mut adam, &batch, 1.0) as f64;
        if step % cfg.report_every == 0 {
            let mean = (window / cfg.report_every as f64) as f32;
            report(step, mean);
            curve.push((step, mean));
            window = 0.0;
        }
    }
    Ok(curve)
}

/// A batch of delayed-recall sequences with random actions and their 0/1 targets.
fn recall_batch(n: usize, rng: &mut ChaCha8Rng) -> TdBatch {
    let lengths: Vec<usize> = (0..n).map(|_| rng.gen_range(LENGTHS)).collect();
    let packing = SeqPacking::new(&lengths);
    let k = packing.total();
    let mut x = Array2::zeros((k, SYMBOLS + 1));
    let mut actions = Vec::with_capacity(k);
    let mut targets = Array1::zeros(k);
    let mut row = 0;
    for &len in &lengths {
        let first = rng.gen_range(0..SYMBOLS);
        for t in 0..len {
            let symbol = if t == 0 {
                first
            } else {
                rng.gen_range(0..SYMBOLS)
            };
            x[[row, symbol]] = 1.0;
            x[[row, SYMBOLS]] = if t == 0 { 1.0 } else { 0.0 };
            let a = rng.gen_range(0..SYMBOLS);
            actions.push(a);
            targets[row] = if a == first { 1.0 } else { 0.0 };
            row += 1;
        }
    }
    TdBatch {
        x,
        packing,
        actions,
        targets,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lstm_learns_to_recall_beyond_what_a_memoryless_net_can() {
        let cfg = DemoConfig {
            steps: 600,
            report_every: 100,
            ..DemoConfig::default()
        };
        let curve = run(&cfg, |_, _| {}).unwrap();
        let (first, last) = (curve[0].1, curve[curve.len() - 1].1);
        assert!(last < 0.5 * MEMORYLESS_LOSS, "loss {first} -> {last}");
        assert!(last < 0.5 * first, "loss {first} -> {last}");
    }

    #[test]
    fn zero_steps_is_refused() {
        let cfg = DemoConfig {
            steps: 0,
            ..DemoConfig::default()
        };
        assert_eq!(
            run(&cfg, |_, _| {}),
            Err(DemoError::NotPositive { name: "steps" })
        );
    }
}
