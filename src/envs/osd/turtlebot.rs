//! A Turtlebot (`AgentTurtlebot_v7` of the `core_*_room.py` files): it drives to a waypoint,
//! delivers the tool a human needs on arriving at (or staying in) that human's area, and waits
//! at its table spot for the Fetch with Get_Tool.

use rand::Rng;
use rand_distr::Normal;

use super::human::Human;
use super::layout::{Layout, N_OBJS};
use super::params::OsdParams;
use crate::envs::EnvRng;

/// Reward of a correct delivery.
pub const DELIVERY_REWARD: f64 = 100.0;

/// One Turtlebot's state.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Turtlebot {
    /// Position (m).
    pub pos: [f64; 2],
    /// The last waypoint reached (`cur_BWP.idx`); kept while driving away, `None` only before
    /// the first arrival.
    pub cur_bwp: Option<usize>,
    /// The macro-action being run (`cur_action.idx`), `None` before the first step.
    pub cur_action: Option<usize>,
    /// `cur_action_time_left`: distance still to drive, then 0, then -k after k steps waiting
    /// at the table.
    pub time_left: f64,
    /// `cur_action_done`.
    pub done: bool,
    /// Tools in the basket, counted per type (`objs_in_basket`).
    pub basket: [f64; N_OBJS],
}

impl Turtlebot {
    /// A Turtlebot at `start` (metres), idle, with an empty basket.
    pub fn new(start: [f64; 2]) -> Self {
        Turtlebot {
            pos: start,
            cur_bwp: None,
            cur_action: None,
            time_left: 0.0,
            done: true,
            basket: [0.0; N_OBJS],
        }
    }

    /// Whether the Turtlebot stands at its table spot waiting for a pass (the Fetch's
    /// precondition: at `ToolRoomTable` and `time_left <= -1`).
    pub fn waiting_at_table(&self, layout: &Layout) -> bool {
        self.cur_bwp == Some(layout.get_tool()) && self.time_left <= -1.0
    }

    /// `AgentTurtlebot_v7.step` for Turtlebot `me` running macro-action `action` (a valid
    /// index); returns its part of the step's reward.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        me: usize,
        action: usize,
        layout: &Layout,
        p: &OsdParams,
        noise: Option<&Normal<f64>>,
        humans: &mut [Human],
        rng: &mut EnvRng,
    ) -> f64 {
        let mut reward = 0.0;
        self.cur_action = Some(action);
        self.done = false;
        let target = layout.waypoint(me, action);
        let (gx, gy) = (target[0] - self.pos[0], target[1] - self.pos[1]);
        let dist = numpy_round2((gx * gx + gy * gy).sqrt());
        if dist <= p.tb_move_speed {
            self.pos = target;
            self.cur_bwp = Some(action);
            if self.time_left > 0.0 {
                self.time_left = 0.0;
                reward += p.tb_move_cost;
                if action == layout.early_return_action {
                    return reward;
                }
            }
            if action < layout.get_tool() {
                self.done = true;
            } else {
                // At the table: wait for the Fetch, give up after get_tool_wait steps.
                self.time_left -= 1.0;
                if self.time_left <= -p.get_tool_wait() {
                    self.time_left = -1.0;
                    self.done = true;
                }
            }
        } else {
            // The reference adds np.random.normal(0, noisy) to x, then to y (0.0 without noise).
            let (nx, ny) = match noise {
                Some(n) => (rng.sample(n), rng.sample(n)),
                None => (0.0, 0.0),
            };
            let dx = p.tb_move_speed / dist * (target[0] - self.pos[0]) + nx;
            let dy = p.tb_move_speed / dist * (target[1] - self.pos[1]) + ny;
            self.pos[0] += dx;
            self.pos[1] += dy;
            self.time_left = dist - p.tb_move_speed;
            reward += p.tb_move_cost;
        }
        // Deliver when at the area of the human this action goes to.
        if action < layout.n_humans() && self.cur_bwp == Some(action) {
            let human = &mut humans[action];
            if !human.obtained && self.basket[human.need] > 0.0 {
                self.basket[human.need] -= 1.0;
                if human.time_left <= 0.0 && p.delay_delivery_penalty != 0.0 {
                    reward += DELIVERY_REWARD + p.delay_delivery_penalty;
                } else {
                    reward += DELIVERY_REWARD;
                }
                human.obtained = true;
            }
        }
        reward
    }
}

/// `round(d, 2)` as the reference computes it on a numpy float64 (`round(np.sqrt(..), 2)`),
/// which is numpy's `around`: `rint(d * 100) / 100`, ties to even on the product. This is not
/// CPython's float `round` (the ICRA port's `round2`): e.g. 0.015 gives 0.02 here, 0.01 there.
pub fn numpy_round2(d: f64) -> f64 {
    (d * 100.0).round_ties_even() / 100.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numpy_rounding_is_not_cpythons() {
        // Checked against numpy 2.4: round(np.float64(x), 2).
        assert_eq!(numpy_round2(0.015), 0.02);
        assert_eq!(numpy_round2(0.025), 0.02);
        assert_eq!(numpy_round2(0.005), 0.0);
        assert_eq!(numpy_round2(std::f64::consts::SQRT_2), 1.41);
    }
}
