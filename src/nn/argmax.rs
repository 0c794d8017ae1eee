//! The one greedy-index rule of the crate, shared by acting, targets, the conditional joint
//! argmax and deployed policies (quirk Q14): the first index of the maximal Q-value, compared
//! with strict `>` so ties keep the earliest, and a NaN never wins over a number (an all-NaN
//! input gives its first index). On finite Q-values every caller's choice is the reference's.

/// The first index of the maximal value among `(index, value)` pairs, in the order given;
/// `None` when there are none.
pub fn first_argmax(items: impl IntoIterator<Item = (usize, f32)>) -> Option<usize> {
    let mut best = FirstArgmax::default();
    for (idx, q) in items {
        best.offer(idx, q);
    }
    best.index()
}

/// [`first_argmax`] fed one pair at a time, for callers that visit their candidates (a
/// recursion over agents) instead of iterating them.
#[derive(Debug, Clone, Copy, Default)]
pub struct FirstArgmax {
    best: Option<(usize, f32)>,
}

impl FirstArgmax {
    /// The next candidate, in order.
    pub fn offer(&mut self, idx: usize, q: f32) {
        match self.best {
            Some((_, best_q)) if !(q > best_q || (best_q.is_nan() && !q.is_nan())) => {}
            _ => self.best = Some((idx, q)),
        }
    }

    /// The index chosen so far; `None` before any offer.
    pub fn index(&self) -> Option<usize> {
        self.best.map(|(idx, _)| idx)
    }
}

/// The index of the first maximal value of `q` (0 for an empty slice).
pub fn argmax(q: &[f32]) -> usize {
    first_argmax(q.iter().copied().enumerate()).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_go_to_the_lowest_index() {
        assert_eq!(argmax(&[1.0, 3.0, 3.0, -1.0]), 1);
        assert_eq!(argmax(&[-2.0, -3.0]), 0);
        assert_eq!(argmax(&[0.0, 0.5, 0.25, 0.5001]), 3);
        assert_eq!(argmax(&[]), 0);
    }

    #[test]
    fn nan_never_wins_over_a_number() {
        assert_eq!(argmax(&[f32::NAN, 1.0, 2.0]), 2);
        assert_eq!(argmax(&[1.0, f32::NAN, 0.5]), 0);
        assert_eq!(argmax(&[f32::NAN, f32::NAN]), 0);
        assert_eq!(first_argmax([(4, f32::NAN), (7, -1.0)]), Some(7));
        assert_eq!(first_argmax(std::iter::empty()), None);
    }
}
