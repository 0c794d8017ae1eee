//! The conditional argmax of the centralized Q-net (spec `algorithms.md` 2.1 and 4.5).
//!
//! Joint index = C-order ravel of `(m_0, .., m_{N-1})`, agent 0 most significant
//! ([`crate::nn::joint_index`]): `idx = ((m_0 * n_1) + m_1) * n_2 + m_2`. The conditional argmax maximises only over the joint
//! actions whose busy agents' components equal their running macro-actions (`c_i >= 0`), free
//! agents (`c_i = -1`) ranging over all their actions; ties go to the first maximal flat index in
//! C-order (quirk Q14). Only allowed combinations are visited.

use ndarray::{ArrayView1, ArrayView2};

use crate::nn::argmax::FirstArgmax;
use crate::nn::joint_index::for_each_allowed;

/// Why a conditional argmax was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CondArgmaxError {
    /// Q's columns are not the joint action count.
    #[error("Q has {got} columns, expected the {expected} joint actions")]
    WrongWidth {
        /// Joint actions (product of the agents' counts).
        expected: usize,
        /// Columns of Q.
        got: usize,
    },
    /// The conditioning has the wrong number of entries.
    #[error(
        "conditioning has {got} entries, expected {expected} ({rows} rows x {n_agents} agents)"
    )]
    WrongCondLength {
        /// rows x agents.
        expected: usize,
        /// Entries given.
        got: usize,
        /// Rows of Q.
        rows: usize,
        /// Agents.
        n_agents: usize,
    },
    /// A conditioning entry that is neither -1 (free) nor an action of its agent.
    #[error(
        "row {row}, agent {agent}: conditioning value {value} is neither -1 nor in 0..{n_actions}"
    )]
    BadCondition {
        /// Row of Q.
        row: usize,
        /// The agent.
        agent: usize,
        /// The entry.
        value: i32,
        /// Macro-actions the agent has.
        n_actions: usize,
    },
    /// No agents, so no joint action.
    #[error("no agents")]
    NoAgents,
}

/// The conditional argmax of one joint Q vector `q` \[A\] under `cond` \[N\] (-1 = free).
///
/// Among allowed joint actions, returns the first (in C-order) maximal one; NaN entries never win
/// a comparison, so an all-NaN row returns the first allowed index.
pub fn cond_argmax(
    q: ArrayView1<'_, f32>,
    n_actions: &[usize],
    cond: &[i32],
) -> Result<usize, CondArgmaxError> {
    let q2 = q.insert_axis(ndarray::Axis(0));
    Ok(cond_argmax_rows(q2, n_actions, cond)?[0])
}

/// [`cond_argmax`] for every row: `q` [K, A], `cond` [K * N] (row-major, row k's conditioning at
/// `cond[k * N .. (k + 1) * N]`). Returns K joint indices.
pub fn cond_argmax_rows(
    q: ArrayView2<'_, f32>,
    n_actions: &[usize],
    cond: &[i32],
) -> Result<Vec<usize>, CondArgmaxError> {
    let n_agents = n_actions.len();
    if n_agents == 0 {
        return Err(CondArgmaxError::NoAgents);
    }
    let a: usize = n_actions.iter().product();
    let (rows, width) = q.dim();
    if width != a {
        return Err(CondArgmaxError::WrongWidth {
            expected: a,
            got: width,
        });
    }
    if cond.len() != rows * n_agents {
        return Err(CondArgmaxError::WrongCondLength {
            expected: rows * n_agents,
            got: cond.len(),
            rows,
            n_agents,
        });
    }
    let mut out = Vec::with_capacity(rows);
    for (row, (q_row, c)) in q.outer_iter().zip(cond.chunks(n_agents)).enumerate() {
        for (agent, (&ci, &n)) in c.iter().zip(n_actions).enumerate() {
            if ci != -1 && usize::try_from(ci).map_or(true, |c| c >= n) {
                return Err(CondArgmaxError::BadCondition {
                    row,
                    agent,
                    value: ci,
                    n_actions: n,
                });
            }
        }
        let mut best = FirstArgmax::default();
        let fixed = |i: usize| usize::try_from(c[i]).ok();
        for_each_allowed(n_actions, fixed, None, &mut |idx| {
            best.offer(idx, q_row[idx])
        });
        out.push(best.index().expect("at least one allowed joint action"));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::{Array1, Array2};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use crate::nn::joint_index::{ravel, unravel};

    /// The 8x8 Box Pushing joint table Q[m0, m1] = 10 * m0 + m1 with two planted maxima.
    fn table_8x8() -> Array1<f32> {
        let mut q = Array1::from_shape_fn(64, |k| (10 * (k / 8) + k % 8) as f32 / 100.0);
        q[ravel(&[2, 5], &[8, 8])] = 5.0; // global maximum
        q[ravel(&[6, 1], &[8, 8])] = 4.0; // best with m0 = 6 ... tied below
        q[ravel(&[6, 3], &[8, 8])] = 4.0;
        q
    }

    #[test]
    fn free_free_picks_the_global_maximum() {
        let q = table_8x8();
        assert_eq!(
            cond_argmax(q.view(), &[8, 8], &[-1, -1]).unwrap(),
            2 * 8 + 5
        );
    }

    #[test]
    fn agent_0_fixed_maximises_over_agent_1_only_and_breaks_ties_first() {
        let q = table_8x8();
        // agent 0 busy with 6: row 6 holds 4.0 at m1 = 1 and 3; the first wins
        assert_eq!(cond_argmax(q.view(), &[8, 8], &[6, -1]).unwrap(), 6 * 8 + 1);
        // agent 0 busy with 0: row 0 is increasing, maximum at m1 = 7
        assert_eq!(cond_argmax(q.view(), &[8, 8], &[0, -1]).unwrap(), 7);
        // agent 1 busy with 5: column 5, the planted 5.0 at m0 = 2
        assert_eq!(cond_argmax(q.view(), &[8, 8], &[-1, 5]).unwrap(), 2 * 8 + 5);
        // both busy: the only allowed action
        assert_eq!(cond_argmax(q.view(), &[8, 8], &[3, 4]).unwrap(), 3 * 8 + 4);
    }

    #[test]
    fn rows_match_a_brute_force_masked_argmax_on_random_tables() {
        let n_actions = [3, 3, 6];
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let k = 200;
        // values on a coarse grid so ties happen
        let q = Array2::from_shape_fn((k, 54), |_| rng.gen_range(0..5) as f32);
        let cond: Vec<i32> = (0..k * 3)
            .map(|j| {
                if rng.gen_bool(0.5) {
                    -1
                } else {
                    rng.gen_range(0..n_actions[j % 3] as i32)
                }
            })
            .collect();
        let got = cond_argmax_rows(q.view(), &n_actions, &cond).unwrap();
        let mut m = [0usize; 3];
        for row in 0..k {
            let c = &cond[row * 3..row * 3 + 3];
            let mut best: Option<(usize, f32)> = None;
            for idx in 0..54 {
                unravel(idx, &n_actions, &mut m);
                let allowed = (0..3).all(|i| c[i] == -1 || m[i] as i32 == c[i]);
                if allowed && best.is_none_or(|(_, b)| q[[row, idx]] > b) {
                    best = Some((idx, q[[row, idx]]));
                }
            }
            assert_eq!(got[row], best.unwrap().0, "row {row} cond {c:?}");
        }
    }

    #[test]
    fn unconditioned_rows_equal_plain_argmax() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let q = Array2::from_shape_fn((50, 64), |_| rng.gen::<f32>());
        let got = cond_argmax_rows(q.view(), &[8, 8], &vec![-1; 100]).unwrap();
        for (row, &g) in got.iter().enumerate() {
            let r = q.row(row);
            let plain = (0..64).fold(0, |b, j| if r[j] > r[b] { j } else { b });
            assert_eq!(g, plain);
        }
    }

    #[test]
    fn refuses_bad_shapes_and_conditions() {
        let q = Array2::<f32>::zeros((2, 64));
        assert!(matches!(
            cond_argmax_rows(q.view(), &[8, 8], &[-1; 3]),
            Err(CondArgmaxError::WrongCondLength { .. })
        ));
        assert!(matches!(
            cond_argmax_rows(q.view(), &[8, 7], &[-1; 4]),
            Err(CondArgmaxError::WrongWidth { .. })
        ));
        assert_eq!(
            cond_argmax_rows(q.view(), &[8, 8], &[-1, -1, 8, -1]),
            Err(CondArgmaxError::BadCondition {
                row: 1,
                agent: 0,
                value: 8,
                n_actions: 8
            })
        );
        assert!(cond_argmax_rows(q.view(), &[8, 8], &[-2, -1, -1, -1]).is_err());
    }

    #[test]
    fn nan_never_wins() {
        let mut q = Array1::<f32>::zeros(4);
        q[0] = f32::NAN;
        q[2] = 1.0;
        assert_eq!(cond_argmax(q.view(), &[2, 2], &[-1, -1]).unwrap(), 2);
    }
}
