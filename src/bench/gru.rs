//! `macdec bench gru`: the recurrent layer alone, GRU beside LSTM on the same shapes, one
//! forward and backward (with the input's gradient, as inside the Q-net) over a batch of
//! full-length sequences on one thread.
//!
//! A GRU has 3 gate blocks to the LSTM's 4, so at equal sizes it does 3/4 of the matrix-product
//! flops; the question is whether it is as fast *per flop*. `per_flop_vs_lstm` is the GRU's time
//! per flop over the LSTM's (1.0 = as efficient). Flops count the multiply-adds of the products
//! actually executed (2 each); pointwise work is not counted, which favours neither side much
//! (the GRU's cell does about as much pointwise work per hidden unit as the LSTM's).
//! `scripts/pytorch_gru_bench.py` times `nn.GRU` and `nn.LSTM` on the same shapes.

use std::time::Instant;

use ndarray::Array2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::nets::thread_cpu_ns;
use crate::autograd::{SeqPacking, Tape};
use crate::nn::{GruParams, LstmParams};

/// One benchmarked shape: input and hidden size, `batch` sequences of `seq` steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RnnShape {
    /// Label in the table, e.g. `bp10x10-dec`.
    pub name: &'static str,
    /// Input features per step.
    pub input: usize,
    /// Hidden size H.
    pub hidden: usize,
    /// Sequences per pass.
    pub batch: usize,
    /// Steps per sequence.
    pub seq: usize,
}

/// The recurrent layers of the paper's nets (`bench nets`): the LSTM's input is fc2's output,
/// of size H. The Warehouse centralized net has the same recurrent layer as the decentralized.
pub const SHAPES: [RnnShape; 3] = [
    RnnShape {
        name: "bp10x10-dec",
        input: 32,
        hidden: 32,
        batch: 128,
        seq: 15,
    },
    RnnShape {
        name: "bp10x10-cen",
        input: 64,
        hidden: 64,
        batch: 128,
        seq: 15,
    },
    RnnShape {
        name: "wtd-dec",
        input: 64,
        hidden: 64,
        batch: 16,
        seq: 150,
    },
];

/// Which recurrent layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rnn {
    /// The Q-nets' LSTM (4 gates).
    Lstm,
    /// The actors' GRU (3 gates).
    Gru,
}

impl Rnn {
    /// Gate blocks: rows of W_ih and W_hh are `gates() * H`.
    pub fn gates(self) -> usize {
        match self {
            Rnn::Lstm => 4,
            Rnn::Gru => 3,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Rnn::Lstm => "lstm",
            Rnn::Gru => "gru",
        }
    }
}

/// Timing of one layer at one shape.
#[derive(Debug, Clone, PartialEq)]
pub struct RnnBench {
    /// The shape timed.
    pub shape: RnnShape,
    /// The layer timed.
    pub rnn: Rnn,
    /// Median wall-clock time of one forward and backward pass, in ms.
    pub median_ms: f64,
    /// 10th percentile of the same, in ms.
    pub p10_ms: f64,
    /// 90th percentile of the same, in ms.
    pub p90_ms: f64,
    /// Median thread CPU time per pass, where available (see `bench nets`).
    pub cpu_median_ms: Option<f64>,
    /// Matrix-product flops of one forward and backward.
    pub flops: f64,
}

impl RnnBench {
    /// Microseconds per time step of the batch (the pass over `seq` steps, divided by `seq`).
    pub fn us_per_step(&self) -> f64 {
        self.median_ms * 1e3 / self.shape.seq as f64
    }

    /// Picoseconds per matrix-product flop at the median time.
    pub fn ps_per_flop(&self) -> f64 {
        self.median_ms * 1e9 / self.flops
    }
}

/// Flops of the products of one forward and backward of a layer with `gates` blocks, with the
/// input's gradient, as executed: the recurrent products skip each sequence's first step
/// (h_prev = 0), the weight gradient of W_hh runs over all rows.
pub fn rnn_flops(gates: usize, input: usize, hidden: usize, packing: &SeqPacking) -> f64 {
    let g = (gates * hidden) as f64;
    let k = packing.total() as f64;
    let rec = (packing.total() - packing.batch_size(0)) as f64;
    let (i, h) = (input as f64, hidden as f64);
    let forward = 2.0 * k * i * g + 2.0 * rec * h * g;
    let weight_grads = 2.0 * k * i * g + 2.0 * k * h * g;
    let input_grads = 2.0 * k * g * i + 2.0 * rec * g * h;
    forward + weight_grads + input_grads
}

/// Time `iters` forward+backward passes of the LSTM and of the GRU at one shape (after
/// `warmup` untimed ones each), alternating one pass of each, so a change in the machine's load
/// (other processes on a shared machine) affects both sides alike. Returns [LSTM, GRU].
pub fn bench_pair(shape: &RnnShape, iters: usize, warmup: usize) -> [RnnBench; 2] {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let packing = SeqPacking::new(&vec![shape.seq; shape.batch]);
    let k = packing.total();
    let x = Array2::from_shape_simple_fn((k, shape.input), || rng.gen_range(-1.0f32..1.0));
    let dy = Array2::from_shape_simple_fn((k, shape.hidden), || rng.gen_range(-1.0f32..1.0));
    let lstm = LstmParams::pytorch_default(shape.input, shape.hidden, &mut rng);
    let gru = GruParams::pytorch_default(shape.input, shape.hidden, &mut rng);
    let mut tapes = [Tape::new(), Tape::new()];
    let rnns = [Rnn::Lstm, Rnn::Gru];
    let pass = |rnn: Rnn, tape: &mut Tape| {
        tape.reset();
        let xv = tape.param(x.view());
        let y = match rnn {
            Rnn::Lstm => {
                let w = lstm.bind(tape);
                tape.lstm_packed(xv, w, &packing)
            }
            Rnn::Gru => {
                let w = gru.bind(tape);
                tape.gru_packed(xv, w, &packing)
            }
        };
        tape.backward_with(y, dy.view());
    };
    for _ in 0..warmup {
        for (rnn, tape) in rnns.iter().zip(tapes.iter_mut()) {
            pass(*rnn, tape);
        }
    }
    let mut times: [Vec<f64>; 2] = Default::default();
    let mut cpu_times: [Vec<f64>; 2] = Default::default();
    for _ in 0..iters.max(1) {
        for (j, (rnn, tape)) in rnns.iter().zip(tapes.iter_mut()).enumerate() {
            let c0 = thread_cpu_ns();
            let t0 = Instant::now();
            pass(*rnn, tape);
            times[j].push(t0.elapsed().as_secs_f64() * 1e3);
            if let (Some(a), Some(b)) = (c0, thread_cpu_ns()) {
                cpu_times[j].push(b.saturating_sub(a) as f64 * 1e-6);
            }
        }
    }
    let at = |v: &[f64], q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    [0, 1].map(|j| {
        times[j].sort_by(f64::total_cmp);
        cpu_times[j].sort_by(f64::total_cmp);
        let (t, c) = (&times[j], &cpu_times[j]);
        RnnBench {
            shape: *shape,
            rnn: rnns[j],
            median_ms: at(t, 0.5),
            p10_ms: at(t, 0.1),
            p90_ms: at(t, 0.9),
            cpu_median_ms: (c.len() == t.len()).then(|| at(c, 0.5)),
            flops: rnn_flops(rnns[j].gates(), shape.input, shape.hidden, &packing),
        }
    })
}

/// Bench every shape (or only the one named `only`), LSTM then GRU, and format the table:
/// what `macdec bench gru` prints.
pub fn run(only: Option<&str>, iters: usize) -> String {
    let mut rows = Vec::new();
    for shape in SHAPES.iter().filter(|s| only.is_none_or(|o| o == s.name)) {
        rows.extend(bench_pair(shape, iters, iters.div_ceil(10).max(3)));
    }
    format_table(&rows)
}

/// A plain-text table; each GRU row also gives its time and time per flop over the LSTM row of
/// the same shape before it.
pub fn format_table(rows: &[RnnBench]) -> String {
    let mut s = format!(
        "{:<12} {:<5} {:>6} {:>7} {:>9} {:>7} {:>7} {:>7} {:>8} {:>6} {:>7} {:>7} {:>8} {:>9}\n",
        "shape",
        "rnn",
        "in/H",
        "batch",
        "median_ms",
        "p10_ms",
        "p90_ms",
        "cpu_ms",
        "us/step",
        "GFLOP",
        "GFLOP/s",
        "ps/flop",
        "vs_lstm",
        "flop_vs"
    );
    let mut lstm: Option<&RnnBench> = None;
    for r in rows {
        let vs = match (r.rnn, lstm) {
            (Rnn::Gru, Some(l)) if l.shape == r.shape => (
                format!("{:.3}", r.median_ms / l.median_ms),
                format!("{:.3}", r.ps_per_flop() / l.ps_per_flop()),
            ),
            _ => ("-".to_string(), "-".to_string()),
        };
        if r.rnn == Rnn::Lstm {
            lstm = Some(r);
        }
        s += &format!(
            "{:<12} {:<5} {:>6} {:>7} {:>9.3} {:>7.3} {:>7.3} {:>7} {:>8.2} {:>6.3} {:>7.1} {:>7.2} {:>8} {:>9}\n",
            r.shape.name,
            r.rnn.name(),
            format!("{}/{}", r.shape.input, r.shape.hidden),
            format!("{}x{}", r.shape.batch, r.shape.seq),
            r.median_ms,
            r.p10_ms,
            r.p90_ms,
            r.cpu_median_ms
                .map_or("-".to_string(), |t| format!("{t:.3}")),
            r.us_per_step(),
            r.flops / 1e9,
            r.flops / (r.median_ms * 1e-3) / 1e9,
            r.ps_per_flop(),
            vs.0,
            vs.1,
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flop_count_of_a_known_shape() {
        // 1 sequence of 2 steps, in 1, H 1: K = 2, one recurrent row; G = gates.
        // forward 2*2*G + 2*1*G, weight grads 2*2*G + 2*2*G, input grads 2*2*G + 2*1*G = 20 G
        let p = SeqPacking::new(&[2]);
        assert_eq!(rnn_flops(4, 1, 1, &p), 80.0);
        assert_eq!(rnn_flops(3, 1, 1, &p), 60.0);
    }

    #[test]
    fn a_tiny_bench_compares_gru_with_lstm() {
        let s = RnnShape {
            name: "tiny",
            input: 3,
            hidden: 4,
            batch: 2,
            seq: 3,
        };
        let rows = bench_pair(&s, 3, 1);
        assert!(rows
            .iter()
            .all(|r| r.median_ms > 0.0 && r.p10_ms <= r.p90_ms));
        assert_eq!(rows[1].flops, 0.75 * rows[0].flops);
        let table = format_table(&rows);
        let gru_line = table.lines().find(|l| l.contains(" gru ")).unwrap();
        assert!(!gru_line.trim_end().ends_with('-'), "{table}");
    }
}
