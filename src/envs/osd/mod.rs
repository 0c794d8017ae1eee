//! MacroMARL's Warehouse Tool Delivery environments A–E (GitHub `yuchen-x/MacroMARL`,
//! `my_env/osd_ma_{double,tripple,four}_room.py` with their `core_*_room.py`), exact step for
//! step: `OSD-D-v7` (Warehouse A and B), `OSD-T-v0` (C), `OSD-T-v1` (D), `OSD-F-v0` (E).
//!
//! Turtlebots carry tools from a table in the tool room to humans working in their own areas; a
//! Fetch arm finds the tools and passes them over. Each human needs tools 0, 1, 2 in order; the
//! episode is terminal when every human got its third tool (`docs/MACROMARL.md` §3.2). The four
//! reference classes share their logic, so one generic environment [`Osd`] serves them, the
//! const parameter picking its [`Layout`] (their differences, all in `layout.rs`).
//!
//! The horizon is the runner's (`env_terminate_step`): the cut there is *truncated* (the learner
//! bootstraps), except in OSD-F-v0, whose env itself is terminal at `terminate_step`.
//!
//! **Optimum: unknown** ([`MacroEnv::optimal_return`] is `None`). Every delivery is worth at
//! most 100 and every step costs 1, so a return is at most 300 x humans - steps (`docs/MACROMARL.md` §3.2). Lower
//! bounds at the published settings (undiscounted): the scripted team of `scenarios.rs` gets
//! A 533 in 67 steps (the bound for that length), C 797 in 103, D 760 in 100, E 1051 in 129;
//! the reference's shipped learned policies get C 801 in 99, D 781 in 99, E 1050 in 130
//! (`docs/MACROMARL.md` §4).
//!
//! The published settings draw nothing; with `TB_move_noisy` or `fetch_manip_noisy` set, steps
//! draw from the caller's [`EnvRng`] (same distributions as the reference, not its numbers).

mod domain;
pub mod draw;
mod fetch;
mod human;
pub mod layout;
mod observe;
mod params;
mod render;
mod turtlebot;

#[cfg(test)]
mod scenarios;

pub use domain::{OsdDomain, OSD_D_V7, OSD_F_V0, OSD_T_V0, OSD_T_V1};
pub use fetch::{Fetch, FetchAction};
pub use human::Human;
pub use layout::{Layout, D7, F0, LAYOUTS, T0, T1};
pub use params::OsdParams;
pub use turtlebot::{numpy_round2, Turtlebot};

use rand_distr::Normal;

use crate::envs::{EnvError, EnvRng, FirstRecordObs, MacroEnv, StepOutcome};

/// Warehouse A/B (`OSD-D-v7`).
pub type OsdD7 = Osd<D7>;
/// Warehouse C (`OSD-T-v0`).
pub type OsdT0 = Osd<T0>;
/// Warehouse D (`OSD-T-v1`).
pub type OsdT1 = Osd<T1>;
/// Warehouse E (`OSD-F-v0`).
pub type OsdF0 = Osd<F0>;

/// One of MacroMARL's Warehouse environments, [`LAYOUTS`]`[V]`. Each `V` is its own type, so
/// each gym id has its own [`crate::envs::AnyEnv`] variant. Build with [`Osd::new`]; it starts
/// reset.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Osd<const V: usize> {
    params: OsdParams,
    noise: Option<Normal<f64>>,
    tbs: Vec<Turtlebot>,
    fetch: Fetch,
    humans: Vec<Human>,
    /// Which humans got their third tool (`finish_serve_humans`), and how many.
    served: Vec<bool>,
    n_served: usize,
    /// Primitive steps since reset (`count_step`).
    count: usize,
    /// Set once `done` was returned; stepping again is an error until reset.
    over: bool,
    executed: Vec<usize>,
    mac_done: Vec<bool>,
    /// Each agent's observation as the last step returned it (Turtlebots, then the Fetch).
    obs: Vec<Vec<f32>>,
    /// The Turtlebots' observations kept for busy steps (the reference's `old_observations`;
    /// see [`Layout::held_obs_slot`]).
    held: Vec<Vec<f32>>,
    obs_sizes: Vec<usize>,
    n_actions: Vec<usize>,
    /// Reward of the last step (for pictures only).
    last_reward: f64,
}

impl<const V: usize> Osd<V> {
    /// The layout this environment follows.
    pub fn layout() -> &'static Layout {
        &LAYOUTS[V]
    }

    /// The environment with `params`, reset.
    pub fn new(params: OsdParams) -> Result<Self, EnvError> {
        let layout = Self::layout();
        params.validate(layout)?;
        let n_tb = layout.n_turtlebots();
        let mut obs_sizes = vec![layout.tb_obs_size(params.obs_human_wait); n_tb];
        obs_sizes.push(layout.fetch_obs_size(params.obs_human_wait));
        let mut n_actions = vec![layout.tb_action_names.len(); n_tb];
        n_actions.push(layout.fetch_action_names.len());
        let noise = (params.tb_move_noisy > 0.0)
            .then(|| Normal::new(0.0, params.tb_move_noisy).expect("std checked finite, > 0"));
        let mut env = Osd {
            noise,
            tbs: Vec::new(),
            fetch: Fetch::default(),
            humans: params.human_speeds.iter().map(|&s| Human::new(s)).collect(),
            served: vec![false; layout.n_humans()],
            n_served: 0,
            count: 0,
            over: false,
            executed: vec![0; n_tb + 1],
            mac_done: vec![true; n_tb + 1],
            obs: obs_sizes.iter().map(|&n| vec![0.0; n]).collect(),
            held: obs_sizes[..n_tb].iter().map(|&n| vec![0.0; n]).collect(),
            obs_sizes,
            n_actions,
            last_reward: 0.0,
            params,
        };
        env.reset_state();
        Ok(env)
    }

    /// The environment with the published settings and `horizon`.
    pub fn published(horizon: usize) -> Result<Self, EnvError> {
        Self::new(OsdParams {
            horizon,
            terminate_step: horizon,
            ..OsdParams::published(Self::layout())
        })
    }

    /// The parameters the environment was built with.
    pub fn params(&self) -> &OsdParams {
        &self.params
    }
    /// The Turtlebots' current states.
    pub fn turtlebots(&self) -> &[Turtlebot] {
        &self.tbs
    }
    /// The Fetch's current state.
    pub fn fetch(&self) -> &Fetch {
        &self.fetch
    }
    /// The humans' current states.
    pub fn humans(&self) -> &[Human] {
        &self.humans
    }
    /// Reward of the last step (0 after reset).
    pub fn last_reward(&self) -> f64 {
        self.last_reward
    }

    /// `reset()`: new robots (`createAgents`), humans at their first step, reset observations.
    fn reset_state(&mut self) {
        let layout = Self::layout();
        self.tbs.clear();
        self.tbs
            .extend(layout.tb_starts.iter().map(|&s| Turtlebot::new(s)));
        self.fetch = Fetch::default();
        for h in &mut self.humans {
            *h = Human::new(h.speeds);
        }
        self.served.fill(false);
        self.n_served = 0;
        self.count = 0;
        self.over = false;
        self.executed.fill(0);
        self.mac_done.fill(true);
        self.last_reward = 0.0;
        let n_tb = self.tbs.len();
        for (o, h) in self.obs[..n_tb].iter_mut().zip(&mut self.held) {
            observe::write_tb_reset_obs(layout, o);
            h.copy_from_slice(o);
        }
        self.obs[n_tb].fill(0.0);
    }

    fn check_actions(&self, actions: &[usize]) -> Result<(), EnvError> {
        if actions.len() != self.n_actions.len() {
            return Err(EnvError::WrongActionCount {
                expected: self.n_actions.len(),
                got: actions.len(),
            });
        }
        for (agent, (&a, &n)) in actions.iter().zip(&self.n_actions).enumerate() {
            if self.mac_done[agent] && a >= n {
                return Err(EnvError::ActionOutOfRange {
                    agent,
                    action: a,
                    n_actions: n,
                });
            }
        }
        Ok(())
    }

    /// One step in the reference's order: Turtlebots, the Fetch, the served test, the humans,
    /// the observations of the agents that finished. Returns (reward, terminal).
    fn advance(&mut self, actions: &[usize], rng: &mut EnvRng) -> (f64, bool) {
        let layout = Self::layout();
        let p = &self.params;
        self.count += 1;
        let mut reward = -1.0;
        for (i, tb) in self.tbs.iter_mut().enumerate() {
            let a = match (tb.done, tb.cur_action) {
                (false, Some(running)) => running,
                _ => actions[i],
            };
            self.executed[i] = a;
            reward += tb.step(i, a, layout, p, self.noise.as_ref(), &mut self.humans, rng);
        }
        let f = self.tbs.len();
        let a = match (self.fetch.done, self.fetch.cur_action) {
            (false, Some(running)) => running,
            _ => actions[f],
        };
        self.executed[f] = a;
        reward += self.fetch.step(a, layout, p, &mut self.tbs, rng);
        for (done, tb) in self.mac_done.iter_mut().zip(&self.tbs) {
            *done = tb.done;
        }
        self.mac_done[f] = self.fetch.done;
        for (served, h) in self.served.iter_mut().zip(&self.humans) {
            if !*served && h.served() {
                *served = true;
                self.n_served += 1;
            }
        }
        for h in &mut self.humans {
            h.tick();
        }
        for (i, tb) in self.tbs.iter().enumerate() {
            if tb.done {
                observe::write_tb_obs(layout, p, tb, &self.fetch, &self.humans, &mut self.obs[i]);
                let slot = layout.held_obs_slot(i, p.obs_human_wait);
                self.held[slot].copy_from_slice(&self.obs[i]);
            } else {
                self.obs[i].copy_from_slice(&self.held[i]);
            }
        }
        if self.fetch.done {
            observe::write_fetch_obs(
                layout,
                p,
                &self.fetch,
                &self.tbs,
                &self.humans,
                &mut self.obs[f],
            );
        }
        let terminal = self.n_served == layout.n_humans()
            || (layout.terminal_at_terminate_step && self.count == p.terminate_step);
        (reward, terminal)
    }
}

impl<const V: usize> MacroEnv for Osd<V> {
    fn n_agents(&self) -> usize {
        self.n_actions.len()
    }
    fn obs_sizes(&self) -> &[usize] {
        &self.obs_sizes
    }
    fn n_actions(&self) -> &[usize] {
        &self.n_actions
    }
    fn action_names(&self, agent: usize) -> &'static [&'static str] {
        assert!(agent < self.n_agents(), "agent {agent} out of range");
        let layout = Self::layout();
        if agent < layout.n_turtlebots() {
            layout.tb_action_names
        } else {
            layout.fetch_action_names
        }
    }
    fn obs_names(&self, agent: usize) -> Vec<String> {
        render::obs_names(Self::layout(), self.params.obs_human_wait, agent)
    }
    fn horizon(&self) -> usize {
        self.params.horizon
    }
    fn reset(&mut self, _rng: &mut EnvRng) {
        self.reset_state();
    }
    fn step(&mut self, actions: &[usize], rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        if self.over {
            return Err(EnvError::EpisodeOver);
        }
        self.check_actions(actions)?;
        let (reward, terminal) = self.advance(actions, rng);
        self.last_reward = reward;
        Ok(if terminal || self.count >= self.params.horizon {
            self.over = true;
            StepOutcome::ended(reward, terminal)
        } else {
            StepOutcome::running(reward)
        })
    }
    fn obs(&self, agent: usize) -> &[f32] {
        &self.obs[agent]
    }
    fn executed(&self) -> &[usize] {
        &self.executed
    }
    fn mac_done(&self) -> &[bool] {
        &self.mac_done
    }
    fn t(&self) -> usize {
        self.count
    }
    fn render_ascii(&self) -> String {
        render::ascii(self)
    }
    /// The reference's `reset()` hands out its held-observation list and the first step
    /// overwrites the entries of the agents that finished in it; MacroMARL's runner records
    /// that list as the first record's observation (`envs_runner.py`: `last_obs = env.reset()`).
    fn first_record_obs(&self) -> FirstRecordObs {
        FirstRecordObs::OverwrittenByFirstStep
    }
    fn deterministic(&self) -> bool {
        !self.params.noisy()
    }
    fn describe(&self) -> String {
        let layout = Self::layout();
        format!(
            "{} ({}), horizon {}",
            layout.title, layout.gym_id, self.params.horizon
        )
    }
    fn draw(&self) -> Option<crate::draw::Picture> {
        Some(draw::draw(self))
    }
    fn state_size(&self) -> usize {
        Self::layout().state_size()
    }
    fn write_state(&self, out: &mut [f32]) {
        let layout = Self::layout();
        assert_eq!(
            out.len(),
            layout.state_size(),
            "state buffer has the wrong length"
        );
        if layout.has_state {
            observe::write_state(
                layout,
                &self.params,
                &self.tbs,
                &self.fetch,
                &self.humans,
                out,
            );
        }
    }
}
