//! `macdec bench nets`: the time of one full training update (forward over the sequence batch,
//! TD loss, backward, Adam) of the Q-nets at the paper's shapes, on one thread (issue 3).
//!
//! Our code never spawns threads inside an update, so this is single-threaded by construction.
//! GFLOP/s counts the multiply-adds of the matrix products actually executed (2 flops each),
//! which dominate; elementwise work is not counted.

use std::time::Instant;

use ndarray::{Array1, Array2};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::autograd::SeqPacking;
use crate::nn::{Adam, AdamConfig, QNet, QNetConfig, TdBatch, Updater};

/// One benchmarked configuration: a net and a batch of `batch` full-length sequences of `seq`
/// steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NetShape {
    /// Label in the table, e.g. `wtd-dec`.
    pub name: &'static str,
    /// The Q-net's sizes.
    pub cfg: QNetConfig,
    /// Sequences per update.
    pub batch: usize,
    /// Steps per sequence.
    pub seq: usize,
    /// PyTorch 2.x CPU, 1 thread, the same shape and update (`shared/bench/pytorch_qnet_update.py
    /// --arch ref`), measured on this machine as stated in issue 3.
    pub pytorch_ms: Option<f64>,
}

const fn shape(
    name: &'static str,
    cfg: [usize; 4],
    batch: usize,
    seq: usize,
    pytorch_ms: Option<f64>,
) -> NetShape {
    NetShape {
        name,
        cfg: QNetConfig {
            input: cfg[0],
            mlp: cfg[1],
            hidden: cfg[2],
            output: cfg[3],
        },
        batch,
        seq,
        pytorch_ms,
    }
}

/// The paper's nets (`docs/ALGORITHMS.md` §10) and the PyTorch script's two shapes.
pub const SHAPES: [NetShape; 6] = [
    shape("bp10x10-dec", [5, 32, 32, 8], 128, 15, None),
    shape("bp10x10-cen", [10, 32, 64, 64], 128, 15, None),
    shape("wtd-dec", [13, 32, 64, 3], 16, 150, None),
    shape("wtd-cen", [30, 32, 64, 54], 16, 150, None),
    shape("torch-bp", [13, 32, 32, 8], 128, 15, Some(2.46)),
    shape("torch-wtd", [16, 32, 64, 3], 16, 150, Some(6.41)),
];

/// Timing of one shape.
#[derive(Debug, Clone, PartialEq)]
pub struct NetBench {
    /// The configuration timed.
    pub shape: NetShape,
    /// Median wall-clock time of one update, in ms.
    pub median_ms: f64,
    /// 10th percentile of the same, in ms.
    pub p10_ms: f64,
    /// 90th percentile of the same, in ms.
    pub p90_ms: f64,
    /// Median CPU time of the thread per update (Linux `CLOCK_THREAD_CPUTIME_ID`), which stays
    /// meaningful when other processes compete for the cores; `None` where unavailable.
    pub cpu_median_ms: Option<f64>,
    /// Matrix-product flops of one update.
    pub flops: f64,
}

impl NetBench {
    /// Achieved matrix-product throughput at the median time.
    pub fn gflops(&self) -> f64 {
        self.flops / (self.median_ms * 1e-3) / 1e9
    }
}

/// Flops of the matrix products in one update (forward, backward without the input's
/// gradient, as executed: the recurrent products skip each sequence's first step).
pub fn update_flops(cfg: QNetConfig, packing: &SeqPacking) -> f64 {
    let QNetConfig {
        input,
        mlp: m,
        hidden: h,
        output,
    } = cfg;
    let k = packing.total() as f64;
    let rec = (packing.total() - packing.batch_size(0)) as f64;
    let mm = |rows: f64, a: usize, b: usize| 2.0 * rows * a as f64 * b as f64;
    let forward = mm(k, input, m)
        + mm(k, m, h)
        + mm(k, h, 4 * h)
        + mm(rec, h, 4 * h)
        + mm(k, h, m)
        + mm(k, m, output);
    let weight_grads =
        mm(k, input, m) + mm(k, m, h) + mm(k, 2 * h, 4 * h) + mm(k, h, m) + mm(k, m, output);
    let input_grads =
        mm(k, m, h) + mm(k, h, 4 * h) + mm(rec, 4 * h, h) + mm(k, h, m) + mm(k, m, output);
    forward + weight_grads + input_grads
}

/// A random batch of full-length sequences for `shape` (fixed inputs, actions and targets, as
/// in the PyTorch script).
pub fn random_batch(shape: &NetShape, rng: &mut ChaCha8Rng) -> TdBatch {
    let packing = SeqPacking::new(&vec![shape.seq; shape.batch]);
    let k = packing.total();
    TdBatch {
        x: Array2::from_shape_simple_fn((k, shape.cfg.input), || rng.gen_range(-1.0..1.0)),
        packing,
        actions: (0..k).map(|_| rng.gen_range(0..shape.cfg.output)).collect(),
        targets: Array1::from_shape_simple_fn(k, || rng.gen_range(-1.0..1.0)),
    }
}

/// Time `iters` updates (after `warmup` untimed ones) of one shape.
pub fn bench_shape(shape: &NetShape, iters: usize, warmup: usize) -> NetBench {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let mut net = QNet::new(shape.cfg, &mut rng);
    let mut adam = Adam::new(AdamConfig::with_lr(1e-3), &net.params);
    let mut updater = Updater::new(&net);
    let batch = random_batch(shape, &mut rng);
    for _ in 0..warmup {
        updater.td_step(&mut net, &mut adam, &batch, 1.0);
    }
    let mut times = Vec::with_capacity(iters.max(1));
    let mut cpu_times = Vec::with_capacity(iters.max(1));
    for _ in 0..iters.max(1) {
        let c0 = thread_cpu_ns();
        let t0 = Instant::now();
        updater.td_step(&mut net, &mut adam, &batch, 1.0);
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        if let (Some(a), Some(b)) = (c0, thread_cpu_ns()) {
            cpu_times.push(b.saturating_sub(a) as f64 * 1e-6);
        }
    }
    times.sort_by(f64::total_cmp);
    cpu_times.sort_by(f64::total_cmp);
    let at = |v: &[f64], q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    NetBench {
        shape: *shape,
        median_ms: at(&times, 0.5),
        p10_ms: at(&times, 0.1),
        p90_ms: at(&times, 0.9),
        cpu_median_ms: (cpu_times.len() == times.len()).then(|| at(&cpu_times, 0.5)),
        flops: update_flops(shape.cfg, &batch.packing),
    }
}

/// Nanoseconds of CPU time this thread has used (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`, from
/// the C library std already links; no extra dependency).
#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
pub(crate) fn thread_cpu_ns() -> Option<u64> {
    #[repr(C)]
    struct Timespec {
        tv_sec: i64,
        tv_nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    let mut ts = Timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec (two 64-bit fields on 64-bit Linux).
    let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then(|| ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64)
}

#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
pub(crate) fn thread_cpu_ns() -> Option<u64> {
    None
}

/// A plain-text table of results.
pub fn format_table(results: &[NetBench]) -> String {
    let mut s = format!(
        "{:<12} {:>12} {:>7} {:>9} {:>7} {:>7} {:>7} {:>6} {:>7} {:>8}\n",
        "shape",
        "in/M/H/out",
        "batch",
        "median_ms",
        "p10_ms",
        "p90_ms",
        "cpu_ms",
        "GFLOP",
        "GFLOP/s",
        "torch_ms"
    );
    for r in results {
        let c = r.shape.cfg;
        s += &format!(
            "{:<12} {:>12} {:>7} {:>9.3} {:>7.3} {:>7.3} {:>7} {:>6.3} {:>7.1} {:>8}\n",
            r.shape.name,
            format!("{}/{}/{}/{}", c.input, c.mlp, c.hidden, c.output),
            format!("{}x{}", r.shape.batch, r.shape.seq),
            r.median_ms,
            r.p10_ms,
            r.p90_ms,
            r.cpu_median_ms
                .map_or("-".to_string(), |t| format!("{t:.3}")),
            r.flops / 1e9,
            r.gflops(),
            r.shape
                .pytorch_ms
                .map_or("-".to_string(), |t| format!("{t:.2}")),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flop_count_of_a_known_shape() {
        // 1 sequence of 2 steps, in 1, M 1, H 1, out 1: K = 2, one recurrent row.
        let cfg = QNetConfig {
            input: 1,
            mlp: 1,
            hidden: 1,
            output: 1,
        };
        let p = SeqPacking::new(&[2]);
        // forward: 2*2*(1 + 1 + 4 + 1 + 1) + 2*1*4 = 32 + 8; weight grads: 2*2*(1 + 1 + 8 + 1 + 1)
        // = 48; input grads: 2*2*(1 + 4 + 1 + 1) + 2*1*4 = 28 + 8
        assert_eq!(update_flops(cfg, &p), 40.0 + 48.0 + 36.0);
    }

    #[test]
    fn a_tiny_bench_runs_and_reports_positive_times() {
        let s = shape("tiny", [3, 4, 4, 2], 2, 3, None);
        let r = bench_shape(&s, 3, 1);
        assert!(r.median_ms > 0.0 && r.p10_ms <= r.median_ms && r.median_ms <= r.p90_ms);
        assert!(format_table(&[r]).contains("tiny"));
    }
}
