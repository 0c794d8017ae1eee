//! One training batch in the form ACAC's learner squeezes it (`learner_acac.py:
//! _squeeze_cen_exp`, `_squeeze_dec_exp`, `_get_bootstrap`), episode by episode and without
//! padding, from the episodes the runner recorded ([`Episode`], primitive step by primitive
//! step).
//!
//! For an episode of T primitive steps, call e_0 < ... < e_(L-1) the steps where some agent's
//! macro-action ended (`j_mac_v`) and s_0 < ... < s_(L-1) the steps where some agent started
//! one (`ja_st`, the last dropped if it never ended: `_mac_start_filter`). Joint macro-step k:
//! - the critic reads the observations before step e_k (`jobs`), with time s_k + 1, agent i's
//!   encoder stepping where agent i started at s_k (`mac_st`);
//! - the target critic's bootstrap rows are the observations before e_0 (all agents, time 1),
//!   then after each e_k (agent i where its macro-action ended at e_k, time e_k + 2);
//! - the reward is the joint macro-reward at e_k, the discount gamma^(e_k), terminal the flag
//!   at e_(L-1).
//!
//! Agent i's actor reads, for each of its macro-actions that ended (steps where `valid`), the
//! observation before that step, the macro-action, and the time of the macro-action's start
//! (its filtered starts, + 1); its advantage is the joint macro-step's at which it started.
//!
//! Everything here is plain data, so a golden test can build an [`AcacBatch`] from the
//! reference's own tensors as well as from recorded episodes.

use ndarray::Array2;

use crate::algos::actor_critic::episode::Episode;

/// Why episodes cannot be squeezed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BatchError {
    /// The starts and ends of macro-actions do not pair up after dropping an unfinished last
    /// start (the reference's assertion "mask for mac start does not match").
    #[error(
        "episode {episode}: {who} has {starts} macro-action starts and {ends} ends; ACAC's \
         learner needs them to pair up"
    )]
    Unpaired {
        /// The episode's index in the batch.
        episode: usize,
        /// `agent <i>` or `joint`.
        who: String,
        /// Starts after the filter.
        starts: usize,
        /// Ends.
        ends: usize,
    },
    /// The first joint macro-step does not start every agent's macro-action.
    #[error("episode {0}: agent {1} has no macro-action starting at step 0")]
    NoFirstStart(usize, usize),
    /// No episodes.
    #[error("an empty batch")]
    Empty,
}

/// One episode squeezed to its joint macro-steps and each agent's macro-actions.
#[derive(Debug, Clone, PartialEq)]
pub struct SqueezedEpisode {
    /// L joint macro-steps.
    pub joint_steps: usize,
    /// Per agent, its observation rows [L, obs_i] before each e_k (the critic's `jobs`).
    pub critic_obs: Vec<Array2<f32>>,
    /// s_k + 1 for each k.
    pub critic_time: Vec<usize>,
    /// `[k][i]`: agent i started a macro-action at s_k.
    pub critic_starts: Vec<Vec<bool>>,
    /// Per agent, its bootstrap rows [L + 1, obs_i]: before e_0, then after each e_k.
    pub bootstrap_obs: Vec<Array2<f32>>,
    /// 1, then e_k + 2.
    pub bootstrap_time: Vec<usize>,
    /// `[k][i]`: row k of the bootstrap input steps agent i (row 0: every agent).
    pub bootstrap_steps: Vec<Vec<bool>>,
    /// The joint macro-reward at e_k.
    pub rewards: Vec<f32>,
    /// e_k.
    pub end_steps: Vec<usize>,
    /// Whether the episode ended in a terminal state.
    pub terminated: bool,
    /// Per agent, its macro-actions.
    pub agents: Vec<AgentSteps>,
}

/// One agent's completed macro-actions of an episode.
#[derive(Debug, Clone, PartialEq)]
pub struct AgentSteps {
    /// The observation [M, obs_i] before each ending step.
    pub obs: Array2<f32>,
    /// The macro-action.
    pub actions: Vec<usize>,
    /// The start step + 1.
    pub time: Vec<usize>,
    /// The joint macro-step k at which each started.
    pub joint_step: Vec<usize>,
    /// The primitive step at which each ended (`acac-vanilla` weighs its policy gradient by
    /// gamma to it).
    pub end_step: Vec<usize>,
}

/// A training batch: its episodes, squeezed.
#[derive(Debug, Clone, PartialEq)]
pub struct AcacBatch {
    /// In the memory's order.
    pub episodes: Vec<SqueezedEpisode>,
}

/// Starts of one row with the last dropped when they outnumber the ends (`_mac_start_filter`).
fn filtered_starts(starts: &[usize], ends: usize) -> &[usize] {
    if starts.len() != ends && !starts.is_empty() {
        &starts[..starts.len() - 1]
    } else {
        starts
    }
}

fn agent_obs<'e>(e: &'e Episode, row: usize, offsets: &[usize], agent: usize) -> &'e [f32] {
    &e.obs_row(row)[offsets[agent]..offsets[agent + 1]]
}

impl SqueezedEpisode {
    /// Squeeze one recorded episode (`index` names it in errors); `obs_sizes` are the agents'
    /// observation lengths.
    pub fn from_episode(
        e: &Episode,
        index: usize,
        obs_sizes: &[usize],
    ) -> Result<Self, BatchError> {
        let n = e.n_agents;
        let mut offsets = vec![0];
        for &s in obs_sizes {
            offsets.push(offsets.last().copied().unwrap_or(0) + s);
        }
        let ends: Vec<usize> = (0..e.steps).filter(|&t| e.joint_valid(t)).collect();
        let joint_starts_all: Vec<usize> = (0..e.steps)
            .filter(|&t| (0..n).any(|i| e.mac_start(t, i)))
            .collect();
        let starts = filtered_starts(&joint_starts_all, ends.len());
        if starts.len() != ends.len() {
            return Err(BatchError::Unpaired {
                episode: index,
                who: "joint".into(),
                starts: starts.len(),
                ends: ends.len(),
            });
        }
        let l = ends.len();
        // Each agent's starts and ends.
        let mut agents = Vec::with_capacity(n);
        let mut agent_starts = Vec::with_capacity(n);
        for (i, &obs_size) in obs_sizes.iter().enumerate().take(n) {
            let a_ends: Vec<usize> = (0..e.steps).filter(|&t| e.valid(t, i)).collect();
            let all: Vec<usize> = (0..e.steps).filter(|&t| e.mac_start(t, i)).collect();
            let a_starts = filtered_starts(&all, a_ends.len()).to_vec();
            if a_starts.len() != a_ends.len() {
                return Err(BatchError::Unpaired {
                    episode: index,
                    who: format!("agent {i}"),
                    starts: a_starts.len(),
                    ends: a_ends.len(),
                });
            }
            // The critic's encoders need an encoding at the first joint macro-step.
            if l > 0 && !e.mac_start(starts[0], i) {
                return Err(BatchError::NoFirstStart(index, i));
            }
            // The joint macro-step at which each macro-action started: a_st at ja_st positions.
            let joint_step: Vec<usize> = starts
                .iter()
                .enumerate()
                .filter(|(_, s)| a_starts.binary_search(s).is_ok())
                .map(|(k, _)| k)
                .collect();
            if joint_step.len() != a_ends.len() {
                return Err(BatchError::Unpaired {
                    episode: index,
                    who: format!("agent {i} (at joint starts)"),
                    starts: joint_step.len(),
                    ends: a_ends.len(),
                });
            }
            let obs = Array2::from_shape_fn((a_ends.len(), obs_size), |(m, c)| {
                agent_obs(e, a_ends[m], &offsets, i)[c]
            });
            agents.push(AgentSteps {
                obs,
                actions: a_ends.iter().map(|&t| e.action(t, i)).collect(),
                time: a_starts.iter().map(|&s| s + 1).collect(),
                joint_step,
                end_step: a_ends,
            });
            agent_starts.push(a_starts);
        }
        let critic_obs = (0..n)
            .map(|i| {
                Array2::from_shape_fn((l, obs_sizes[i]), |(k, c)| {
                    agent_obs(e, ends[k], &offsets, i)[c]
                })
            })
            .collect();
        let critic_starts = starts
            .iter()
            .map(|s| (0..n).map(|i| e.mac_start(*s, i)).collect())
            .collect();
        let bootstrap_obs = (0..n)
            .map(|i| {
                Array2::from_shape_fn((l + 1, obs_sizes[i]), |(k, c)| {
                    let row = if k == 0 { ends[0] } else { ends[k - 1] + 1 };
                    agent_obs(e, row, &offsets, i)[c]
                })
            })
            .collect();
        let mut bootstrap_time = vec![1];
        bootstrap_time.extend(ends.iter().map(|&t| t + 2));
        let mut bootstrap_steps = vec![vec![true; n]];
        bootstrap_steps.extend(
            ends.iter()
                .map(|&t| (0..n).map(|i| e.valid(t, i)).collect()),
        );
        Ok(SqueezedEpisode {
            joint_steps: l,
            critic_obs,
            critic_time: starts.iter().map(|&s| s + 1).collect(),
            critic_starts,
            bootstrap_obs,
            bootstrap_time,
            bootstrap_steps,
            rewards: ends.iter().map(|&t| e.joint_reward[t]).collect(),
            end_steps: ends.clone(),
            terminated: ends.last().is_some_and(|&t| e.terminate[t]),
            agents,
        })
    }
}

impl AcacBatch {
    /// Squeeze `episodes` (ACAC's memory, oldest first).
    pub fn from_episodes<'a>(
        episodes: impl IntoIterator<Item = &'a Episode>,
        obs_sizes: &[usize],
    ) -> Result<Self, BatchError> {
        let episodes = episodes
            .into_iter()
            .enumerate()
            .map(|(k, e)| SqueezedEpisode::from_episode(e, k, obs_sizes))
            .collect::<Result<Vec<_>, _>>()?;
        if episodes.is_empty() {
            return Err(BatchError::Empty);
        }
        Ok(AcacBatch { episodes })
    }

    /// Agents.
    pub fn n_agents(&self) -> usize {
        self.episodes[0].agents.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two agents, one observation feature each (the step number, times 10 for agent 1).
    /// Agent 0's macro-actions: steps 0-1, 2, 3-4 (unfinished, cut at the horizon);
    /// agent 1's: steps 0-2, 3-4.
    fn episode() -> Episode {
        let steps = 5;
        let n = 2;
        let mut e = Episode {
            n_agents: n,
            joint_obs_size: 2,
            steps,
            ..Default::default()
        };
        for t in 0..=steps {
            e.obs.extend([t as f32, 10.0 * t as f32]);
        }
        let starts = [
            [true, true],
            [false, false],
            [true, false],
            [true, true],
            [false, false],
        ];
        let ends = [
            [false, false],
            [true, false],
            [true, true],
            [false, false],
            [false, true],
        ];
        for t in 0..steps {
            for i in 0..n {
                e.mac_start.push(starts[t][i]);
                e.valid.push(ends[t][i]);
                e.action.push((10 * i + t) as u32);
                e.reward.push(0.0);
            }
            e.joint_reward.push(t as f32 * 0.5);
            e.terminate.push(false);
        }
        e
    }

    #[test]
    fn an_episode_squeezes_as_acacs_learner_squeezes_it() {
        let s = SqueezedEpisode::from_episode(&episode(), 0, &[1, 1]).unwrap();
        // Joint ends at steps 1, 2, 4; joint starts 0, 2, 3 (no start is dropped: 3 of each).
        assert_eq!(s.end_steps, vec![1, 2, 4]);
        assert_eq!(s.critic_time, vec![1, 3, 4]);
        assert_eq!(
            s.critic_starts,
            vec![vec![true, true], vec![true, false], vec![true, true]]
        );
        // jobs: the observations before each end step.
        assert_eq!(s.critic_obs[1].column(0).to_vec(), vec![10.0, 20.0, 40.0]);
        // Bootstrap: before e_0, then after each end; agents stepping where they ended.
        assert_eq!(
            s.bootstrap_obs[0].column(0).to_vec(),
            vec![1.0, 2.0, 3.0, 5.0]
        );
        assert_eq!(s.bootstrap_time, vec![1, 3, 4, 6]);
        assert_eq!(
            s.bootstrap_steps,
            vec![
                vec![true, true],
                vec![true, false],
                vec![true, true],
                vec![false, true]
            ]
        );
        assert_eq!(s.rewards, vec![0.5, 1.0, 2.0]);
        // Agent 0 finished two macro-actions (its third start, step 3, is dropped).
        let a0 = &s.agents[0];
        assert_eq!(a0.actions, vec![1, 2]);
        assert_eq!(a0.time, vec![1, 3]);
        assert_eq!(a0.joint_step, vec![0, 1]);
        assert_eq!(a0.obs.column(0).to_vec(), vec![1.0, 2.0]);
        // Agent 1: steps 0-2 and 3-4, started at joint steps 0 and 2.
        let a1 = &s.agents[1];
        assert_eq!(a1.actions, vec![12, 14]);
        assert_eq!(a1.time, vec![1, 4]);
        assert_eq!(a1.joint_step, vec![0, 2]);
        assert!(!s.terminated);
    }

    #[test]
    fn unpaired_starts_are_an_error_not_a_panic() {
        let mut e = episode();
        // Agent 1 "ends" at step 1 too without a start in between: three ends, two starts.
        e.valid[2 + 1] = true;
        let err = SqueezedEpisode::from_episode(&e, 3, &[1, 1]).unwrap_err();
        assert!(
            matches!(err, BatchError::Unpaired { episode: 3, .. }),
            "{err}"
        );
    }
}
