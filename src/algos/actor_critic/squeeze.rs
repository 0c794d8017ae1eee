//! Which primitive steps of an episode each learner trains on (`docs/MACROMARL.md` §2.6, 2.7):
//! the squeezes of the reference's learners, as step indices.
//!
//! - An agent's macro-actions are the steps its macro-action ended at (`valid`); one still
//!   running when the episode ended is dropped (P9).
//! - The team's joint macro-steps are the steps at which any agent's macro-action ended.
//! - Starts are the first steps of the kept macro-actions: a start whose macro-action never
//!   ended (the last one of a truncated episode) is dropped, as `_mac_start_filter` does.

use super::episode::Episode;

/// The step indices of one episode's squeezes.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Squeezed {
    /// Per agent: the steps its kept macro-actions ended at.
    pub agent_ends: Vec<Vec<usize>>,
    /// Per agent: the steps its kept macro-actions started at (same count as its ends).
    pub agent_starts: Vec<Vec<usize>>,
    /// The steps some agent's macro-action ended at.
    pub joint_ends: Vec<usize>,
    /// The steps some agent's macro-action started at, one per joint end.
    pub joint_starts: Vec<usize>,
}

impl Squeezed {
    /// The squeezes of `e`.
    pub fn of(e: &Episode) -> Self {
        let n = e.n_agents;
        let agent_ends: Vec<Vec<usize>> = (0..n)
            .map(|i| (0..e.steps).filter(|&t| e.valid(t, i)).collect())
            .collect();
        let agent_starts: Vec<Vec<usize>> = (0..n)
            .map(|i| {
                let mut s: Vec<usize> = (0..e.steps).filter(|&t| e.mac_start(t, i)).collect();
                s.truncate(agent_ends[i].len());
                s
            })
            .collect();
        let joint_ends: Vec<usize> = (0..e.steps).filter(|&t| e.joint_valid(t)).collect();
        let mut joint_starts: Vec<usize> = (0..e.steps)
            .filter(|&t| (0..n).any(|i| e.mac_start(t, i)))
            .collect();
        joint_starts.truncate(joint_ends.len());
        Squeezed {
            agent_ends,
            agent_starts,
            joint_ends,
            joint_starts,
        }
    }

    /// For Mac-IAICC: the positions j of the joint squeeze at which agent i's kept
    /// macro-actions start (its critic's values), in order (the reference's `mac_st`: the
    /// j-th joint start step is one of agent i's starts).
    pub fn agent_start_positions(&self, agent: usize) -> Vec<usize> {
        let starts = &self.agent_starts[agent];
        self.joint_starts
            .iter()
            .enumerate()
            .filter(|(_, t)| starts.binary_search(t).is_ok())
            .map(|(j, _)| j)
            .collect()
    }

    /// The positions j of the joint squeeze at which agent i's kept macro-actions end (its
    /// bootstraps in Mac-IAICC, its joint advantages in Naive Mac-IACC).
    pub fn agent_end_positions(&self, agent: usize) -> Vec<usize> {
        let ends = &self.agent_ends[agent];
        self.joint_ends
            .iter()
            .enumerate()
            .filter(|(_, t)| ends.binary_search(t).is_ok())
            .map(|(j, _)| j)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An episode of two agents from per-step `valid` flags; starts follow ends.
    fn episode(valid: &[[bool; 2]]) -> Episode {
        let mut e = Episode {
            n_agents: 2,
            steps: valid.len(),
            ..Default::default()
        };
        let mut last = [true, true];
        for v in valid {
            e.mac_start.extend(last);
            e.valid.extend(v);
            last = *v;
        }
        e
    }

    #[test]
    fn truncated_macro_actions_and_their_starts_are_dropped() {
        // Agent 0 ends at 1 and 3; agent 1 at 2 and then runs past the end.
        let e = episode(&[
            [false, false],
            [true, false],
            [false, true],
            [true, false],
            [false, false],
        ]);
        let s = Squeezed::of(&e);
        assert_eq!(s.agent_ends, [vec![1, 3], vec![2]]);
        // Agent 0's third start (step 4) never ended; agent 1's second (step 3) neither.
        assert_eq!(s.agent_starts, [vec![0, 2], vec![0]]);
        assert_eq!(s.joint_ends, [1, 2, 3]);
        // Joint starts at 0, 2, 3, 4: the last never ended.
        assert_eq!(s.joint_starts, [0, 2, 3]);
        assert_eq!(s.agent_start_positions(0), [0, 1]);
        assert_eq!(s.agent_start_positions(1), [0]);
        assert_eq!(s.agent_end_positions(0), [0, 2]);
        assert_eq!(s.agent_end_positions(1), [1]);
    }
}
