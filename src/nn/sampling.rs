//! Drawing a macro-action from an actor's distribution: the plain softmax of its
//! log-probabilities, or MacroMARL's exploration mixture (1 - eps) pi + eps / |A| (spec
//! `macromarl.md` 2.5). Used while training and by `macdec eval --sample`.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Sample index a from weights p_a (not necessarily normalized; zero weights never drawn).
pub fn sample_weighted(weights: &[f64], rng: &mut ChaCha8Rng) -> usize {
    let total: f64 = weights.iter().sum();
    let u = rng.gen::<f64>() * total;
    let mut acc = 0.0;
    let mut last = 0;
    for (a, &w) in weights.iter().enumerate() {
        if w > 0.0 {
            acc += w;
            last = a;
            if u < acc {
                return a;
            }
        }
    }
    last
}

/// The probabilities of the actor's log-probabilities `logp` under exploration weight `eps`
/// (`None` when evaluated), into `out`.
pub fn mixture(logp: &[f32], eps: Option<f64>, out: &mut Vec<f64>) {
    out.clear();
    let n = logp.len() as f64;
    match eps {
        Some(eps) => out.extend(
            logp.iter()
                .map(|&l| (1.0 - eps) * f64::from(l).exp() + eps / n),
        ),
        None => out.extend(logp.iter().map(|&l| f64::from(l).exp())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn sampling_follows_the_weights_and_never_draws_a_zero() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let w = [0.0, 3.0, 0.0, 1.0];
        let mut counts = [0usize; 4];
        for _ in 0..4000 {
            counts[sample_weighted(&w, &mut rng)] += 1;
        }
        assert_eq!((counts[0], counts[2]), (0, 0));
        assert!((2800..3200).contains(&counts[1]), "{counts:?}");
    }

    #[test]
    fn the_mixture_is_eps_uniform_plus_the_rest_of_pi() {
        let logp = [0.5f32.ln(), 0.25f32.ln(), 0.25f32.ln()];
        let mut p = Vec::new();
        mixture(&logp, Some(0.3), &mut p);
        let want = [0.7 * 0.5 + 0.1, 0.7 * 0.25 + 0.1, 0.7 * 0.25 + 0.1];
        for (a, b) in p.iter().zip(want) {
            assert!((a - b).abs() < 1e-6);
        }
        mixture(&logp, None, &mut p);
        assert!((p[0] - 0.5).abs() < 1e-6);
    }
}
