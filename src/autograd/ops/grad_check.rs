//! Central-difference gradient checks for the ops (test-only).
//!
//! Tolerance, justified for f32: inputs are O(1) and the step is h = 1e-2. The projected output
//! sum(y * R) is accumulated in f64 from f32 values whose rounding error is ~1e-7 relative, so the
//! difference quotient carries a rounding error of about 1e-7 * |f| / h ~ 1e-5 * |f| for the
//! small shapes used here; its truncation error is h^2 / 6 * f''' ~ 2e-5 * f'''. Accepting
//! |analytic - numeric| <= 2e-3 + 1e-2 * max(|analytic|, |numeric|) leaves a margin of ~100x
//! over that noise, while a wrong backward (a missing factor, a transposed product, a wrong sign,
//! a dropped fan-out term) misses by 10% or more; `a_five_percent_error_fails_the_check` shows
//! the check is that sharp. Kinked ops (leaky ReLU) draw their inputs away from the kink.

use ndarray::Array2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::autograd::{Tape, Var};

const STEP: f32 = 1e-2;
const ATOL: f64 = 2e-3;
const RTOL: f64 = 1e-2;

/// How test inputs are drawn.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Inputs {
    /// Uniform in [-1, 1].
    Any,
    /// Magnitude in [0.1, 1], random sign: keeps inputs 10 steps away from a kink at 0.
    AwayFromZero,
}

/// Random arrays of the given shapes, reproducible from `seed`.
pub(crate) fn random_inputs(
    shapes: &[(usize, usize)],
    kind: Inputs,
    seed: u64,
) -> Vec<Array2<f32>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    shapes
        .iter()
        .map(|&(r, c)| {
            Array2::from_shape_fn((r, c), |_| {
                let u: f32 = rng.gen_range(-1.0..1.0);
                match kind {
                    Inputs::Any => u,
                    Inputs::AwayFromZero => u.signum() * (0.1 + 0.9 * u.abs()),
                }
            })
        })
        .collect()
}

/// Panics (naming the input and element) unless `build`'s backward matches central differences.
pub(crate) fn grad_check(
    build: impl Fn(&mut Tape, &[Var]) -> Var,
    shapes: &[(usize, usize)],
    kind: Inputs,
) {
    if let Err(e) = check_gradients(&build, shapes, kind) {
        panic!("gradient check failed: {e}");
    }
}

/// The analytic gradient of sum(y * R) for a fixed random R, and the numeric one, compared.
pub(crate) fn check_gradients(
    build: &dyn Fn(&mut Tape, &[Var]) -> Var,
    shapes: &[(usize, usize)],
    kind: Inputs,
) -> Result<(), String> {
    let inputs = random_inputs(shapes, kind, 7);
    let mut tape = Tape::new();
    let vars: Vec<Var> = inputs.iter().map(|a| tape.param(a.view())).collect();
    let y = build(&mut tape, &vars);
    let (r, c) = tape.shape(y);
    let seed = random_inputs(&[(r, c)], Inputs::Any, 11).remove(0);
    tape.backward_with(y, seed.view());
    let analytic: Vec<Array2<f32>> = vars
        .iter()
        .zip(&inputs)
        .map(|(&v, a)| {
            tape.grad(v)
                .map_or_else(|| Array2::zeros(a.dim()), |g| g.to_owned())
        })
        .collect();

    let mut eval = |xs: &[Array2<f32>]| -> f64 {
        tape.reset();
        let vars: Vec<Var> = xs.iter().map(|a| tape.param(a.view())).collect();
        let y = build(&mut tape, &vars);
        tape.value(y)
            .iter()
            .zip(seed.iter())
            .map(|(&y, &s)| y as f64 * s as f64)
            .sum()
    };
    let mut numeric = Vec::new();
    let mut xs = inputs.clone();
    for i in 0..xs.len() {
        let mut n = Array2::zeros(xs[i].dim());
        for e in 0..xs[i].len() {
            let orig = xs[i].as_slice().unwrap()[e];
            xs[i].as_slice_mut().unwrap()[e] = orig + STEP;
            let plus = eval(&xs);
            xs[i].as_slice_mut().unwrap()[e] = orig - STEP;
            let minus = eval(&xs);
            xs[i].as_slice_mut().unwrap()[e] = orig;
            n.as_slice_mut().unwrap()[e] = ((plus - minus) / (2.0 * STEP as f64)) as f32;
        }
        numeric.push(n);
    }
    compare(&analytic, &numeric)
}

/// Ok if every analytic entry is within the tolerance of the numeric one.
pub(crate) fn compare(analytic: &[Array2<f32>], numeric: &[Array2<f32>]) -> Result<(), String> {
    for (i, (a, n)) in analytic.iter().zip(numeric).enumerate() {
        for (e, (&a, &n)) in a.iter().zip(n.iter()).enumerate() {
            let (a, n) = (a as f64, n as f64);
            if (a - n).abs() > ATOL + RTOL * a.abs().max(n.abs()) {
                return Err(format!("input {i} element {e}: analytic {a}, numeric {n}"));
            }
        }
    }
    Ok(())
}

/// Panics unless a and b have the same shape and differ by at most `tol` anywhere.
pub(crate) fn assert_close(a: &Array2<f32>, b: &Array2<f32>, tol: f32) {
    assert_eq!(a.dim(), b.dim(), "shapes differ");
    for (i, (x, y)) in a.iter().zip(b.iter()).enumerate() {
        assert!((x - y).abs() <= tol, "element {i}: {x} vs {y} (tol {tol})");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_five_percent_error_fails_the_check() {
        let numeric = random_inputs(&[(4, 4)], Inputs::AwayFromZero, 1);
        let wrong: Vec<Array2<f32>> = numeric.iter().map(|g| g * 1.05).collect();
        assert!(compare(&numeric, &numeric).is_ok());
        assert!(compare(&wrong, &numeric).is_err());
    }
}
