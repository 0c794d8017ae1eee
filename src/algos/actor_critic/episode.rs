//! What MacroMARL's runner worker records per primitive step (`docs/MACROMARL.md` §2.2,
//! `cores/pg_based/mac_niacc/envs_runner.py: worker`), one episode per training lane.
//!
//! Per agent, the macro-reward is discounted inside the macro-action (P6): it restarts at the
//! first primitive step of each macro-action and adds gamma^(k-1) r at its k-th step; the joint
//! reward does the same per joint macro-step with the agents' mean reward. Sums are in f64 with
//! the reference's operation order and stored as f32, as the reference's tensors are.

use serde::{Deserialize, Serialize};

use crate::algos::learner::EvalReturns;
use crate::envs::{FirstRecordObs, MacroEnv, StepOutcome};

/// One recorded episode: row t of the per-step fields is primitive step t; `obs` and `state`
/// have one more row (row t is the observation before step t, row t + 1 the one after it).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Episode {
    /// Agents in the domain.
    pub n_agents: usize,
    /// Length of one `obs` row (every agent's observation).
    pub joint_obs_size: usize,
    /// Length of one `state` row (0 for a domain without a global state).
    pub state_size: usize,
    /// Primitive steps recorded.
    pub steps: usize,
    /// Every agent's observation concatenated (agent 0 first), `steps + 1` rows.
    pub obs: Vec<f32>,
    /// `get_state()`, `steps + 1` rows (empty when the learner has no state critic).
    pub state: Vec<f32>,
    /// Whether step t is the first primitive step of agent i's macro-action (`last_mac_start`).
    pub mac_start: Vec<bool>,
    /// The macro-action agent i executed at step t (`info['cur_mac']`).
    pub action: Vec<u32>,
    /// Agent i's discounted macro-reward so far at step t (`accu_rewards`).
    pub reward: Vec<f32>,
    /// The joint macro-step's discounted mean reward so far (`accu_joint_reward`).
    pub joint_reward: Vec<f32>,
    /// The environment's terminal flag after step t (not a horizon cut, P5).
    pub terminate: Vec<bool>,
    /// Whether agent i's macro-action ended at step t (`mac_done`).
    pub valid: Vec<bool>,
}

impl Episode {
    /// Agent i's slice of row `t` of `obs`, given the agents' observation offsets.
    pub fn obs_row(&self, t: usize) -> &[f32] {
        &self.obs[t * self.joint_obs_size..(t + 1) * self.joint_obs_size]
    }

    /// Row t of `state`.
    pub fn state_row(&self, t: usize) -> &[f32] {
        &self.state[t * self.state_size..(t + 1) * self.state_size]
    }

    /// Whether agent i's macro-action ended at step t.
    pub fn valid(&self, t: usize, agent: usize) -> bool {
        self.valid[t * self.n_agents + agent]
    }

    /// Whether some agent's macro-action ended at step t (`max(valid)`).
    pub fn joint_valid(&self, t: usize) -> bool {
        self.valid[t * self.n_agents..(t + 1) * self.n_agents]
            .iter()
            .any(|&v| v)
    }

    /// Whether step t starts agent i's macro-action.
    pub fn mac_start(&self, t: usize, agent: usize) -> bool {
        self.mac_start[t * self.n_agents + agent]
    }

    /// Agent i's executed macro-action at step t.
    pub fn action(&self, t: usize, agent: usize) -> usize {
        self.action[t * self.n_agents + agent] as usize
    }

    /// Agent i's macro-reward at step t.
    pub fn reward(&self, t: usize, agent: usize) -> f32 {
        self.reward[t * self.n_agents + agent]
    }
}

/// The worker's accumulators for the episode in progress on one lane.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EpisodeRecorder {
    episode: Episode,
    with_state: bool,
    gamma: f64,
    last_valid: Vec<bool>,
    acc: Vec<f64>,
    mac_steps: Vec<i32>,
    acc_joint: f64,
    joint_steps: i32,
    /// The episode's return: sum over primitive steps of gamma^t times the mean reward.
    ret: f64,
    /// The undiscounted return so far.
    plain: f64,
}

impl EpisodeRecorder {
    /// A recorder for episodes of `env`'s domain; `with_state` records `get_state()` too.
    pub fn new<E: MacroEnv>(env: &E, gamma: f64, with_state: bool) -> Self {
        let mut r = EpisodeRecorder {
            with_state,
            gamma,
            ..Default::default()
        };
        r.begin(env);
        r
    }

    /// Start a new episode from `env` just reset (the worker's `reset`).
    pub fn begin<E: MacroEnv>(&mut self, env: &E) {
        let n = env.n_agents();
        let e = &mut self.episode;
        e.n_agents = n;
        e.joint_obs_size = env.joint_obs_size();
        e.state_size = if self.with_state { env.state_size() } else { 0 };
        e.steps = 0;
        for v in [&mut e.obs, &mut e.state, &mut e.reward, &mut e.joint_reward] {
            v.clear();
        }
        e.mac_start.clear();
        e.action.clear();
        e.terminate.clear();
        e.valid.clear();
        self.push_observation(env);
        // Reused across episodes: nothing is allocated per episode once warm.
        self.last_valid.clear();
        self.last_valid.resize(n, true);
        self.acc.clear();
        self.acc.resize(n, 0.0);
        self.mac_steps.clear();
        self.mac_steps.resize(n, 0);
        self.acc_joint = 0.0;
        self.joint_steps = 0;
        self.ret = 0.0;
        self.plain = 0.0;
    }

    fn push_observation<E: MacroEnv>(&mut self, env: &E) {
        let e = &mut self.episode;
        for i in 0..e.n_agents {
            e.obs.extend_from_slice(env.obs(i));
        }
        if e.state_size > 0 {
            let at = e.state.len();
            e.state.resize(at + e.state_size, 0.0);
            env.write_state(&mut e.state[at..]);
        }
    }

    /// Record the step `env` just took with `outcome` (the worker's `step`).
    pub fn record<E: MacroEnv>(&mut self, env: &E, outcome: StepOutcome) {
        let n = self.episode.n_agents;
        let g = self.gamma;
        let r = outcome.reward;
        let done = env.mac_done();
        let e = &mut self.episode;
        for (i, &ended) in done.iter().enumerate() {
            e.mac_start.push(self.last_valid[i]);
            if self.last_valid[i] {
                self.acc[i] = r;
                self.mac_steps[i] = 1;
            } else {
                self.mac_steps[i] += 1;
                self.acc[i] += g.powf(f64::from(self.mac_steps[i] - 1)) * r;
            }
            e.reward.push(self.acc[i] as f32);
            e.action.push(env.executed()[i] as u32);
            e.valid.push(ended);
        }
        // sum(reward) / n_agent, summed in agent order as Python does.
        let sum: f64 = (0..n).fold(0.0, |s, _| s + r);
        let mean = sum / n as f64;
        if self.last_valid.iter().any(|&v| v) {
            self.acc_joint = mean;
            self.joint_steps = 1;
        } else {
            self.joint_steps += 1;
            self.acc_joint += g.powf(f64::from(self.joint_steps - 1)) * mean;
        }
        e.joint_reward.push(self.acc_joint as f32);
        e.terminate.push(outcome.terminal());
        self.last_valid.copy_from_slice(done);
        self.ret += g.powf(e.steps as f64) * sum / n as f64;
        self.plain += sum / n as f64;
        e.steps += 1;
        self.push_observation(env);
        // Quirk Q20 (`MacroEnv::first_record_obs`): the runner's first record holds the env's
        // reset list, which the first step overwrote for the agents that finished in it.
        let e = &mut self.episode;
        if e.steps == 1 && env.first_record_obs() == FirstRecordObs::OverwrittenByFirstStep {
            let mut at = 0;
            for (i, &ended) in done.iter().enumerate() {
                let len = env.obs(i).len();
                if ended {
                    e.obs[at..at + len].copy_from_slice(env.obs(i));
                }
                at += len;
            }
        }
    }

    /// The episode so far.
    pub fn episode(&self) -> &Episode {
        &self.episode
    }

    /// The episode's returns so far: discounted (the worker's `R`) and undiscounted (the plain
    /// sum of the agents' mean reward).
    pub fn returns(&self) -> EvalReturns {
        EvalReturns {
            discounted: self.ret,
            undiscounted: self.plain,
        }
    }

    /// Which agents are free to choose (their macro-action ended at the last step, or the
    /// episode just began).
    pub fn free(&self) -> &[bool] {
        &self.last_valid
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::{EnvRng, MacroEnv};
    use rand::SeedableRng;

    #[test]
    fn macro_rewards_restart_at_each_macro_action_and_discount_inside_it() {
        let spec = crate::envs::bp_ma_v0::spec(6, 30);
        let mut env = spec.build().unwrap();
        let mut rng = EnvRng::seed_from_u64(0);
        env.reset(&mut rng);
        let mut rec = EpisodeRecorder::new(&env, 0.9, true);
        let mut steps = 0;
        let (mut discounted, mut plain) = (0.0, 0.0);
        loop {
            let o = env.step(&[0, 1], &mut rng).unwrap();
            rec.record(&env, o);
            discounted += 0.9f64.powi(steps as i32) * o.reward;
            plain += o.reward;
            steps += 1;
            if o.done || steps == 12 {
                break;
            }
        }
        let e = rec.episode();
        assert_eq!(e.steps, steps);
        assert_eq!(e.obs.len(), (steps + 1) * env.joint_obs_size());
        assert_eq!(e.state.len(), (steps + 1) * env.state_size());
        // Every agent starts a macro-action at step 0; a start follows every end.
        for i in 0..2 {
            assert!(e.mac_start(0, i));
            for t in 1..steps {
                assert_eq!(e.mac_start(t, i), e.valid(t - 1, i));
            }
        }
        // The returns are the discounted and the plain sums of the (team = mean) reward.
        let r = rec.returns();
        assert!(
            (r.discounted - discounted).abs() < 1e-9,
            "{r:?} {discounted}"
        );
        assert!((r.undiscounted - plain).abs() < 1e-9, "{r:?} {plain}");
        assert!(plain < 0.0 && r.discounted != r.undiscounted, "{r:?}");
    }

    #[test]
    fn the_first_record_shows_the_first_steps_observation_only_under_quirk_q20() {
        use crate::algos::value::recorder::tests::{script, FakeEnv};
        let mut s = script();
        s[0].2 = [true, false]; // agent 0 finishes at step 1: its observation becomes 10
        let first_obs = |first: FirstRecordObs| {
            let mut rng = EnvRng::seed_from_u64(0);
            let mut env = FakeEnv::new(s.clone());
            env.first = first;
            env.reset(&mut rng);
            let mut rec = EpisodeRecorder::new(&env, 0.9, false);
            for _ in 0..2 {
                let o = env.step(&[0, 0], &mut rng).unwrap();
                rec.record(&env, o);
            }
            let e = rec.episode();
            (
                e.obs_row(0).to_vec(),
                e.obs_row(1).to_vec(),
                e.obs_row(2).to_vec(),
            )
        };
        let faithful = first_obs(FirstRecordObs::OverwrittenByFirstStep);
        let fixed = first_obs(FirstRecordObs::Reset);
        assert_eq!(faithful.0, [10.0, -2.0]);
        assert_eq!(fixed.0, [-1.0, -2.0]);
        // Later rows are the same either way.
        assert_eq!((faithful.1, faithful.2), (fixed.1, fixed.2));
    }
}
