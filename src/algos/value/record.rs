//! The per-primitive-step record of `docs/ALGORITHMS.md` §1.2 and the episode that stores them.
//!
//! One record per primitive step, also when nobody finished: squeezing happens at training time
//! (`docs/ALGORITHMS.md` §3.3). An [`Episode`] keeps its records in flat columns (one `Vec` per field, row `t` at
//! `t * width`), so a buffer of a thousand 150-step episodes is a handful of allocations.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use super::ReplayError;
use crate::envs::MacroEnv;

/// The shapes every record of a run shares: each agent's observation size and action count.
///
/// The joint observation is the agents' observations concatenated in agent order (`docs/ALGORITHMS.md` §1, "Joint
/// observation"); joint actions are the C-order ravel of the agents' actions (`docs/ALGORITHMS.md` §2.1).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "LayoutSizes")]
pub struct Layout {
    obs_sizes: Vec<usize>,
    n_actions: Vec<usize>,
    #[serde(skip_serializing)]
    offsets: Vec<usize>,
}

#[derive(Deserialize)]
struct LayoutSizes {
    obs_sizes: Vec<usize>,
    n_actions: Vec<usize>,
}

impl TryFrom<LayoutSizes> for Layout {
    type Error = ReplayError;
    fn try_from(s: LayoutSizes) -> Result<Self, Self::Error> {
        Layout::new(&s.obs_sizes, &s.n_actions)
    }
}

impl Layout {
    /// `obs_sizes[i]` = d_i, `n_actions[i]` = n_i. Refuses zero agents, mismatched lengths and
    /// agents without actions.
    pub fn new(obs_sizes: &[usize], n_actions: &[usize]) -> Result<Self, ReplayError> {
        if obs_sizes.is_empty() {
            return Err(ReplayError::Zero { name: "n_agents" });
        }
        if n_actions.len() != obs_sizes.len() {
            return Err(ReplayError::WrongLength {
                what: "n_actions (one per agent)",
                expected: obs_sizes.len(),
                got: n_actions.len(),
            });
        }
        if n_actions.contains(&0) {
            return Err(ReplayError::Zero { name: "n_actions" });
        }
        let mut offsets = Vec::with_capacity(obs_sizes.len() + 1);
        let mut at = 0;
        offsets.push(0);
        for &d in obs_sizes {
            at += d;
            offsets.push(at);
        }
        Ok(Self {
            obs_sizes: obs_sizes.to_vec(),
            n_actions: n_actions.to_vec(),
            offsets,
        })
    }

    /// The layout of an environment's records.
    pub fn of_env<E: MacroEnv + ?Sized>(env: &E) -> Result<Self, ReplayError> {
        Self::new(env.obs_sizes(), env.n_actions())
    }

    /// N.
    pub fn n_agents(&self) -> usize {
        self.obs_sizes.len()
    }
    /// d_i for every agent.
    pub fn obs_sizes(&self) -> &[usize] {
        &self.obs_sizes
    }
    /// n_i for every agent.
    pub fn n_actions(&self) -> &[usize] {
        &self.n_actions
    }
    /// D = sum of d_i.
    pub fn joint_obs_size(&self) -> usize {
        self.offsets[self.obs_sizes.len()]
    }
    /// A = product of n_i.
    pub fn n_joint_actions(&self) -> usize {
        self.n_actions.iter().product()
    }
    /// Where agent `agent`'s observation sits inside the joint one. Panics if `agent >= N`.
    pub fn obs_range(&self, agent: usize) -> Range<usize> {
        self.offsets[agent]..self.offsets[agent + 1]
    }
}

/// One record, borrowed: what [`Episode::push`] takes and [`Episode::record`] gives back.
///
/// Field meanings (`docs/ALGORITHMS.md` §1.2): `obs` = the joint macro-observation held before the step,
/// `executed[i]` = the macro-action agent i ran in this step, `acc_id[i]` = agent i's undiscounted
/// macro-reward so far, `acc_joint` = the joint one, `next_obs` = the joint observation after the
/// step, `done` = episode over, `valid[i]` = v_i (agent i's macro-action finished in this step).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordRef<'a> {
    /// The joint macro-observation held before the step.
    pub obs: &'a [f32],
    /// `executed[i]`: the macro-action agent i ran in this step.
    pub executed: &'a [usize],
    /// `acc_id[i]`: agent i's undiscounted macro-reward so far.
    pub acc_id: &'a [f32],
    /// The joint macro-reward so far (undiscounted).
    pub acc_joint: f32,
    /// The joint observation after the step.
    pub next_obs: &'a [f32],
    /// Episode over.
    pub done: bool,
    /// `valid[i]`: v_i, agent i's macro-action finished in this step.
    pub valid: &'a [bool],
}

impl RecordRef<'_> {
    /// vj = max_i v_i: some agent finished in this step (the joint view keeps these, `docs/ALGORITHMS.md` §3.3).
    pub fn vj(&self) -> bool {
        self.valid.iter().any(|&v| v)
    }
}

/// The records of one finished (or growing) episode in time order, stored column by column.
///
/// Invariant (checked on push and on deserialisation): every column has `len` rows of its width.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "EpisodeColumns")]
pub struct Episode {
    n_agents: usize,
    joint_obs_size: usize,
    /// [L, D]
    obs: Vec<f32>,
    /// [L, N]
    executed: Vec<usize>,
    /// [L, N]
    acc_id: Vec<f32>,
    /// [L]
    acc_joint: Vec<f32>,
    /// [L, D]
    next_obs: Vec<f32>,
    /// [L]
    done: Vec<bool>,
    /// [L, N]
    valid: Vec<bool>,
    /// [L], derived from `valid`, so not serialised.
    #[serde(skip_serializing)]
    vj: Vec<bool>,
}

/// The serialised form of [`Episode`] (everything but the derived `vj`), checked on the way in.
#[derive(Deserialize)]
struct EpisodeColumns {
    n_agents: usize,
    joint_obs_size: usize,
    obs: Vec<f32>,
    executed: Vec<usize>,
    acc_id: Vec<f32>,
    acc_joint: Vec<f32>,
    next_obs: Vec<f32>,
    done: Vec<bool>,
    valid: Vec<bool>,
}

impl TryFrom<EpisodeColumns> for Episode {
    type Error = ReplayError;
    fn try_from(c: EpisodeColumns) -> Result<Self, Self::Error> {
        if c.n_agents == 0 {
            return Err(ReplayError::Zero { name: "n_agents" });
        }
        let len = c.done.len();
        let checks: [(&'static str, usize, usize); 6] = [
            ("episode obs column", len * c.joint_obs_size, c.obs.len()),
            (
                "episode next_obs column",
                len * c.joint_obs_size,
                c.next_obs.len(),
            ),
            (
                "episode executed column",
                len * c.n_agents,
                c.executed.len(),
            ),
            ("episode acc_id column", len * c.n_agents, c.acc_id.len()),
            ("episode acc_joint column", len, c.acc_joint.len()),
            ("episode valid column", len * c.n_agents, c.valid.len()),
        ];
        for (what, expected, got) in checks {
            if expected != got {
                return Err(ReplayError::WrongLength {
                    what,
                    expected,
                    got,
                });
            }
        }
        let vj = c
            .valid
            .chunks(c.n_agents)
            .map(|v| v.iter().any(|&x| x))
            .collect();
        Ok(Self {
            n_agents: c.n_agents,
            joint_obs_size: c.joint_obs_size,
            obs: c.obs,
            executed: c.executed,
            acc_id: c.acc_id,
            acc_joint: c.acc_joint,
            next_obs: c.next_obs,
            done: c.done,
            valid: c.valid,
            vj,
        })
    }
}

impl Episode {
    /// An empty episode for `n_agents` agents and joint observation size `joint_obs_size`, with
    /// room for `capacity` records (e.g. the horizon) so pushing does not reallocate.
    pub fn new(n_agents: usize, joint_obs_size: usize, capacity: usize) -> Self {
        Self {
            n_agents,
            joint_obs_size,
            obs: Vec::with_capacity(capacity * joint_obs_size),
            executed: Vec::with_capacity(capacity * n_agents),
            acc_id: Vec::with_capacity(capacity * n_agents),
            acc_joint: Vec::with_capacity(capacity),
            next_obs: Vec::with_capacity(capacity * joint_obs_size),
            done: Vec::with_capacity(capacity),
            valid: Vec::with_capacity(capacity * n_agents),
            vj: Vec::with_capacity(capacity),
        }
    }

    /// Append one record at the end. Refuses fields of the wrong width (the episode is unchanged).
    pub fn push(&mut self, r: RecordRef<'_>) -> Result<(), ReplayError> {
        let (n, d) = (self.n_agents, self.joint_obs_size);
        let checks: [(&'static str, usize, usize); 5] = [
            ("record obs", d, r.obs.len()),
            ("record next_obs", d, r.next_obs.len()),
            ("record executed", n, r.executed.len()),
            ("record acc_id", n, r.acc_id.len()),
            ("record valid", n, r.valid.len()),
        ];
        for (what, expected, got) in checks {
            if expected != got {
                return Err(ReplayError::WrongLength {
                    what,
                    expected,
                    got,
                });
            }
        }
        self.obs.extend_from_slice(r.obs);
        self.executed.extend_from_slice(r.executed);
        self.acc_id.extend_from_slice(r.acc_id);
        self.acc_joint.push(r.acc_joint);
        self.next_obs.extend_from_slice(r.next_obs);
        self.done.push(r.done);
        self.valid.extend_from_slice(r.valid);
        self.vj.push(r.vj());
        Ok(())
    }

    /// Number of records L.
    pub fn len(&self) -> usize {
        self.done.len()
    }
    /// True before the first push.
    pub fn is_empty(&self) -> bool {
        self.done.is_empty()
    }
    /// N.
    pub fn n_agents(&self) -> usize {
        self.n_agents
    }
    /// D.
    pub fn joint_obs_size(&self) -> usize {
        self.joint_obs_size
    }
    /// Whether the last record is terminal (false for an episode the horizon truncated).
    pub fn is_finished(&self) -> bool {
        self.done.last().copied().unwrap_or(false)
    }

    /// Record `t`. Panics if `t >= len()`; the accessors below are the cheap per-field forms.
    pub fn record(&self, t: usize) -> RecordRef<'_> {
        RecordRef {
            obs: self.obs(t),
            executed: self.executed(t),
            acc_id: self.acc_id(t),
            acc_joint: self.acc_joint[t],
            next_obs: self.next_obs(t),
            done: self.done[t],
            valid: self.valid(t),
        }
    }
    /// Joint observation before step `t`, \[D\].
    pub fn obs(&self, t: usize) -> &[f32] {
        &self.obs[t * self.joint_obs_size..(t + 1) * self.joint_obs_size]
    }
    /// Joint observation after step `t`, \[D\].
    pub fn next_obs(&self, t: usize) -> &[f32] {
        &self.next_obs[t * self.joint_obs_size..(t + 1) * self.joint_obs_size]
    }
    /// Executed macro-actions at step `t`, \[N\].
    pub fn executed(&self, t: usize) -> &[usize] {
        &self.executed[t * self.n_agents..(t + 1) * self.n_agents]
    }
    /// Per-agent macro-reward accumulators at step `t`, \[N\].
    pub fn acc_id(&self, t: usize) -> &[f32] {
        &self.acc_id[t * self.n_agents..(t + 1) * self.n_agents]
    }
    /// Joint macro-reward accumulator at step `t`.
    pub fn acc_joint(&self, t: usize) -> f32 {
        self.acc_joint[t]
    }
    /// Episode-over flag of step `t`.
    pub fn done(&self, t: usize) -> bool {
        self.done[t]
    }
    /// v_i of step `t` for every agent, \[N\].
    pub fn valid(&self, t: usize) -> &[bool] {
        &self.valid[t * self.n_agents..(t + 1) * self.n_agents]
    }
    /// v_i of step `t` for one agent.
    pub fn valid_of(&self, t: usize, agent: usize) -> bool {
        self.valid[t * self.n_agents + agent]
    }
    /// vj of step `t`.
    pub fn vj(&self, t: usize) -> bool {
        self.vj[t]
    }

    /// Check that this episode has the shapes of `layout` and that every executed action is in
    /// range (buffers call this once per pushed episode, so squeezing can index freely).
    pub fn check_layout(&self, layout: &Layout) -> Result<(), ReplayError> {
        if self.n_agents != layout.n_agents() || self.joint_obs_size != layout.joint_obs_size() {
            return Err(ReplayError::LayoutMismatch {
                n_agents: self.n_agents,
                joint_obs: self.joint_obs_size,
                expected_agents: layout.n_agents(),
                expected_obs: layout.joint_obs_size(),
            });
        }
        for row in self.executed.chunks(self.n_agents) {
            for (agent, (&action, &n_actions)) in row.iter().zip(layout.n_actions()).enumerate() {
                if action >= n_actions {
                    return Err(ReplayError::ActionOutOfRange {
                        agent,
                        action,
                        n_actions,
                    });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A record of a 2-agent episode with D = 2 + 1 whose values encode `t` (for tests elsewhere).
    pub(crate) fn push_simple(ep: &mut Episode, t: usize, valid: [bool; 2], done: bool) {
        let x = t as f32;
        ep.push(RecordRef {
            obs: &[x, x + 0.1, x + 0.2],
            executed: &[t % 3, (t + 1) % 2],
            acc_id: &[x, -x],
            acc_joint: 10.0 * x,
            next_obs: &[x + 1.0, x + 1.1, x + 1.2],
            done,
            valid: &valid,
        })
        .expect("test record has the right widths");
    }

    #[test]
    fn episode_columns_return_what_was_pushed() {
        let mut ep = Episode::new(2, 3, 4);
        push_simple(&mut ep, 0, [true, false], false);
        push_simple(&mut ep, 1, [false, false], false);
        push_simple(&mut ep, 2, [false, true], true);
        assert_eq!(ep.len(), 3);
        assert!(ep.is_finished());
        let r = ep.record(2);
        assert_eq!(r.obs, &[2.0, 2.1, 2.2]);
        assert_eq!(r.next_obs, &[3.0, 3.1, 3.2]);
        assert_eq!(r.executed, &[2, 1]);
        assert_eq!(r.acc_id, &[2.0, -2.0]);
        assert_eq!(r.acc_joint, 20.0);
        assert!(r.done);
        assert_eq!(r.valid, &[false, true]);
        assert!(ep.vj(0) && !ep.vj(1) && ep.vj(2));
        assert!(ep.valid_of(0, 0) && !ep.valid_of(0, 1));
    }

    #[test]
    fn push_refuses_a_record_of_the_wrong_width() {
        let mut ep = Episode::new(2, 3, 1);
        let err = ep
            .push(RecordRef {
                obs: &[0.0; 2],
                executed: &[0, 0],
                acc_id: &[0.0, 0.0],
                acc_joint: 0.0,
                next_obs: &[0.0; 3],
                done: false,
                valid: &[true, true],
            })
            .unwrap_err();
        assert_eq!(
            err,
            ReplayError::WrongLength {
                what: "record obs",
                expected: 3,
                got: 2
            }
        );
        assert!(ep.is_empty());
    }

    #[test]
    fn episode_serde_round_trip_rebuilds_vj_and_rejects_bad_columns() {
        let mut ep = Episode::new(2, 3, 2);
        push_simple(&mut ep, 0, [false, true], false);
        push_simple(&mut ep, 1, [false, false], true);
        let json = serde_json::to_string(&ep).unwrap();
        assert!(!json.contains("\"vj\""));
        let back: Episode = serde_json::from_str(&json).unwrap();
        assert_eq!(back, ep);
        let broken = json.replace("\"acc_joint\":[0.0,10.0]", "\"acc_joint\":[0.0]");
        assert_ne!(broken, json);
        assert!(serde_json::from_str::<Episode>(&broken).is_err());
    }

    #[test]
    fn layout_gives_agent_slices_and_joint_sizes() {
        let l = Layout::new(&[13, 13, 4], &[3, 3, 6]).unwrap();
        assert_eq!(l.joint_obs_size(), 30);
        assert_eq!(l.n_joint_actions(), 54);
        assert_eq!(l.obs_range(2), 26..30);
        assert!(Layout::new(&[5], &[8, 8]).is_err());
        assert!(Layout::new(&[], &[]).is_err());
        let back: Layout = serde_json::from_str(&serde_json::to_string(&l).unwrap()).unwrap();
        assert_eq!(back, l);
    }

    #[test]
    fn check_layout_rejects_out_of_range_actions() {
        let mut ep = Episode::new(2, 3, 1);
        push_simple(&mut ep, 2, [true, true], true); // executed [2, 1]
        assert!(ep
            .check_layout(&Layout::new(&[2, 1], &[3, 2]).unwrap())
            .is_ok());
        assert_eq!(
            ep.check_layout(&Layout::new(&[2, 1], &[2, 2]).unwrap()),
            Err(ReplayError::ActionOutOfRange {
                agent: 0,
                action: 2,
                n_actions: 2
            })
        );
        assert!(matches!(
            ep.check_layout(&Layout::new(&[2, 2], &[3, 2]).unwrap()),
            Err(ReplayError::LayoutMismatch { .. })
        ));
    }
}
