//! Box Pushing, the macro-action version used for the paper's Box Pushing figures, exact to
//! `docs/BOX_PUSHING.md` (the reference's `BoxPushing_harder`).
//!
//! Two robots on an N x N grid push boxes north into the top row: a small box alone is worth +10,
//! the big box +100 but needs both robots to push together. Every step costs -0.1; pushing into a
//! wall edge, into the big box alone or into a small box sideways costs -5. Each robot sees only
//! its front cell. The module splits along the spec: [`geometry`] (section 1), [`layout`] (2),
//! [`actions`] (3), `step` (4), `navigate` (5.1), `push` (5.2), [`observe`] (6), `render`.

pub mod actions;
pub(crate) mod domain;
pub mod draw;
pub mod geometry;
pub mod layout;
mod navigate;
pub mod observe;
mod push;
mod render;
pub mod rules;
mod spec;
pub mod state;
mod step;

pub use domain::{BoxPushingDomain, DEFAULT_GRID_DIM, MAX_GRID_DIM};
pub use rules::Rules;
pub use spec::{paper_spec, spec};

#[cfg(test)]
mod properties;
#[cfg(test)]
mod scenarios;

use self::actions::{ACTION_NAMES, N_ACTIONS};
use self::layout::GridLayout;
use self::observe::{OBS_NAMES, OBS_SIZE, RESET_OBS};
use self::state::{Boxes, Robot};
use super::{EnvError, EnvRng, MacroEnv, StepOutcome};

/// Number of robots.
pub const N_AGENTS: usize = 2;

/// Smallest grid side of the ICRA paper's Box Pushing: the spec's general layout formulas need
/// N >= 8 (`docs/BOX_PUSHING.md` §2). MacroMARL's rules go down to 4 ([`Rules::min_grid`]).
pub const MIN_GRID: usize = Rules::ICRA.min_grid;

/// Length of the global state ([`MacroEnv::write_state`]): per robot x, y and a one-hot heading,
/// per box x, y (MacroMARL's `get_state()`).
pub const STATE_SIZE: usize = N_AGENTS * 6 + 3 * 2;

/// Largest supported grid side, so every coordinate (even a robot lifted above the grid by the Q2
/// joint push) fits in `i32` with room to spare.
pub const MAX_GRID: usize = 1 << 20;

/// Delivery counters that persist across resets, as the reference keeps them (quirk Q14).
/// Diagnostics only; they never affect the dynamics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct DeliveryStats {
    /// Steps in which exactly one small box entered the goal row.
    pub single_small_box: u64,
    /// Steps in which both small boxes entered the goal row.
    pub both_small_boxes: u64,
    /// Steps in which the big box entered the goal row.
    pub big_box: u64,
}

/// The Box Pushing environment (`docs/BOX_PUSHING.md`). Deterministic: the RNG passed to
/// [`MacroEnv::reset`] / [`MacroEnv::step`] is never drawn from (`docs/BOX_PUSHING.md` §9; random initialisation,
/// unused by the paper, is not provided).
///
/// Constructed in the reset state, so `step` may be called at once.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct BoxPushing {
    layout: GridLayout,
    horizon: usize,
    rules: Rules,
    robots: [Robot; N_AGENTS],
    boxes: Boxes,
    /// The joint big-box push latch (`docs/BOX_PUSHING.md` §4 step 3, 5.4): once on, it stays on until reset.
    joint_push: bool,
    /// Primitive steps since reset.
    t: usize,
    done: bool,
    obs: [[f32; OBS_SIZE]; N_AGENTS],
    executed: [usize; N_AGENTS],
    mac_done: [bool; N_AGENTS],
    stats: DeliveryStats,
}

impl BoxPushing {
    /// Check `grid` and `horizon` as [`Self::with_rules`] does, without building (config
    /// validation).
    pub fn check_params(grid: usize, horizon: usize, rules: &Rules) -> Result<(), EnvError> {
        let min = rules.min_grid;
        if grid < min {
            return Err(EnvError::InvalidParameter {
                name: "grid",
                reason: format!(
                    "must be at least {min} (`docs/BOX_PUSHING.md` §2 layout), got {grid}"
                ),
            });
        }
        if !grid.is_multiple_of(2) {
            return Err(EnvError::InvalidParameter {
                name: "grid",
                reason: format!(
                    "must be even (an odd grid puts the big box off the cell centres, `docs/BOX_PUSHING.md` Q9), got {grid}"
                ),
            });
        }
        if grid > MAX_GRID {
            return Err(EnvError::InvalidParameter {
                name: "grid",
                reason: format!("must be at most {MAX_GRID}, got {grid}"),
            });
        }
        if horizon == 0 {
            return Err(EnvError::InvalidParameter {
                name: "horizon",
                reason: "must be at least 1 primitive step, got 0".to_string(),
            });
        }
        Ok(())
    }

    /// The ICRA paper's N x N Box Pushing with an episode horizon in primitive steps (paper: 10
    /// with 100, 30 with 200): [`Self::with_rules`] with [`Rules::ICRA`].
    pub fn new(grid: usize, horizon: usize) -> Result<Self, EnvError> {
        Self::with_rules(grid, horizon, Rules::ICRA)
    }

    /// An N x N Box Pushing environment under `rules`, with an episode horizon in primitive steps.
    ///
    /// `grid` must be even and at least `rules.min_grid`: the spec's layout formulas need N >= 8
    /// (`docs/BOX_PUSHING.md` §2; MacroMARL adds fixed 4 x 4 and 6 x 6 layouts) and an odd N puts the big box and
    /// its waypoints off the cell centres, where they can never be reached or seen (quirk Q9).
    /// `horizon` must be at least 1.
    pub fn with_rules(grid: usize, horizon: usize, rules: Rules) -> Result<Self, EnvError> {
        Self::check_params(grid, horizon, &rules)?;
        let layout = GridLayout::new(grid as i32);
        Ok(Self {
            robots: start_robots(&layout),
            boxes: start_boxes(&layout),
            layout,
            horizon,
            rules,
            joint_push: false,
            t: 0,
            done: false,
            obs: [RESET_OBS; N_AGENTS],
            executed: [0; N_AGENTS],
            mac_done: [true; N_AGENTS],
            stats: DeliveryStats::default(),
        })
    }

    /// The rules this environment plays by.
    pub fn rules(&self) -> &Rules {
        &self.rules
    }

    /// Grid side N.
    pub fn grid(&self) -> usize {
        self.layout.n as usize
    }

    /// The fixed start configuration and waypoints.
    pub fn layout(&self) -> &GridLayout {
        &self.layout
    }

    /// Robot `agent`'s state (cell, heading, current macro-action, remembered waypoint). Panics if
    /// `agent >= 2`.
    pub fn robot(&self, agent: usize) -> &Robot {
        &self.robots[agent]
    }

    /// Current box positions.
    pub fn boxes(&self) -> &Boxes {
        &self.boxes
    }

    /// Whether the joint big-box push is under way (`docs/BOX_PUSHING.md` §5.4).
    pub fn joint_push_active(&self) -> bool {
        self.joint_push
    }

    /// Whether the episode has ended (delivery or horizon).
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Delivery counters over the environment's lifetime (quirk Q14).
    pub fn delivery_stats(&self) -> DeliveryStats {
        self.stats
    }

    /// Back to the start configuration (`docs/BOX_PUSHING.md` §2). Statistics persist (Q14).
    fn reset_state(&mut self) {
        self.robots = start_robots(&self.layout);
        self.boxes = start_boxes(&self.layout);
        self.joint_push = false;
        self.t = 0;
        self.done = false;
        self.obs = [RESET_OBS; N_AGENTS];
        self.executed = [0; N_AGENTS];
        self.mac_done = [true; N_AGENTS];
    }

    /// Put robot `agent` on `cell` facing `heading` (other state untouched), for tests that start from a
    /// hand-made configuration.
    #[cfg(test)]
    pub(crate) fn place_robot(
        &mut self,
        agent: usize,
        cell: geometry::Cell,
        heading: geometry::Heading,
    ) {
        self.robots[agent].cell = cell;
        self.robots[agent].heading = heading;
    }
}

/// Both robots at their start cells, free, remembering no waypoint (`docs/BOX_PUSHING.md` §2).
fn start_robots(layout: &GridLayout) -> [Robot; N_AGENTS] {
    layout
        .robot_starts
        .map(|(cell, heading)| Robot::at_start(cell, heading))
}

fn start_boxes(layout: &GridLayout) -> Boxes {
    Boxes {
        small: layout.small_boxes,
        big_left: layout.big_box_left,
    }
}

impl MacroEnv for BoxPushing {
    fn n_agents(&self) -> usize {
        N_AGENTS
    }

    fn obs_sizes(&self) -> &[usize] {
        &[OBS_SIZE; N_AGENTS]
    }

    #[inline]
    fn n_actions(&self) -> &[usize] {
        &[N_ACTIONS; N_AGENTS]
    }

    fn action_names(&self, agent: usize) -> &'static [&'static str] {
        assert!(agent < N_AGENTS, "agent {agent} out of range 0..{N_AGENTS}");
        &ACTION_NAMES
    }

    fn obs_names(&self, agent: usize) -> Vec<String> {
        assert!(agent < N_AGENTS, "agent {agent} out of range 0..{N_AGENTS}");
        OBS_NAMES.iter().map(|s| s.to_string()).collect()
    }

    fn horizon(&self) -> usize {
        self.horizon
    }

    fn reset(&mut self, _rng: &mut EnvRng) {
        self.reset_state();
    }

    #[inline]
    fn step(&mut self, actions: &[usize], _rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        self.step_primitive(actions)
    }

    #[inline]
    fn obs(&self, agent: usize) -> &[f32] {
        &self.obs[agent]
    }

    /// After reset (before any step) this is `[0, 0]` and means nothing.
    fn executed(&self) -> &[usize] {
        &self.executed
    }

    #[inline]
    fn mac_done(&self) -> &[bool] {
        &self.mac_done
    }

    fn t(&self) -> usize {
        self.t
    }

    fn render_ascii(&self) -> String {
        render::render(self)
    }

    /// Known at gamma 0.98 for the ICRA paper's two settings (10x10 horizon 100, 30x30 horizon
    /// 200) and for MacroMARL's published rewards on grids 6 to 14 (`docs/MACROMARL.md` §3.1), where
    /// the best plan is the scripted one: each robot to its big-box waypoint, then the joint push.
    fn optimal_return(&self, discount: f64) -> Option<f64> {
        if discount != 0.98 {
            return None;
        }
        if self.rules == Rules::ICRA {
            return match (self.grid(), self.horizon) {
                (10, 100) => Some(BP10_OPTIMAL),
                (30, 200) => Some(BP30_OPTIMAL),
                _ => None,
            };
        }
        let published = Rules {
            penalty: self.rules.penalty,
            ..Rules::MACROMARL
        };
        (self.rules == published && matches!(self.grid(), 6 | 8 | 10 | 12 | 14))
            .then(|| self.big_box_plan_return(discount))
            .flatten()
    }

    fn state_size(&self) -> usize {
        STATE_SIZE
    }

    /// Robots (x, y, one-hot heading), then boxes 0, 1, big (x, y), each coordinate the cell
    /// centre over the grid side (the big box's centre is between its two cells), as the
    /// reference's `get_state()`.
    fn write_state(&self, out: &mut [f32]) {
        assert_eq!(
            out.len(),
            STATE_SIZE,
            "Box Pushing's state has {STATE_SIZE} values"
        );
        let n = self.grid() as f64;
        let centre = |c: i32| ((c as f64 + 0.5) / n) as f32;
        let mut at = 0;
        for robot in &self.robots {
            out[at] = centre(robot.cell.col);
            out[at + 1] = centre(robot.cell.row);
            out[at + 2..at + 6].fill(0.0);
            out[at + 2 + robot.heading.index()] = 1.0;
            at += 6;
        }
        for cell in self.boxes.small {
            out[at] = centre(cell.col);
            out[at + 1] = centre(cell.row);
            at += 2;
        }
        out[at] = ((self.boxes.big_left.col as f64 + 1.0) / n) as f32;
        out[at + 1] = centre(self.boxes.big_left.row);
    }

    /// "Box Pushing 10x10, horizon 100"; rewards other than the ICRA paper's are named.
    fn describe(&self) -> String {
        let rewards = if self.rules == Rules::ICRA {
            String::new()
        } else {
            let r = &self.rules;
            format!(
                ", rewards {}/{}/{}",
                r.big_box_reward, r.small_box_reward, r.penalty
            )
        };
        format!(
            "Box Pushing {0}x{0}{rewards}, horizon {1}",
            self.grid(),
            self.horizon
        )
    }

    fn draw(&self) -> Option<crate::draw::Picture> {
        Some(draw::draw(self))
    }
}

impl BoxPushing {
    /// The discounted return of the scripted big-box plan from reset (robot 0 to W2, robot 1 to
    /// W3, then both push), if it delivers within the horizon.
    fn big_box_plan_return(&self, discount: f64) -> Option<f64> {
        let mut env = self.clone();
        env.reset_state();
        let (mut ret, mut weight) = (0.0, 1.0);
        let mut plans = [[2, 4], [3, 4]];
        loop {
            let actions = [plans[0][0], plans[1][0]];
            let out = env.step_primitive(&actions).ok()?;
            ret += weight * out.reward;
            weight *= discount;
            if out.done {
                return (env.boxes.big_left.row == env.layout.goal_row()).then_some(ret);
            }
            for (plan, &done) in plans.iter_mut().zip(&env.mac_done) {
                if done {
                    plan[0] = plan[1];
                }
            }
        }
    }
}

/// Optimal discounted return of Box Pushing 10x10 (horizon 100, gamma 0.98); `box_pushing.md` 11.
pub const BP10_OPTIMAL: f64 = 80.71093744250365;
/// Optimal discounted return of Box Pushing 30x30 (horizon 200, gamma 0.98); `box_pushing.md` 11.
pub const BP30_OPTIMAL: f64 = 41.75397237445474;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_below_eight_is_rejected() {
        let err = BoxPushing::new(6, 100).unwrap_err();
        assert!(matches!(
            err,
            EnvError::InvalidParameter { name: "grid", .. }
        ));
        assert!(err.to_string().contains("at least 8"), "{err}");
    }

    #[test]
    fn odd_grid_is_rejected() {
        let err = BoxPushing::new(11, 100).unwrap_err();
        assert!(matches!(
            err,
            EnvError::InvalidParameter { name: "grid", .. }
        ));
        assert!(err.to_string().contains("even"), "{err}");
    }

    #[test]
    fn zero_horizon_is_rejected() {
        let err = BoxPushing::new(10, 0).unwrap_err();
        assert!(matches!(
            err,
            EnvError::InvalidParameter {
                name: "horizon",
                ..
            }
        ));
    }

    #[test]
    fn sizes_match_the_spec() {
        let env = BoxPushing::new(10, 100).unwrap();
        assert_eq!(env.n_agents(), 2);
        assert_eq!(env.obs_sizes(), &[5, 5]);
        assert_eq!(env.n_actions(), &[8, 8]);
        assert_eq!(env.joint_obs_size(), 10);
        assert_eq!(env.n_joint_actions(), 64);
        assert_eq!(env.action_names(1)[2], "GT_BB0");
        assert_eq!(env.obs_names(0)[3], "wall");
    }
}
