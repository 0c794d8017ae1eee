//! What MacroMARL's value-based runner records (`cores/value_based/mac_dec_q/envs_runner.py` and
//! `mac_cen_q/envs_runner_cen_condi.py`, `docs/MACROMARL.md` §8.2): one record per primitive step,
//! with each agent's macro-reward discounted **inside** its macro-action and the discount its
//! bootstrap needs, and the same for the joint macro-action (restarted after any agent finished).

use crate::envs::{FirstRecordObs, MacroEnv, StepOutcome};
use serde::{Deserialize, Serialize};

/// One primitive step of one environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Step {
    /// Every agent's observation before the step, concatenated in agent order.
    pub obs: Vec<f32>,
    /// The macro-action each agent executed (`info['cur_mac']`).
    pub actions: Vec<usize>,
    /// Agent i's macro-reward so far: sum over its macro-action's steps k = 1.. of
    /// discount^(k-1) r_k.
    pub rewards: Vec<f32>,
    /// discount^(k-1) at agent i's k-th step: with the macro-action ending here, the bootstrap is
    /// discount x this = discount^duration.
    pub gammas: Vec<f32>,
    /// The joint macro-reward (of the agents' mean reward) since any agent last finished.
    pub joint_reward: f32,
    /// discount^(k-1) of the joint macro-action.
    pub joint_gamma: f32,
    /// Every agent's observation after the step.
    pub next_obs: Vec<f32>,
    /// Every agent's macro-action availability after the step (1 available, 0 not), concatenated.
    pub next_avail: Vec<f32>,
    /// The environment reported a terminal state (a horizon cut is not one: it bootstraps).
    pub terminal: bool,
    /// Whether each agent's macro-action ended in this step (`info['mac_done']`).
    pub valid: Vec<bool>,
}

impl Step {
    /// Whether any agent's macro-action ended (the joint squeeze keeps these).
    pub fn any_valid(&self) -> bool {
        self.valid.iter().any(|&v| v)
    }
}

/// A finished episode's records, in time order.
pub type Episode = Vec<Step>;

/// The runner's accumulators for one environment, and the episode being recorded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recorder {
    discount: f64,
    last_obs: Vec<f32>,
    last_valid: Vec<bool>,
    acc: Vec<f64>,
    gamma: Vec<f64>,
    mac_steps: Vec<i32>,
    last_joint_valid: bool,
    joint_acc: f64,
    joint_gamma: f64,
    joint_steps: i32,
    steps: Episode,
}

/// Every agent's observation, concatenated in agent order.
pub fn joint_obs<E: MacroEnv>(env: &E) -> Vec<f32> {
    (0..env.n_agents())
        .flat_map(|i| env.obs(i).iter().copied())
        .collect()
}

/// Every agent's availability mask, concatenated. macdec's domains have every macro-action
/// available (so do the reference's: `get_avail_actions` is all ones in every domain).
pub fn all_available<E: MacroEnv>(env: &E) -> Vec<f32> {
    vec![1.0; env.n_actions().iter().sum()]
}

impl Recorder {
    /// The accumulators at a reset (`'reset'`: every agent just finished, nothing accumulated).
    pub fn new<E: MacroEnv>(env: &E, discount: f64) -> Self {
        Recorder::starting(joint_obs(env), env.n_agents(), discount)
    }

    /// The same from the reset's observations (concatenated) and the number of agents.
    pub fn starting(obs: Vec<f32>, n_agents: usize, discount: f64) -> Self {
        let n = n_agents;
        Recorder {
            discount,
            last_obs: obs,
            last_valid: vec![true; n],
            acc: vec![0.0; n],
            gamma: vec![0.0; n],
            mac_steps: vec![0; n],
            last_joint_valid: true,
            joint_acc: 0.0,
            joint_gamma: 0.0,
            joint_steps: 0,
            steps: Vec::new(),
        }
    }

    /// Record the step `env` just took; returns the episode when it ended (then call
    /// [`Recorder::new`] again after the reset).
    pub fn record<E: MacroEnv>(&mut self, env: &E, outcome: StepOutcome) -> Option<Episode> {
        let first = self.steps.is_empty();
        let mut ended = self.record_parts(
            StepParts {
                next_obs: joint_obs(env),
                executed: env.executed(),
                mac_done: env.mac_done(),
                next_avail: all_available(env),
            },
            outcome,
        );
        // Quirk Q20 (`MacroEnv::first_record_obs`): the runner's first record holds the list
        // `env.reset()` returned, which the first step overwrote for the agents that finished in
        // it (the Warehouse domains; `last_obs = env.reset()` in the value runners too).
        if first && env.first_record_obs() == FirstRecordObs::OverwrittenByFirstStep {
            let step = match ended.as_mut() {
                Some(episode) => &mut episode[0],
                None => &mut self.steps[0],
            };
            let mut at = 0;
            for i in 0..env.n_agents() {
                let len = env.obs(i).len();
                if env.mac_done()[i] {
                    step.obs[at..at + len].copy_from_slice(env.obs(i));
                }
                at += len;
            }
        }
        ended
    }

    /// [`Recorder::record`] from the step's parts (what the reference's worker reads off
    /// `env.step` and `env.get_avail_actions()`), with the team reward every agent receives.
    pub fn record_parts(&mut self, parts: StepParts<'_>, outcome: StepOutcome) -> Option<Episode> {
        let valid = parts.mac_done.to_vec();
        let n = valid.len();
        let r = outcome.reward;
        for i in 0..n {
            if self.last_valid[i] {
                self.acc[i] = r;
                self.mac_steps[i] = 1;
                self.gamma[i] = 1.0;
            } else {
                self.mac_steps[i] += 1;
                let g = self.discount.powf(f64::from(self.mac_steps[i] - 1));
                self.acc[i] += g * r;
                self.gamma[i] = g;
            }
        }
        // The joint macro-reward is of the agents' mean reward (`sum(reward) / n_agent`).
        let mean = (0..n).map(|_| r).sum::<f64>() / n as f64;
        if self.last_joint_valid {
            self.joint_acc = mean;
            self.joint_steps = 1;
            self.joint_gamma = 1.0;
        } else {
            self.joint_steps += 1;
            let g = self.discount.powf(f64::from(self.joint_steps - 1));
            self.joint_acc += g * mean;
            self.joint_gamma = g;
        }
        self.last_joint_valid = valid.iter().any(|&v| v);
        self.last_valid.clone_from(&valid);
        self.steps.push(Step {
            obs: std::mem::replace(&mut self.last_obs, parts.next_obs.clone()),
            actions: parts.executed.to_vec(),
            rewards: self.acc.iter().map(|&a| a as f32).collect(),
            gammas: self.gamma.iter().map(|&g| g as f32).collect(),
            joint_reward: self.joint_acc as f32,
            joint_gamma: self.joint_gamma as f32,
            next_obs: parts.next_obs,
            next_avail: parts.next_avail,
            terminal: outcome.terminal(),
            valid,
        });
        outcome.done.then(|| std::mem::take(&mut self.steps))
    }
}

/// What one primitive step produced, as the recorder reads it.
#[derive(Debug, Clone)]
pub struct StepParts<'a> {
    /// Every agent's observation after the step, concatenated.
    pub next_obs: Vec<f32>,
    /// The macro-action each agent executed.
    pub executed: &'a [usize],
    /// Whether each agent's macro-action ended.
    pub mac_done: &'a [bool],
    /// Every agent's availability mask after the step, concatenated.
    pub next_avail: Vec<f32>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::value::recorder::tests::{script, FakeEnv};
    use crate::envs::EnvRng;
    use rand::SeedableRng;

    #[test]
    fn the_first_record_shows_the_first_steps_observation_only_under_quirk_q20() {
        let mut s = script();
        s[0].2 = [true, false]; // agent 0 finishes at step 1: its observation becomes 10
        let first_obs = |first: FirstRecordObs| {
            let mut rng = EnvRng::seed_from_u64(0);
            let mut env = FakeEnv::new(s.clone());
            env.first = first;
            env.reset(&mut rng);
            let mut rec = Recorder::new(&env, 0.9);
            for _ in 0..2 {
                let o = env.step(&[0, 0], &mut rng).unwrap();
                rec.record(&env, o);
            }
            (rec.steps[0].obs.clone(), rec.steps[1].obs.clone())
        };
        let faithful = first_obs(FirstRecordObs::OverwrittenByFirstStep);
        let fixed = first_obs(FirstRecordObs::Reset);
        assert_eq!(faithful.0, [10.0, -2.0]);
        assert_eq!(fixed.0, [-1.0, -2.0]);
        assert_eq!(faithful.1, fixed.1);
    }

    #[test]
    fn macro_rewards_are_discounted_inside_the_macro_action() {
        // Agent 0 runs one 3-step macro-action, agent 1 finishes every step; reward 1 per step.
        let mut rec = Recorder::starting(vec![0.0, 0.0], 2, 0.5);
        let mut last = None;
        for (t, done0) in [false, false, true].into_iter().enumerate() {
            let parts = StepParts {
                next_obs: vec![t as f32, t as f32],
                executed: &[3, 1],
                mac_done: &[done0, true],
                next_avail: vec![1.0; 4],
            };
            last = rec.record_parts(parts, StepOutcome::running(1.0));
        }
        assert!(last.is_none());
        let third = &rec.steps[2];
        // 1 + 0.5 + 0.25, gamma_b = 0.5^2: the bootstrap is 0.5 x 0.25 = 0.5^3.
        assert_eq!((third.rewards[0], third.gammas[0]), (1.75, 0.25));
        assert_eq!((third.rewards[1], third.gammas[1]), (1.0, 1.0));
        // The joint macro-action restarts after any agent finished: every step here.
        assert_eq!((third.joint_reward, third.joint_gamma), (1.0, 1.0));
    }
}
