//! Drawing a macro-action from an actor's distribution: the plain softmax of its
//! log-probabilities, or MacroMARL's exploration mixture (1 - eps) pi + eps / |A| (spec
//! `macromarl.md` 2.5). Used while training and by `macdec eval --sample`.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::argmax::FirstArgmax;
use super::joint_index::{for_each_allowed, unravel};
use crate::autograd::kernels::exp::exp_f64_in_place;

/// Sample index a from weights p_a (not necessarily normalized; zero weights never drawn).
pub fn sample_weighted(weights: &[f64], rng: &mut ChaCha8Rng) -> usize {
    let total: f64 = weights.iter().sum();
    let u = rng.gen::<f64>() * total;
    weighted_pick(weights, u).unwrap_or(0)
}

/// The first entry at which the running sum of the positive weights exceeds `u`, else the last
/// positive entry, `None` if no weight is positive. Zero entries change neither the sum nor the
/// pick, so leaving them out of `weights` picks the same entry among the rest.
fn weighted_pick(weights: &[f64], u: f64) -> Option<usize> {
    let mut acc = 0.0;
    let mut last = None;
    for (a, &w) in weights.iter().enumerate() {
        if w > 0.0 {
            acc += w;
            last = Some(a);
            if u < acc {
                return Some(a);
            }
        }
    }
    last
}

/// The probabilities of the actor's log-probabilities `logp` under exploration weight `eps`
/// (`None` when evaluated), into `out`.
pub fn mixture(logp: &[f32], eps: Option<f64>, out: &mut Vec<f64>) {
    out.clear();
    out.extend(logp.iter().map(|&l| f64::from(l)));
    mix_in_place(out, eps, logp.len() as f64);
}

/// Each log-probability `l` of `probs` becomes its weight in the mixture over `n` entries:
/// (1 - eps) e^l + eps / n, or e^l without exploration (e^l in f64, glibc's `exp` bit for bit,
/// four at a time; then one rounded multiply and one rounded add, as written).
fn mix_in_place(probs: &mut [f64], eps: Option<f64>, n: f64) {
    exp_f64_in_place(probs);
    if let Some(eps) = eps {
        let (keep, floor) = (1.0 - eps, eps / n);
        for p in probs {
            *p = keep * *p + floor;
        }
    }
}

/// How [`conditioned_joint`] picks among the allowed joint macro-actions.
pub enum Pick<'a> {
    /// A draw from their probabilities (MacroMARL's acting and evaluation).
    Sample(&'a mut ChaCha8Rng),
    /// The most probable (the first on ties): greedy execution.
    MostProbable,
}

/// Mac-CAC's joint macro-action (spec `macromarl.md` 2.5, P4): the probabilities of the
/// centralized actor's log-probabilities `logp` under `eps` ([`mixture`]), zeroed for every
/// joint macro-action in which a busy agent's part differs from its running macro-action
/// (`running[i]` where `!free[i]`), then picked by `pick` and unravelled in C order (agent 0
/// most significant) into `actions`; `probs` is left holding the allowed entries' weights in
/// increasing joint order. `logp` has one entry per joint macro-action (the
/// product of `n_actions`, as a policy's manifest checks). `Pick::MostProbable` is
/// [`conditioned_argmax`] of `logp` and leaves `probs` alone.
#[allow(clippy::too_many_arguments)]
pub fn conditioned_joint(
    logp: &[f32],
    eps: Option<f64>,
    free: &[bool],
    running: &[usize],
    n_actions: &[usize],
    pick: Pick<'_>,
    probs: &mut Vec<f64>,
    actions: &mut [usize],
) {
    debug_assert_eq!(logp.len(), n_actions.iter().product::<usize>());
    let rng = match pick {
        Pick::Sample(rng) => rng,
        Pick::MostProbable => return conditioned_argmax(logp, free, running, n_actions, actions),
    };
    // The draw of `sample_weighted` over the whole masked mixture (the other entries zero),
    // computed on the allowed entries only, in increasing order: adding zeros changes no sum
    // and a zero is never picked, so the total, the draw and the pick are the same bit for bit.
    // With one agent free of three, 15 of 3 375 joint macro-actions are allowed. They come in
    // runs: the last agent's allowed part (all of its macro-actions, or its running one) after
    // each allowed part of the others.
    let busy = busy_part(free, running);
    let (last, n_last) = (n_actions.len() - 1, n_actions[n_actions.len() - 1]);
    let run = match busy(last) {
        Some(r) => r.min(n_last)..(r + 1).min(n_last),
        None => 0..n_last,
    };
    probs.clear();
    for_each_allowed(&n_actions[..last], &busy, None, &mut |prefix| {
        let at = prefix * n_last;
        probs.extend(
            logp[at + run.start..at + run.end]
                .iter()
                .map(|&l| f64::from(l)),
        );
    });
    mix_in_place(probs, eps, logp.len() as f64);
    let total: f64 = probs.iter().sum();
    let u = rng.gen::<f64>() * total;
    let mut joint = 0;
    if let Some(k) = weighted_pick(probs, u) {
        // Entry k is the (k mod run length)-th of the (k / run length)-th run.
        let (nth, offset) = (k / run.len(), k % run.len());
        let mut seen = 0;
        for_each_allowed(&n_actions[..last], &busy, None, &mut |prefix| {
            if seen == nth {
                joint = prefix * n_last + run.start + offset;
            }
            seen += 1;
        });
    }
    unravel(joint, n_actions, actions);
}

/// The part [`for_each_allowed`] fixes for agent `i`: its running macro-action while it is busy.
fn busy_part<'a>(free: &'a [bool], running: &'a [usize]) -> impl Fn(usize) -> Option<usize> + 'a {
    |i| (!free[i]).then_some(running[i])
}

/// The greedy joint macro-action of a centralized net's `scores` (Q-values or an actor's
/// log-probabilities, one per joint macro-action): the highest score among the joint
/// macro-actions that keep every busy agent's running macro-action, the first in C order on ties
/// and a NaN never winning ([`crate::nn::argmax::first_argmax`]'s rule), unravelled into
/// `actions`. For a centralized Q-net this is the conditional argmax (`docs/ALGORITHMS.md` §4.3);
/// for Mac-CAC's actor, its most probable allowed joint macro-action. A busy agent's part is left
/// as `running[i]`. With no allowed joint macro-action (a `running[i]` out of range), `actions`
/// is left as it was.
pub fn conditioned_argmax(
    scores: &[f32],
    free: &[bool],
    running: &[usize],
    n_actions: &[usize],
    actions: &mut [usize],
) {
    let mut best = FirstArgmax::default();
    for_each_allowed(n_actions, busy_part(free, running), None, &mut |j| {
        best.offer(j, scores[j]);
    });
    if let Some(j) = best.index() {
        unravel(j, n_actions, actions);
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
    fn the_joint_choice_keeps_busy_agents_and_greedy_takes_the_most_probable_allowed() {
        // Two agents with 2 and 3 macro-actions: joint j = 3 a0 + a1.
        let p = [0.05f32, 0.1, 0.05, 0.4, 0.3, 0.1];
        let logp: Vec<f32> = p.iter().map(|x| x.ln()).collect();
        let (mut probs, mut actions) = (Vec::new(), [9, 9]);
        let both = [true, true];
        conditioned_joint(
            &logp,
            None,
            &both,
            &[0, 0],
            &[2, 3],
            Pick::MostProbable,
            &mut probs,
            &mut actions,
        );
        assert_eq!(actions, [1, 0]);
        // Agent 0 busy on 0: only j in 0..3 allowed, the best of them is (0, 1).
        let busy0 = [false, true];
        conditioned_joint(
            &logp,
            None,
            &busy0,
            &[0, 2],
            &[2, 3],
            Pick::MostProbable,
            &mut probs,
            &mut actions,
        );
        assert_eq!(actions, [0, 1]);
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        for _ in 0..200 {
            conditioned_joint(
                &logp,
                Some(0.2),
                &busy0,
                &[0, 2],
                &[2, 3],
                Pick::Sample(&mut rng),
                &mut probs,
                &mut actions,
            );
            assert_eq!(actions[0], 0);
        }
    }

    /// The whole mixture, then every joint macro-action that changes a busy agent's running
    /// one zeroed: what `conditioned_joint` computed before it visited only the allowed ones.
    fn masked_mixture(
        logp: &[f32],
        eps: Option<f64>,
        free: &[bool],
        running: &[usize],
        n_actions: &[usize],
    ) -> Vec<f64> {
        // The definition, with the platform's exp (the kernel must give its bits).
        let n = logp.len() as f64;
        let mut p: Vec<f64> = logp
            .iter()
            .map(|&l| match eps {
                Some(eps) => (1.0 - eps) * f64::from(l).exp() + eps / n,
                None => f64::from(l).exp(),
            })
            .collect();
        for (j, w) in p.iter_mut().enumerate() {
            if !keeps_busy_agents(j, free, running, n_actions) {
                *w = 0.0;
            }
        }
        p
    }

    /// The definition: joint macro-action `joint` leaves every busy agent's part at its running
    /// macro-action.
    fn keeps_busy_agents(
        joint: usize,
        free: &[bool],
        running: &[usize],
        n_actions: &[usize],
    ) -> bool {
        let mut parts = vec![0; n_actions.len()];
        unravel(joint, n_actions, &mut parts);
        (0..parts.len()).all(|i| free[i] || parts[i] == running[i])
    }

    #[test]
    fn the_joint_draw_equals_the_masked_whole_mixture_bit_for_bit() {
        let mut gen = ChaCha8Rng::seed_from_u64(11);
        for case in 0..3000 {
            let agents = gen.gen_range(1..=4);
            let n_actions: Vec<usize> = (0..agents).map(|_| gen.gen_range(1..=5)).collect();
            let free: Vec<bool> = (0..agents).map(|_| gen.gen_bool(0.5)).collect();
            // Now and then a running macro-action out of range: nothing is allowed then.
            let running: Vec<usize> = n_actions
                .iter()
                .map(|&n| gen.gen_range(0..n + usize::from(case % 50 == 0)))
                .collect();
            let total: usize = n_actions.iter().product();
            let logp: Vec<f32> = (0..total)
                .map(|_| match gen.gen_range(0..20) {
                    0 => f32::NEG_INFINITY,
                    1 => f32::NAN,
                    2 => -200.0,
                    _ => -gen.gen::<f32>() * 6.0,
                })
                .collect();
            let eps = [None, Some(0.0), Some(0.3), Some(1.0)][case % 4];
            let want_probs = masked_mixture(&logp, eps, &free, &running, &n_actions);
            let (mut a, mut b) = (
                ChaCha8Rng::seed_from_u64(case as u64),
                ChaCha8Rng::seed_from_u64(case as u64),
            );
            let mut want = vec![0; agents];
            unravel(sample_weighted(&want_probs, &mut a), &n_actions, &mut want);
            let (mut probs, mut got) = (vec![7.0], vec![9; agents]);
            conditioned_joint(
                &logp,
                eps,
                &free,
                &running,
                &n_actions,
                Pick::Sample(&mut b),
                &mut probs,
                &mut got,
            );
            assert_eq!(got, want, "case {case}");
            let bits = |p: &[f64]| p.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let allowed: Vec<f64> = (0..total)
                .filter(|&j| keeps_busy_agents(j, &free, &running, &n_actions))
                .map(|j| want_probs[j])
                .collect();
            assert_eq!(bits(&probs), bits(&allowed), "case {case}");
            assert_eq!(
                a.gen::<u64>(),
                b.gen::<u64>(),
                "case {case}: the streams diverged"
            );
            // Greedy: the first largest allowed score (a NaN never winning), else untouched.
            let best = crate::nn::argmax::first_argmax(
                (0..total)
                    .filter(|&j| keeps_busy_agents(j, &free, &running, &n_actions))
                    .map(|j| (j, logp[j])),
            );
            let mut want = vec![9; agents];
            if let Some(j) = best {
                unravel(j, &n_actions, &mut want);
            }
            let mut got = vec![9; agents];
            conditioned_joint(
                &logp,
                eps,
                &free,
                &running,
                &n_actions,
                Pick::MostProbable,
                &mut probs,
                &mut got,
            );
            assert_eq!(got, want, "case {case}: greedy");
        }
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
