//! Warehouse Tool Delivery (WTD), the reference's `ObjSearchDelivery_v4` ("OSD_S_4"), exact to
//! `docs/WAREHOUSE.md`.
//!
//! Two Turtlebots fetch tools from a table in the tool room and carry them to a human working in
//! the workshop; a Fetch arm searches the tools and passes them over. The human needs tool k to
//! leave work step k; the third correct delivery ends the episode (best return 262 at H = 150).
//!
//! One step's order (`docs/WAREHOUSE.md` §8, quirk Q14) lives in `step.rs`; each robot's rules in its own
//! file. At the paper's settings nothing is random; with `tb_move_noisy > 0` travel steps draw
//! normals from the caller's [`EnvRng`].

mod domain;
pub mod draw;
mod fetch;
mod human;
mod observe;
mod params;
mod pyround;
mod render;
mod spec;
mod step;
mod turtlebot;

#[cfg(test)]
mod properties;
#[cfg(test)]
mod scenarios;
#[cfg(test)]
mod testkit;

pub use domain::WarehouseDomain;
pub use fetch::{Fetch, FetchAction};
pub use human::Human;
pub use observe::{FETCH_OBS, TB_OBS};
pub use params::{WarehouseParams, FETCH_POS, N_TOOLS, TURTLEBOT_STARTS, WAYPOINTS};
pub use pyround::round2;
pub use spec::{paper_spec, spec};
pub use turtlebot::{TbAction, Turtlebot};

use rand_distr::Normal;

use crate::envs::{EnvError, EnvRng, FirstRecordObs, MacroEnv, StepOutcome};
use fetch::FetchDynamics;
use turtlebot::TbDynamics;

/// Number of agents: Turtlebot 0, Turtlebot 1, Fetch.
pub const N_AGENTS: usize = 3;
const OBS_SIZES: [usize; N_AGENTS] = [TB_OBS, TB_OBS, FETCH_OBS];
const N_ACTIONS: [usize; N_AGENTS] = [3, 3, 6];
const TB_ACTION_NAMES: [&str; 3] = ["Go-to-WS", "Go-to-TR", "Get-Tool"];
const FETCH_ACTION_NAMES: [&str; 6] = [
    "Wait-M",
    "Pass-to-M(0)",
    "Pass-to-M(1)",
    "Search-Tool(0)",
    "Search-Tool(1)",
    "Search-Tool(2)",
];

/// The Warehouse Tool Delivery environment. Build with [`Warehouse::new`] or
/// [`Warehouse::paper`]; it starts reset.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Warehouse {
    params: WarehouseParams,
    tb_dyn: TbDynamics,
    fetch_dyn: FetchDynamics,
    tbs: [Turtlebot; 2],
    fetch: Fetch,
    human: Human,
    /// Primitive steps since reset (`count_step`).
    count: usize,
    /// Set once `done` was returned; stepping again is an error until reset.
    over: bool,
    executed: [usize; N_AGENTS],
    mac_done: [bool; N_AGENTS],
    obs_tb: [[f32; TB_OBS]; 2],
    obs_fetch: [f32; FETCH_OBS],
    /// Reward of the last step (for the renderer only).
    last_reward: f64,
}

impl Warehouse {
    /// Validate `params` and build a reset environment.
    pub fn new(params: WarehouseParams) -> Result<Self, EnvError> {
        params.validate()?;
        let noise = if params.tb_move_noisy > 0.0 {
            let normal =
                Normal::new(0.0, params.tb_move_noisy).map_err(|e| EnvError::InvalidParameter {
                    name: "tb_move_noisy",
                    reason: e.to_string(),
                })?;
            Some(normal)
        } else {
            None
        };
        let tb_dyn = TbDynamics {
            speed: params.tb_move_speed,
            wait_limit: params.get_tool_wait(),
            delay_delivery_penalty: params.delay_delivery_penalty,
            noise,
        };
        let fetch_dyn = FetchDynamics {
            pass_steps: f64::from(params.fetch_pass_obj_tc),
            search_steps: f64::from(params.fetch_look_for_obj_tc),
            n_each_obj: params.n_each_obj,
        };
        let mut env = Self {
            tbs: Self::fresh_turtlebots(),
            human: Human::new(params.human_speed_per_step),
            params,
            tb_dyn,
            fetch_dyn,
            fetch: Fetch::default(),
            count: 0,
            over: false,
            executed: [0; N_AGENTS],
            mac_done: [true; N_AGENTS],
            obs_tb: [observe::turtlebot_reset_obs(); 2],
            obs_fetch: [0.0; FETCH_OBS],
            last_reward: 0.0,
        };
        env.reset_state();
        Ok(env)
    }

    /// The paper's environment (all defaults) with horizon `horizon` (the paper uses 150).
    pub fn paper(horizon: usize) -> Result<Self, EnvError> {
        Self::new(WarehouseParams::paper(horizon))
    }

    /// The parameters this environment was built with.
    pub fn params(&self) -> &WarehouseParams {
        &self.params
    }

    /// Turtlebot `i` (0 or 1). Panics if `i > 1`.
    pub fn turtlebot(&self, i: usize) -> &Turtlebot {
        &self.tbs[i]
    }

    /// The Fetch robot's state.
    pub fn fetch(&self) -> &Fetch {
        &self.fetch
    }

    /// The human's state.
    pub fn human(&self) -> &Human {
        &self.human
    }

    fn fresh_turtlebots() -> [Turtlebot; 2] {
        [0, 1].map(|i| Turtlebot::new(TURTLEBOT_STARTS[i], WAYPOINTS[i]))
    }

    /// Rebuild robots and human as at reset (`docs/WAREHOUSE.md` §4); draws nothing.
    fn reset_state(&mut self) {
        self.tbs = Self::fresh_turtlebots();
        self.fetch = Fetch::default();
        self.human = Human::new(self.params.human_speed_per_step);
        self.count = 0;
        self.over = false;
        self.executed = [0; N_AGENTS];
        self.mac_done = [true; N_AGENTS];
        self.obs_tb = [observe::turtlebot_reset_obs(); 2];
        self.obs_fetch = [0.0; FETCH_OBS];
        self.last_reward = 0.0;
    }
}

impl MacroEnv for Warehouse {
    fn n_agents(&self) -> usize {
        N_AGENTS
    }

    fn obs_sizes(&self) -> &[usize] {
        &OBS_SIZES
    }

    fn n_actions(&self) -> &[usize] {
        &N_ACTIONS
    }

    fn action_names(&self, agent: usize) -> &'static [&'static str] {
        match agent {
            0 | 1 => &TB_ACTION_NAMES,
            2 => &FETCH_ACTION_NAMES,
            _ => panic!("agent {agent} out of range 0..{N_AGENTS}"),
        }
    }

    fn obs_names(&self, agent: usize) -> Vec<String> {
        match agent {
            0 | 1 => observe::turtlebot_obs_names(),
            2 => observe::fetch_obs_names(),
            _ => panic!("agent {agent} out of range 0..{N_AGENTS}"),
        }
    }

    fn horizon(&self) -> usize {
        self.params.terminate_step
    }

    /// Reset consumes no random draws (`docs/WAREHOUSE.md` §4).
    fn reset(&mut self, _rng: &mut EnvRng) {
        self.reset_state();
    }

    fn step(&mut self, actions: &[usize], rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        self.step_checked(actions, rng)
    }

    /// The held observation. Note (`docs/WAREHOUSE.md` Q10): the reference's `reset()` list is the env's own
    /// held list and is overwritten by the first step; here the caller copies what it keeps, and a
    /// runner replicating that aliasing does so itself (algorithms `docs/WAREHOUSE.md` Q20).
    fn obs(&self, agent: usize) -> &[f32] {
        match agent {
            0 | 1 => &self.obs_tb[agent],
            2 => &self.obs_fetch,
            _ => panic!("agent {agent} out of range 0..{N_AGENTS}"),
        }
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
        render::render(self)
    }

    /// Warehouse's first step overwrites the held observations of the agents that finished in it
    /// (quirk Q20, faithful).
    fn first_record_obs(&self) -> FirstRecordObs {
        FirstRecordObs::OverwrittenByFirstStep
    }

    /// Random only with Turtlebot movement noise.
    fn deterministic(&self) -> bool {
        self.params.tb_move_noisy == 0.0
    }

    /// Known for the paper's horizon 150 at gamma 1.
    fn optimal_return(&self, discount: f64) -> Option<f64> {
        (self.params.terminate_step == 150 && discount == 1.0).then_some(WTD_OPTIMAL)
    }

    fn describe(&self) -> String {
        format!(
            "Warehouse Tool Delivery, horizon {}",
            self.params.terminate_step
        )
    }

    fn draw(&self) -> Option<crate::draw::Picture> {
        Some(draw::draw(self))
    }
}

/// Best achievable return of Warehouse Tool Delivery (horizon 150, gamma 1); `warehouse.md` 10.
pub const WTD_OPTIMAL: f64 = 262.0;
