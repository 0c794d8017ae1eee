//! The Fetch arm (`AgentFetch_v4` with two Turtlebots, `_v5` with three; the same code but for
//! the number of Pass actions): Wait_Request (1 step), Pass_Obj_T{k} (hands the first staged
//! tool to Turtlebot k), Look_For_obj{j} (stages tool j; at most 2 staged, `n_each_obj` of each
//! type in all).

use rand::Rng;

use super::layout::{Layout, N_OBJS};
use super::params::OsdParams;
use super::turtlebot::Turtlebot;
use crate::envs::EnvRng;

/// What a Fetch macro-action index means (the index layout is `[Wait, Pass_T0.., Look_0..]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FetchAction {
    /// Wait_Request: wait one step.
    Wait,
    /// Pass to Turtlebot k.
    Pass(usize),
    /// Look for tool j.
    Look(usize),
}

impl FetchAction {
    /// Action `a` of a Fetch serving `n_tb` Turtlebots (a < 1 + n_tb + N_OBJS).
    pub fn of(a: usize, n_tb: usize) -> FetchAction {
        match a {
            0 => FetchAction::Wait,
            a if a <= n_tb => FetchAction::Pass(a - 1),
            a => FetchAction::Look(a - 1 - n_tb),
        }
    }
}

/// The Fetch's state.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Fetch {
    /// `cur_action.idx`, `None` before the first step.
    pub cur_action: Option<usize>,
    /// `cur_action_time_left`.
    pub time_left: f64,
    /// `cur_action_done`.
    pub done: bool,
    /// How many of each tool were found so far (`count_found_obj`).
    pub count_found: [usize; N_OBJS],
    /// A pass is under way (`serving`; only drawn).
    pub serving: bool,
    /// The pass started without its Turtlebot waiting at the table (`serving_failed`).
    pub serving_failed: bool,
    /// `ready_objs`: [1, 0] when one tool is staged, [0, 1] when two, as the reference sets it.
    pub ready: [f64; 2],
    /// The staged tools in order (`found_objs`), the first `n_found` entries.
    found: [usize; 2],
    n_found: usize,
}

impl Default for Fetch {
    fn default() -> Self {
        Fetch {
            cur_action: None,
            time_left: 0.0,
            done: true,
            count_found: [0; N_OBJS],
            serving: false,
            serving_failed: false,
            ready: [0.0; 2],
            found: [0; 2],
            n_found: 0,
        }
    }
}

impl Fetch {
    /// The staged tools, first to be passed first.
    pub fn staged(&self) -> &[usize] {
        &self.found[..self.n_found]
    }

    /// `MacroAction.t_cost` of action `a`.
    fn t_cost(a: FetchAction, p: &OsdParams) -> f64 {
        match a {
            FetchAction::Wait => 1.0,
            FetchAction::Pass(_) => p.fetch_pass_obj_tc as f64,
            FetchAction::Look(_) => p.fetch_look_for_obj_tc as f64,
        }
    }

    /// The duration of the current macro-action (for the state's progress entry).
    pub fn cur_t_cost(&self, layout: &Layout, p: &OsdParams) -> Option<f64> {
        self.cur_action
            .map(|a| Self::t_cost(FetchAction::of(a, layout.n_turtlebots()), p))
    }

    /// `AgentFetch_v4/_v5.step` with `action` (used only when free, as the reference); returns
    /// the Fetch's part of the reward.
    pub fn step(
        &mut self,
        action: usize,
        layout: &Layout,
        p: &OsdParams,
        tbs: &mut [Turtlebot],
        rng: &mut EnvRng,
    ) -> f64 {
        let mut reward = 0.0;
        self.time_left -= 1.0;
        if self.time_left > 0.0 {
            return reward;
        }
        let n_tb = layout.n_turtlebots();
        if self.done {
            // Start a new macro-action.
            self.cur_action = Some(action);
            let a = FetchAction::of(action, n_tb);
            self.time_left = if p.fetch_manip_noisy != 0.0 {
                let noise = [-1.0, 0.0, 1.0, 2.0][rng.gen_range(0..4)];
                Self::t_cost(a, p) + noise - 1.0
            } else {
                Self::t_cost(a, p) - 1.0
            };
            self.done = a == FetchAction::Wait;
            // Reference quirk: the start-of-pass test exists for Pass_Obj_T0 and _T1 only
            // (`AgentFetch_v5.step` has no branch for action 3), so a pass to Turtlebot 2
            // succeeds if it waits at the table when the pass *ends*, wherever it was before.
            if let FetchAction::Pass(k @ 0..=1) = a {
                self.serving = true;
                if !tbs[k].waiting_at_table(layout) {
                    self.serving_failed = true;
                }
            }
            return reward;
        }
        match FetchAction::of(self.cur_action.unwrap_or(0), n_tb) {
            FetchAction::Wait => {}
            FetchAction::Pass(k) => {
                self.serving = false;
                let tb = &mut tbs[k];
                // The Turtlebot must still be running Get_Tool and waiting when the pass ends.
                if !self.serving_failed
                    && tb.time_left < 0.0
                    && tb.cur_action == Some(layout.get_tool())
                {
                    if self.n_found > 0 {
                        let tool = self.found[0];
                        self.found[0] = self.found[1];
                        self.n_found -= 1;
                        tb.basket[tool] += 1.0;
                    }
                    tb.done = true;
                    tb.time_left = 0.0;
                    self.ready = [0.0; 2];
                    if self.n_found == 1 {
                        self.ready[0] = 1.0;
                    }
                } else {
                    reward += p.fetch_drop_obj_penalty;
                }
                self.serving_failed = false;
            }
            FetchAction::Look(j) => {
                if self.n_found < 2 && self.count_found[j] < layout.n_each_obj {
                    self.count_found[j] += 1;
                    self.found[self.n_found] = j;
                    self.n_found += 1;
                    self.ready = if self.n_found == 2 {
                        [0.0, 1.0]
                    } else {
                        [1.0, 0.0]
                    };
                }
            }
        }
        self.done = true;
        reward
    }
}
