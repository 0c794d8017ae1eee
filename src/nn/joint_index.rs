//! Joint macro-action indices, the one implementation every centralized net shares (the ICRA
//! Q-nets' conditional argmax, MacroMARL's MacCen-Q and Mac-CAC's joint actor): a joint
//! macro-action `(m_0, .., m_{N-1})` is the C-order index `((m_0 * n_1) + m_1) * n_2 + m_2 ..`,
//! agent 0 most significant (`np.ravel_multi_index`), and the joint macro-actions a decision may
//! pick are visited without testing every index.

/// C-order joint index of `actions` (agent 0 most significant). Panics (debug) if an action is
/// out of range or the lengths differ.
pub fn ravel(actions: &[usize], n_actions: &[usize]) -> usize {
    debug_assert_eq!(actions.len(), n_actions.len());
    actions.iter().zip(n_actions).fold(0, |idx, (&a, &n)| {
        debug_assert!(a < n, "action {a} out of range 0..{n}");
        idx * n + a
    })
}

/// Inverse of [`ravel`]: writes each agent's action of joint index `index` into `out` \[N\].
pub fn unravel(index: usize, n_actions: &[usize], out: &mut [usize]) {
    debug_assert_eq!(out.len(), n_actions.len());
    let mut rest = index;
    for (slot, &n) in out.iter_mut().zip(n_actions).rev() {
        *slot = rest % n;
        rest /= n;
    }
}

/// Agent `agent`'s component of joint index `index`, without unravelling the others.
pub fn unravel_component(index: usize, n_actions: &[usize], agent: usize) -> usize {
    let stride: usize = n_actions[agent + 1..].iter().product();
    (index / stride) % n_actions[agent]
}

/// Calls `f` on every joint index over the agents of `n_actions` whose component of agent `i` is
/// `fixed(i)` where that is `Some` (a busy agent keeps its running macro-action; none when it is
/// out of range) and, with `avail` (the agents' 0/1 masks concatenated in agent order), is
/// available; in increasing order, which is C order. Only those indices are visited, and nothing
/// is allocated. Over a prefix of the agents (`&n_actions[..k]`) it gives the prefixes' indices.
pub fn for_each_allowed(
    n_actions: &[usize],
    fixed: impl Fn(usize) -> Option<usize>,
    avail: Option<&[f32]>,
    f: &mut impl FnMut(usize),
) {
    /// Agent `i` on, its mask at `avail[lo..]`, the components before it giving `prefix`.
    fn visit(
        n_actions: &[usize],
        fixed: &impl Fn(usize) -> Option<usize>,
        avail: Option<&[f32]>,
        (i, lo, prefix): (usize, usize, usize),
        f: &mut impl FnMut(usize),
    ) {
        let Some(&n) = n_actions.get(i) else {
            f(prefix);
            return;
        };
        let actions = match fixed(i) {
            Some(r) => r..(r + 1).min(n),
            None => 0..n,
        };
        for a in actions {
            if avail.is_none_or(|m| m[lo + a] != 0.0) {
                visit(n_actions, fixed, avail, (i + 1, lo + n, prefix * n + a), f);
            }
        }
    }
    visit(n_actions, &fixed, avail, (0, 0, 0), f);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn ravel_is_c_order_with_agent_0_most_significant() {
        assert_eq!(ravel(&[1, 2, 3], &[3, 3, 6]), (3 + 2) * 6 + 3);
        let mut out = [0; 3];
        unravel(33, &[3, 3, 6], &mut out);
        assert_eq!(out, [1, 2, 3]);
        assert_eq!(unravel_component(33, &[3, 3, 6], 0), 1);
        assert_eq!(unravel_component(33, &[3, 3, 6], 1), 2);
        assert_eq!(unravel_component(33, &[3, 3, 6], 2), 3);
        for k in 0..54 {
            unravel(k, &[3, 3, 6], &mut out);
            assert_eq!(ravel(&out, &[3, 3, 6]), k);
        }
    }

    #[test]
    fn the_allowed_indices_are_every_index_that_qualifies_in_order() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for case in 0..2000 {
            let agents = rng.gen_range(0..=4);
            let n_actions: Vec<usize> = (0..agents).map(|_| rng.gen_range(1..=5)).collect();
            // Now and then a fixed action out of range: nothing qualifies then.
            let fixed: Vec<Option<usize>> = n_actions
                .iter()
                .map(|&n| {
                    rng.gen_bool(0.4)
                        .then(|| rng.gen_range(0..n + usize::from(case % 7 == 0)))
                })
                .collect();
            let width: usize = n_actions.iter().sum();
            let mask: Vec<f32> = (0..width).map(|_| f32::from(rng.gen_bool(0.7))).collect();
            let avail = (case % 2 == 0).then_some(mask.as_slice());
            let total: usize = n_actions.iter().product();
            let mut components = vec![0; agents];
            let want: Vec<usize> = (0..total)
                .filter(|&j| {
                    unravel(j, &n_actions, &mut components);
                    let mut lo = 0;
                    components
                        .iter()
                        .zip(&n_actions)
                        .enumerate()
                        .all(|(i, (&a, &n))| {
                            let ok = fixed[i].is_none_or(|r| r == a)
                                && avail.is_none_or(|m| m[lo + a] != 0.0);
                            lo += n;
                            ok
                        })
                })
                .collect();
            let mut got = Vec::new();
            for_each_allowed(&n_actions, |i| fixed[i], avail, &mut |j| got.push(j));
            assert_eq!(got, want, "case {case}: {n_actions:?} {fixed:?}");
        }
    }
}
