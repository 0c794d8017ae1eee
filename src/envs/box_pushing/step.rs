//! One environment step in the reference's exact order (`docs/BOX_PUSHING.md` §4).

use super::actions::{MacroAction, N_ACTIONS, PUSH};
use super::geometry::Heading;
use super::layout::GridLayout;
use super::navigate::move_step;
use super::observe::observe;
use super::push::push_step;
use super::state::{Boxes, Robot};
use super::{BoxPushing, N_AGENTS};
use crate::envs::{EnvError, StepOutcome};

/// The time penalty every step starts from (`docs/BOX_PUSHING.md` §7).
pub const STEP_REWARD: f64 = -0.1;

/// One primitive step of macro-action `m` for one robot (`docs/BOX_PUSHING.md` §5). Returns its penalty.
#[inline]
fn execute(
    robot: &mut Robot,
    m: MacroAction,
    boxes: &mut Boxes,
    layout: &GridLayout,
    hit: f64,
) -> f64 {
    match m {
        MacroAction::MoveTo(k) => {
            move_step(robot, k, layout.waypoints[k as usize], boxes);
            0.0
        }
        MacroAction::Push => push_step(robot, boxes, layout.n, hit),
        MacroAction::TurnLeft => {
            robot.heading = robot.heading.left();
            robot.finished = true;
            0.0
        }
        MacroAction::TurnRight => {
            robot.heading = robot.heading.right();
            robot.finished = true;
            0.0
        }
        MacroAction::Stay => {
            robot.finished = true;
            0.0
        }
    }
}

/// Whether this step starts the joint big-box push (`docs/BOX_PUSHING.md` §4 step 3): both robots pass Push, both
/// are free, both face north, and their remembered waypoints are W2 and W3 in either order.
/// Positions are not checked (quirk Q2).
#[inline]
fn joint_push_starts(actions: &[usize], robots: &[Robot; N_AGENTS]) -> bool {
    actions[0] == PUSH
        && actions[1] == PUSH
        && robots
            .iter()
            .all(|r| r.finished && r.heading == Heading::North)
        && matches!(
            (robots[0].waypoint, robots[1].waypoint),
            (Some(2), Some(3)) | (Some(3), Some(2))
        )
}

impl BoxPushing {
    /// The body of [`crate::envs::MacroEnv::step`]. Input is validated before any state changes,
    /// so an error leaves the environment as it was.
    #[inline]
    pub(super) fn step_primitive(&mut self, actions: &[usize]) -> Result<StepOutcome, EnvError> {
        if self.done {
            return Err(EnvError::EpisodeOver);
        }
        if actions.len() != N_AGENTS {
            return Err(EnvError::WrongActionCount {
                expected: N_AGENTS,
                got: actions.len(),
            });
        }
        // A free robot's value becomes its macro-action; a busy robot's value is ignored (Q12).
        let mut effective = [MacroAction::Stay; N_AGENTS];
        for (agent, robot) in self.robots.iter().enumerate() {
            effective[agent] = if robot.finished {
                MacroAction::from_index(actions[agent]).ok_or(EnvError::ActionOutOfRange {
                    agent,
                    action: actions[agent],
                    n_actions: N_ACTIONS,
                })?
            } else {
                robot
                    .current
                    .expect("a busy robot always has a current macro-action")
            };
        }

        // 1-2. Count the step; start from the time penalty.
        self.t += 1;
        let mut reward = STEP_REWARD;

        // 3. The joint-push latch, checked only here and never cleared until reset.
        if !self.joint_push && joint_push_starts(actions, &self.robots) {
            self.joint_push = true;
        }

        if !self.joint_push {
            // 4. Robot 0 fully, then robot 1, which sees robot 0's move (Q15).
            for (agent, &m) in effective.iter().enumerate() {
                let robot = &mut self.robots[agent];
                robot.current = Some(m);
                robot.finished = false;
                let penalty = execute(robot, m, &mut self.boxes, &self.layout, self.rules.penalty);
                self.executed[agent] = m.index();
                self.mac_done[agent] = robot.finished;
                reward += penalty;
            }
        } else {
            // 5. Joint push: both robots and the big box rise one row, no checks (`docs/BOX_PUSHING.md` §5.4).
            for robot in &mut self.robots {
                robot.current = Some(MacroAction::Push);
                robot.finished = false;
                robot.cell.row += 1;
            }
            self.boxes.big_left.row += 1;
            if self.boxes.big_left.row == self.layout.goal_row() {
                for robot in &mut self.robots {
                    robot.finished = true;
                }
            }
            self.executed = [PUSH; N_AGENTS];
            self.mac_done = [self.robots[0].finished, self.robots[1].finished];
        }

        // 6. Goal check in box order small 0, small 1, big; the bonus sums from 0.0 first.
        let goal = self.layout.goal_row();
        let mut bonus = 0.0;
        let mut small_delivered = 0;
        let mut terminal = false;
        for row in [self.boxes.small[0].row, self.boxes.small[1].row] {
            if row == goal {
                terminal = true;
                bonus += self.rules.small_box_reward;
                small_delivered += 1;
            }
        }
        if self.boxes.big_left.row == goal {
            terminal = true;
            bonus += self.rules.big_box_reward;
            self.stats.big_box += 1;
        }
        match small_delivered {
            1 => self.stats.single_small_box += 1,
            2 => self.stats.both_small_boxes += 1,
            _ => {}
        }
        reward += bonus;

        // 7. Fresh observations for robots that finished, held ones for the others (`docs/BOX_PUSHING.md` §6).
        for agent in 0..N_AGENTS {
            if self.robots[agent].finished {
                let mate = &self.robots[1 - agent];
                self.obs[agent] = observe(&self.robots[agent], mate, &self.boxes, self.layout.n);
            }
        }

        // 8. The horizon cut is folded into done (Q1); it is terminal under the ICRA rules (Q7)
        // and a truncation under MacroMARL's, whose runner bootstraps from it.
        self.done = terminal || self.t >= self.horizon;
        Ok(StepOutcome {
            reward,
            done: self.done,
            truncated: self.done && !terminal && !self.rules.horizon_is_terminal,
        })
    }
}
