//! A Turtlebot's primitive step (`docs/WAREHOUSE.md` §5): drive toward the macro-action's waypoint, wait
//! at the table for Get-Tool, deliver at the workshop for Go-to-WS.

use rand::Rng;
use rand_distr::Normal;

use super::human::Human;
use super::pyround::round2;
use crate::envs::EnvRng;

/// Turtlebot macro-actions (`docs/WAREHOUSE.md` §3); the index is also the target waypoint's code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TbAction {
    /// Go-to-WS: drive to the workshop waypoint (code 0) and offer the basket.
    GoWorkshop = 0,
    /// Go-to-TR: drive to the tool-room wait point (code 1).
    GoToolRoom = 1,
    /// Get-Tool: drive to the own table spot (code 2), then wait for a hand-over or time out.
    GetTool = 2,
}

impl TbAction {
    /// Every action, in code order.
    pub const ALL: [TbAction; 3] = [Self::GoWorkshop, Self::GoToolRoom, Self::GetTool];
}

/// Settings shared by both Turtlebots, copied from the parameters once.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct TbDynamics {
    /// Distance per primitive step (m), 0.6.
    pub speed: f64,
    /// Get-Tool wait limit W (10): the wait ends when `tl < -W`.
    pub wait_limit: f64,
    /// Late deliveries are worth 20 instead of 100.
    pub delay_delivery_penalty: bool,
    /// Movement noise; `None` when the std is 0. The reference draws normal(0, 0) = +0.0 even
    /// then, which changes nothing, so with zero noise no draws are made at all (`docs/WAREHOUSE.md` §9).
    pub noise: Option<Normal<f64>>,
}

/// State of `AgentTurtlebot_v4` (`docs/WAREHOUSE.md` §4).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Turtlebot {
    /// Position (x, y) in m.
    pub pos: [f64; 2],
    /// Targets of the three macro-actions, `(x, y)` by code.
    pub targets: [[f64; 2]; 3],
    /// Code of the last waypoint reached; sticky while travelling away (quirk Q1). None at reset.
    pub loc: Option<usize>,
    /// Current macro-action; None only before the first step.
    pub cur: Option<TbAction>,
    /// Whether the current macro-action finished (true at reset: free).
    pub done: bool,
    /// Signed "time left": remaining distance minus speed while travelling, 0 on arrival,
    /// minus the waiting steps at the table (`docs/WAREHOUSE.md` §4).
    pub tl: f64,
    /// Tool counts carried.
    pub basket: [f64; 3],
}

impl Turtlebot {
    /// A Turtlebot at reset.
    pub fn new(start: [f64; 2], targets: [[f64; 2]; 3]) -> Self {
        Self {
            pos: start,
            targets,
            loc: None,
            cur: None,
            done: true,
            tl: 0.0,
            basket: [0.0; 3],
        }
    }

    /// Whether the robot stands exactly on its table spot (the Fetch's "beside the table" bit).
    pub fn at_table(&self) -> bool {
        self.pos == self.targets[TbAction::GetTool as usize]
    }

    /// One primitive step of macro-action `a` (`docs/WAREHOUSE.md` §5). Returns the step's reward
    /// (0, or the delivery bonus). Draws two normals (x then y) only on a travel step with noise.
    pub fn step(
        &mut self,
        a: TbAction,
        dyn_: &TbDynamics,
        human: &mut Human,
        rng: &mut EnvRng,
    ) -> f64 {
        self.cur = Some(a);
        self.done = false;
        let goal = self.targets[a as usize];
        let (gx, gy) = (goal[0] - self.pos[0], goal[1] - self.pos[1]);
        // Squares then sqrt, as numpy does (not hypot, which rounds differently); Q3 rounding.
        // Most steps wait or repeat at the goal itself, where the distance is exactly 0.
        let d = if gx == 0.0 && gy == 0.0 {
            0.0
        } else {
            round2((gx * gx + gy * gy).sqrt())
        };
        if d <= dyn_.speed {
            self.pos = goal;
            self.loc = Some(a as usize);
            if self.tl > 0.0 {
                self.tl = 0.0;
                if a == TbAction::GetTool {
                    return 0.0; // arrival step of Get-Tool: not a waiting step (Q4)
                }
            }
            if a == TbAction::GetTool {
                self.tl -= 1.0;
                if self.tl < -dyn_.wait_limit {
                    self.tl = -1.0;
                    self.done = true;
                }
            } else {
                self.done = true;
            }
        } else {
            let (nx, ny) = match &dyn_.noise {
                Some(normal) => (rng.sample(normal), rng.sample(normal)),
                None => (0.0, 0.0),
            };
            // Both components from the old position; step length is speed * true_dist / d.
            let dx = dyn_.speed / d * gx + nx;
            let dy = dyn_.speed / d * gy + ny;
            self.pos[0] += dx;
            self.pos[1] += dy;
            self.tl = d - dyn_.speed;
        }
        self.deliver(a, dyn_, human)
    }

    /// Delivery check (`docs/WAREHOUSE.md` §5 step 4): Go-to-WS with the workshop as last waypoint hands
    /// over the human's needed tool if carried. Other tools stay in the basket (Q8).
    fn deliver(&mut self, a: TbAction, dyn_: &TbDynamics, human: &mut Human) -> f64 {
        if a != TbAction::GoWorkshop || self.loc != Some(0) {
            return 0.0;
        }
        if human.obtained || self.basket[human.need] <= 0.0 {
            return 0.0;
        }
        self.basket[human.need] -= 1.0;
        human.obtained = true;
        if dyn_.delay_delivery_penalty && human.htl < 0.0 {
            20.0
        } else {
            100.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::warehouse::params::{TURTLEBOT_STARTS, WAYPOINTS};
    use rand::SeedableRng;

    fn dynamics() -> TbDynamics {
        TbDynamics {
            speed: 0.6,
            wait_limit: 10.0,
            delay_delivery_penalty: false,
            noise: None,
        }
    }

    /// Steps until `a` reports done (Go-to-*) or arrives (Get-Tool: `tl` becomes 0 at the goal).
    fn leg_steps(robot: usize, from: [f64; 2], a: TbAction) -> usize {
        let mut tb = Turtlebot::new(from, WAYPOINTS[robot]);
        let mut h = Human::new(18.0);
        let mut rng = EnvRng::seed_from_u64(0);
        for k in 1..=30 {
            tb.step(a, &dynamics(), &mut h, &mut rng);
            if a != TbAction::GetTool && tb.done {
                return k;
            }
            if a == TbAction::GetTool && tb.pos == tb.targets[2] {
                return k;
            }
        }
        panic!("leg never ended");
    }

    #[test]
    fn leg_durations_match_the_spec_table() {
        use TbAction::*;
        // `docs/WAREHOUSE.md` §5 "Leg durations": rows = start, columns = WS, TR, table, for T0 then T1.
        // The table spot row's "0 (waits at once)" is checked in the Get-Tool tests below.
        let ws = WAYPOINTS[0][0];
        let tr = WAYPOINTS[0][1];
        let expect: [([f64; 2], [usize; 3], [usize; 3]); 3] = [
            (TURTLEBOT_STARTS[0], [6, 4, 5], [0; 3]),
            (ws, [1, 6, 9], [1, 6, 8]),
            (tr, [6, 1, 3], [6, 1, 3]),
        ];
        for (row, (from, t0, t1)) in expect.iter().enumerate() {
            for (col, a) in [GoWorkshop, GoToolRoom, GetTool].into_iter().enumerate() {
                assert_eq!(leg_steps(0, *from, a), t0[col], "T0 row {row} col {col}");
                if row > 0 {
                    assert_eq!(leg_steps(1, *from, a), t1[col], "T1 row {row} col {col}");
                }
            }
        }
        assert_eq!(
            [GoWorkshop, GoToolRoom, GetTool].map(|a| leg_steps(1, TURTLEBOT_STARTS[1], a)),
            [6, 2, 4]
        );
        for (r, wps) in WAYPOINTS.iter().enumerate() {
            assert_eq!(leg_steps(r, wps[2], GoToolRoom), 3);
        }
        assert_eq!(leg_steps(0, WAYPOINTS[0][2], GoWorkshop), 9);
        assert_eq!(leg_steps(1, WAYPOINTS[1][2], GoWorkshop), 8);
    }

    #[test]
    fn t1_table_to_workshop_needs_the_rounding() {
        // `docs/WAREHOUSE.md` §5 example: tl after each move, then arrival at step 8 (Q3).
        let mut tb = Turtlebot::new(WAYPOINTS[1][2], WAYPOINTS[1]);
        let mut h = Human::new(18.0);
        let mut rng = EnvRng::seed_from_u64(0);
        let want = [
            4.2,
            3.6,
            3.0,
            2.4,
            1.7999999999999998,
            1.2000000000000002,
            0.6,
        ];
        for w in want {
            tb.step(TbAction::GoWorkshop, &dynamics(), &mut h, &mut rng);
            assert_eq!(tb.tl, w);
            assert!(!tb.done);
        }
        tb.step(TbAction::GoWorkshop, &dynamics(), &mut h, &mut rng);
        assert!(tb.done);
        assert_eq!((tb.pos, tb.tl, tb.loc), ([6.0, 3.0], 0.0, Some(0)));
    }

    /// Total Get-Tool duration without a hand-over, from `from` with `tl` preset.
    fn get_tool_duration(robot: usize, from: [f64; 2], tl: f64) -> usize {
        let mut tb = Turtlebot::new(from, WAYPOINTS[robot]);
        tb.tl = tl;
        let mut h = Human::new(18.0);
        let mut rng = EnvRng::seed_from_u64(0);
        for k in 1..=40 {
            tb.step(TbAction::GetTool, &dynamics(), &mut h, &mut rng);
            if tb.done {
                assert_eq!(tb.tl, -1.0);
                return k;
            }
        }
        panic!("Get-Tool never timed out");
    }

    #[test]
    fn get_tool_time_outs_match_the_spec() {
        assert_eq!(get_tool_duration(0, TURTLEBOT_STARTS[0], 0.0), 16);
        assert_eq!(get_tool_duration(0, WAYPOINTS[0][0], 0.0), 20);
        assert_eq!(get_tool_duration(1, WAYPOINTS[1][0], 0.0), 19);
        assert_eq!(get_tool_duration(0, WAYPOINTS[0][1], 0.0), 14);
        assert_eq!(get_tool_duration(1, WAYPOINTS[1][1], 0.0), 14);
        // Q4: at the table, 11 steps after a hand-over (tl 0), 10 after a time-out (tl -1).
        assert_eq!(get_tool_duration(0, WAYPOINTS[0][2], 0.0), 11);
        assert_eq!(get_tool_duration(1, WAYPOINTS[1][2], -1.0), 10);
    }

    #[test]
    fn waiting_counts_down_tl() {
        let mut tb = Turtlebot::new(WAYPOINTS[0][1], WAYPOINTS[0]);
        let mut h = Human::new(18.0);
        let mut rng = EnvRng::seed_from_u64(0);
        let d = dynamics();
        for _ in 0..3 {
            tb.step(TbAction::GetTool, &d, &mut h, &mut rng);
        }
        assert_eq!(tb.tl, 0.0, "arrival step sets tl to 0 and does not wait");
        assert!(tb.at_table());
        for w in 1..=5 {
            tb.step(TbAction::GetTool, &d, &mut h, &mut rng);
            assert_eq!(tb.tl, -f64::from(w));
        }
    }

    #[test]
    fn only_the_needed_tool_is_delivered() {
        let d = dynamics();
        let mut rng = EnvRng::seed_from_u64(0);
        let mut tb = Turtlebot::new(WAYPOINTS[0][0], WAYPOINTS[0]);
        tb.basket = [0.0, 1.0, 1.0];
        let mut h = Human::new(18.0);
        assert_eq!(tb.step(TbAction::GoWorkshop, &d, &mut h, &mut rng), 0.0);
        assert_eq!(tb.loc, Some(0));
        assert_eq!(tb.basket, [0.0, 1.0, 1.0], "wrong tools stay (Q8)");
        h.need = 1;
        assert_eq!(tb.step(TbAction::GoWorkshop, &d, &mut h, &mut rng), 100.0);
        assert_eq!(tb.basket, [0.0, 0.0, 1.0]);
        assert!(h.obtained);
        assert_eq!(tb.step(TbAction::GoWorkshop, &d, &mut h, &mut rng), 0.0);
        // Delay penalty: 20 when the human is already waiting.
        let late = TbDynamics {
            delay_delivery_penalty: true,
            ..dynamics()
        };
        h = Human::new(18.0);
        h.need = 2;
        h.htl = -3.0;
        assert_eq!(tb.step(TbAction::GoWorkshop, &late, &mut h, &mut rng), 20.0);
    }
}
