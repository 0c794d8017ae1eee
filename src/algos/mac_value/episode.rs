//! What MacroMARL's value-based runner records (`cores/value_based/mac_dec_q/envs_runner.py` and
//! `mac_cen_q/envs_runner_cen_condi.py`, `docs/MACROMARL.md` §8.2): one record per primitive step,
//! with each agent's macro-reward discounted **inside** its macro-action and the discount its
//! bootstrap needs, and the same for the joint macro-action (restarted after any agent finished).

use crate::envs::{MacroEnv, StepOutcome};
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
        self.record_parts(
            StepParts {
                next_obs: joint_obs(env),
                executed: env.executed(),
                mac_done: env.mac_done(),
                next_avail: all_available(env),
            },
            outcome,
        )
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
