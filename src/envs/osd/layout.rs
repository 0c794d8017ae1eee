//! What distinguishes MacroMARL's four Warehouse environments from one another: the rooms'
//! waypoints, the robots' start points, how many humans and Turtlebots there are, which Fetch
//! (`AgentFetch_v4` passes to 2 Turtlebots, `_v5` to 3), and the few places where one reference
//! file's code differs from the others'. Everything else is the same code (`docs/MACROMARL.md` §3.2), which lives
//! once in this folder.
//!
//! Coordinates are metres, as `BeliefWayPoint` and `createAgents` of each class set them.

/// Number of tool types (`n_objs`, the reference's default, which no script changes).
pub const N_OBJS: usize = 3;
/// Work steps of a human (`n_steps_human_task = n_objs + 1`).
pub const N_WORK_STEPS: usize = N_OBJS + 1;
/// The Fetch's fixed position (every class: `AgentFetch_*(.., 0.9, 2.5, ..)`).
pub const FETCH_POS: [f64; 2] = [0.9, 2.5];
/// Most Turtlebots and humans any layout has (sizes of the fixed arrays).
pub const MAX_TURTLEBOTS: usize = 3;
/// Most humans any layout has.
pub const MAX_HUMANS: usize = 4;

/// What the Turtlebots' `obs_human_wait` bits mean (only with `obs_human_wait = true`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HumanWaitObs {
    /// `osd_ma_double_room.py`: every human whose step time ran out, seen from anywhere; the
    /// Fetch observes the same bits.
    EveryHuman,
    /// `osd_ma_tripple_room.py`, `osd_ma_four_room.py`: only the human in the area the
    /// Turtlebot is at; the Fetch's observation has no such bits (its code is commented out).
    HumanHere,
}

/// One Warehouse environment class of the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The gym id (`OSD-D-v7`), which also names the domain.
    pub gym_id: &'static str,
    /// The paper's name for it, for titles.
    pub title: &'static str,
    /// Work area of each human (`WorkArea{k}`, waypoint index k); their number is the number of
    /// humans.
    pub work_areas: &'static [[f64; 2]],
    /// `ToolRoomWait`, waypoint index `n_humans`.
    pub tool_room_wait: [f64; 2],
    /// Each Turtlebot's own `ToolRoomTable` spot, waypoint index `n_humans + 1`; their number
    /// is the number of Turtlebots (and of the Fetch's Pass actions).
    pub tables: &'static [[f64; 2]],
    /// Each Turtlebot's start point.
    pub tb_starts: &'static [[f64; 2]],
    /// How many of each tool the Fetch can find (`n_each_obj`).
    pub n_each_obj: usize,
    /// The Turtlebot macro-action whose arrival step returns before the rest of the step
    /// (`if action == 3: return reward` in `core_double_room.py`, 4 in the other two cores).
    /// In the double and triple rooms that is Get_Tool, so Get_Tool's first waiting step comes
    /// one step after arrival; `core_four_room.py` kept 4, which there is **Go_Tool_Room**: its
    /// arrival does not end the macro-action (one extra step), and Get_Tool waits from the
    /// arrival step on. A reference quirk kept on purpose.
    pub early_return_action: usize,
    /// What the Turtlebots' `obs_human_wait` bits mean.
    pub human_wait_obs: HumanWaitObs,
    /// The class has `get_state()` (only `osd_ma_double_room.py` v7 and `tripple` v0).
    pub has_state: bool,
    /// The env itself ends the episode at `terminate_step` (only OSD-F-v0).
    pub terminal_at_terminate_step: bool,
    /// Names of the Turtlebots' and the Fetch's macro-actions (the reference's `MacroAction` names).
    pub tb_action_names: &'static [&'static str],
    /// Names of the Fetch's macro-actions, by index.
    pub fetch_action_names: &'static [&'static str],
    /// Published settings: human step times (Warehouse A, C, D, E) and the runner's horizon.
    pub default_human_speeds: &'static [[i64; N_WORK_STEPS]],
    /// The runner's published horizon in primitive steps.
    pub default_horizon: usize,
}

impl Layout {
    /// Humans (one per work area).
    pub fn n_humans(&self) -> usize {
        self.work_areas.len()
    }
    /// Turtlebots (one per table).
    pub fn n_turtlebots(&self) -> usize {
        self.tables.len()
    }
    /// Turtlebot macro-action Go_Tool_Room (= waypoint index of `ToolRoomWait`).
    pub fn go_tool_room(&self) -> usize {
        self.n_humans()
    }
    /// Turtlebot macro-action Get_Tool (= waypoint index of `ToolRoomTable`).
    pub fn get_tool(&self) -> usize {
        self.n_humans() + 1
    }
    /// Waypoint `idx` of Turtlebot `tb` (the reference's `BWPs_T{tb}[idx]`).
    pub fn waypoint(&self, tb: usize, idx: usize) -> [f64; 2] {
        let n = self.n_humans();
        if idx < n {
            self.work_areas[idx]
        } else if idx == n {
            self.tool_room_wait
        } else {
            self.tables[tb]
        }
    }
    /// Where the reference keeps Turtlebot `tb`'s observation to hand out while it is busy
    /// (its slot of `old_observations`). Reference bug, kept: in `osd_ma_double_room.py` the
    /// human-wait loop `for idx, human in enumerate(self.humans)` reuses the Turtlebot loop's
    /// `idx`, so with `obs_human_wait` every finished Turtlebot's observation is stored in slot
    /// `n_humans - 1` (Turtlebot 1's): a busy Turtlebot 1 then shows the observation Turtlebot 0
    /// last got, and a busy Turtlebot 0 its reset observation. A Turtlebot's observation at the
    /// step its macro-action ends, the one a policy acts on, is always its own.
    pub fn held_obs_slot(&self, tb: usize, obs_human_wait: bool) -> usize {
        if obs_human_wait && self.human_wait_obs == HumanWaitObs::EveryHuman {
            self.n_humans() - 1
        } else {
            tb
        }
    }
    /// Length of a Turtlebot's observation, without and with the human-wait bits.
    pub fn tb_obs_size(&self, obs_human_wait: bool) -> usize {
        let n = self.n_humans();
        (n + 3) + N_WORK_STEPS * n + N_OBJS + 2 + if obs_human_wait { n } else { 0 }
    }
    /// Length of the Fetch's observation.
    pub fn fetch_obs_size(&self, obs_human_wait: bool) -> usize {
        let wait = obs_human_wait && self.human_wait_obs == HumanWaitObs::EveryHuman;
        N_OBJS + self.n_turtlebots() + if wait { self.n_humans() } else { 0 }
    }
    /// Length of `get_state()`: 0 where the class has none.
    pub fn state_size(&self) -> usize {
        if !self.has_state {
            return 0;
        }
        let agents = self.n_turtlebots() + 1;
        2 * agents
            + N_OBJS * self.n_turtlebots()
            + 2 * N_OBJS
            + 1
            + (N_WORK_STEPS + 1) * self.n_humans()
    }
    /// Width of the world in metres (the reference's viewer: 700 px for two rooms, 900 for more).
    pub fn world_width_m(&self) -> f64 {
        if self.n_humans() == 2 {
            7.0
        } else {
            9.0
        }
    }
}

/// Index of OSD-D-v7 (Warehouse A and B) in [`LAYOUTS`].
pub const D7: usize = 0;
/// Index of OSD-T-v0 (Warehouse C).
pub const T0: usize = 1;
/// Index of OSD-T-v1 (Warehouse D).
pub const T1: usize = 2;
/// Index of OSD-F-v0 (Warehouse E).
pub const F0: usize = 3;

const FETCH_V4_ACTIONS: [&str; 6] = [
    "Wait_Request",
    "Pass_Obj_T0",
    "Pass_Obj_T1",
    "Look_For_obj0",
    "Look_For_obj1",
    "Look_For_obj2",
];
const FETCH_V5_ACTIONS: [&str; 7] = [
    "Wait_Request",
    "Pass_Obj_T0",
    "Pass_Obj_T1",
    "Pass_Obj_T2",
    "Look_For_obj0",
    "Look_For_obj1",
    "Look_For_obj2",
];
const TRIPLE_TB_ACTIONS: [&str; 5] = ["Go_WA0", "Go_WA1", "Go_WA2", "Go_Tool_Room", "Get_Tool"];
const TRIPLE_WORK_AREAS: [[f64; 2]; 3] = [[6.0, 3.0], [8.0, 3.0], [8.0, 2.0]];
const TWO_TABLES: [[f64; 2]; 2] = [[1.2, 3.7], [1.2, 1.3]];
const THREE_TABLES: [[f64; 2]; 3] = [[0.8, 3.7], [1.2, 3.7], [1.2, 1.3]];
const TWO_STARTS: [[f64; 2]; 2] = [[3.0, 3.5], [3.0, 1.5]];
const THREE_STARTS: [[f64; 2]; 3] = [[3.0, 4.0], [3.0, 2.5], [3.0, 1.0]];

/// The four environments, indexed by [`D7`], [`T0`], [`T1`], [`F0`].
pub static LAYOUTS: [Layout; 4] = [
    // osd_ma_double_room.py: ObjSearchDelivery_v7 with core_double_room.py.
    Layout {
        gym_id: "OSD-D-v7",
        title: "Warehouse A/B",
        work_areas: &[[6.0, 3.0], [6.0, 2.0]],
        tool_room_wait: [3.0, 2.5],
        tables: &TWO_TABLES,
        tb_starts: &TWO_STARTS,
        n_each_obj: 2,
        early_return_action: 3,
        human_wait_obs: HumanWaitObs::EveryHuman,
        has_state: true,
        terminal_at_terminate_step: false,
        tb_action_names: &["Go_WA0", "Go_WA1", "Go_Tool_Room", "Get_Tool"],
        fetch_action_names: &FETCH_V4_ACTIONS,
        default_human_speeds: &[[27, 20, 20, 20], [27, 20, 20, 20]],
        default_horizon: 200,
    },
    // osd_ma_tripple_room.py: ObjSearchDelivery_v0 with core_tripple_room.py.
    Layout {
        gym_id: "OSD-T-v0",
        title: "Warehouse C",
        work_areas: &TRIPLE_WORK_AREAS,
        tool_room_wait: [3.0, 2.5],
        tables: &TWO_TABLES,
        tb_starts: &TWO_STARTS,
        n_each_obj: 3,
        early_return_action: 4,
        human_wait_obs: HumanWaitObs::HumanHere,
        has_state: true,
        terminal_at_terminate_step: false,
        tb_action_names: &TRIPLE_TB_ACTIONS,
        fetch_action_names: &FETCH_V4_ACTIONS,
        default_human_speeds: &[[40; 4], [40; 4], [40; 4]],
        default_horizon: 250,
    },
    // osd_ma_tripple_room.py: ObjSearchDelivery_v1 (three Turtlebots, AgentFetch_v5).
    Layout {
        gym_id: "OSD-T-v1",
        title: "Warehouse D",
        work_areas: &TRIPLE_WORK_AREAS,
        tool_room_wait: [3.0, 2.5],
        tables: &THREE_TABLES,
        tb_starts: &THREE_STARTS,
        n_each_obj: 3,
        early_return_action: 4,
        human_wait_obs: HumanWaitObs::HumanHere,
        has_state: false,
        terminal_at_terminate_step: false,
        tb_action_names: &TRIPLE_TB_ACTIONS,
        fetch_action_names: &FETCH_V5_ACTIONS,
        default_human_speeds: &[[38; 4], [38; 4], [27; 4]],
        default_horizon: 250,
    },
    // osd_ma_four_room.py: ObjSearchDelivery_v0 with core_four_room.py.
    Layout {
        gym_id: "OSD-F-v0",
        title: "Warehouse E",
        work_areas: &[[6.0, 3.0], [8.0, 3.0], [6.0, 2.0], [8.0, 2.0]],
        tool_room_wait: [3.0, 2.5],
        tables: &THREE_TABLES,
        tb_starts: &THREE_STARTS,
        n_each_obj: 4,
        early_return_action: 4,
        human_wait_obs: HumanWaitObs::HumanHere,
        has_state: false,
        terminal_at_terminate_step: true,
        tb_action_names: &[
            "Go_WA0",
            "Go_WA1",
            "Go_WA2",
            "Go_WA3",
            "Go_Tool_Room",
            "Get_Tool",
        ],
        fetch_action_names: &FETCH_V5_ACTIONS,
        default_human_speeds: &[[40; 4], [40; 4], [40; 4], [40; 4]],
        default_horizon: 300,
    },
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Sizes as the spec's table (section 3) measured them on the reference.
    #[test]
    fn sizes_match_the_reference() {
        let sizes: Vec<_> = LAYOUTS
            .iter()
            .map(|l| {
                (
                    l.tb_obs_size(false),
                    l.fetch_obs_size(false),
                    l.tb_action_names.len(),
                    l.fetch_action_names.len(),
                    l.state_size(),
                )
            })
            .collect();
        assert_eq!(
            sizes,
            [
                (18, 5, 4, 6, 29),
                (23, 5, 5, 6, 34),
                (23, 6, 5, 7, 0),
                (28, 6, 6, 7, 0)
            ]
        );
        for l in &LAYOUTS {
            assert_eq!(l.tb_action_names.len(), l.n_humans() + 2);
            assert_eq!(l.fetch_action_names.len(), 1 + l.n_turtlebots() + N_OBJS);
            assert_eq!(l.tb_starts.len(), l.n_turtlebots());
            assert_eq!(l.default_human_speeds.len(), l.n_humans());
            assert!(l.n_humans() <= MAX_HUMANS && l.n_turtlebots() <= MAX_TURTLEBOTS);
        }
    }
}
