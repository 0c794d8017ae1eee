//! Overcooked, the macro-action version MacroMARL trains on (`Overcooked-MA-v1` from
//! gym-macro-overcooked behind MacroMARL's `MacEnvWrapper`), exact to the reference code
//! (`docs/MACROMARL.md` §3.3; where the spec and the code disagree, the code).
//!
//! Agents in a 7 x 7 (or 9 x 9) kitchen fetch a tomato, a lettuce and an onion, chop each
//! three times on a cutting board, gather them on a plate and deliver the task's salad. Every
//! primitive step costs "step penalty", a needed food chopped through earns "subtask finished",
//! the right dish "correct delivery" and ends the episode, anything else handed in "wrong
//! delivery". The episode has no horizon of its own: MacroMARL's runner cuts it at
//! `env_terminate_step`, which is a truncation (the learner bootstraps), not a terminal.
//!
//! Two engine quirks need no code: `_checkMacroActionDone`'s "go to counter" branch tests a
//! name with a trailing space and never fires (see [`macro_actions::ended_after_step`]), and
//! `_checkCollision` reads `info['collision']`, which the primitive step leaves empty, so
//! collisions never end a macro-action (`docs/MACROMARL.md` §3.3, 5.2).
//!
//! ACAC's `Overcooked-MA-v0` (Overcooked-Large, `crate::envs::overcooked_large`) runs this same
//! engine under its own rules ([`layout::Rules::V0`], [`OvercookedParams::large`]).
//!
//! The module follows the reference's layers: [`layout`] (maps), [`world`] (items), `step`
//! (the primitive step), [`astar`] (navigation with Python's heap order), [`macro_actions`]
//! and [`observe`] (belief and macro-observations); `domain` holds the config keys.

pub mod astar;
mod domain;
pub mod draw;
pub mod layout;
pub mod macro_actions;
pub mod numpy_random;
pub mod observe;
pub mod rand_start;
mod render;
pub mod step;
pub mod world;

#[cfg(test)]
mod scenarios;

pub use domain::{map_letter, OvercookedDomain, PAPER_N_AGENT, REFERENCE_N_AGENT};

/// The key readers ACAC's copy of the domain shares (`crate::envs::overcooked_acac`).
pub(crate) mod domain_keys {
    pub(crate) use super::domain::{default_rewards, key_of, params};
}

use self::astar::PyHeap;
use self::layout::{belief_base, large_start_map, start_map, Cells, MapType, Rules, Tile};
use self::macro_actions::{ended_after_step, large_names, low_level, names, Ctx, MacState, Macro};
use self::numpy_random::DrawInt;
use self::numpy_random::NumpyRandom;
use self::observe::{macro_obs, obs_len, reset_belief, task_len, update_belief, Belief, TASKS};
use self::step::{primitive_step, Rewards};
use self::world::{Kit, Numbering, World, FOOD_NAMES, STAY};
use super::{EnvError, EnvRng, MacroEnv, StepOutcome};

/// Everything that defines an Overcooked environment (the reference's constructor arguments
/// and the runner's horizon).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OvercookedParams {
    /// Grid side: 7 (the paper's) or 9 (`grid_dim`).
    pub side: usize,
    /// The map type: A open, B divided, C divided with a gap.
    pub map: MapType,
    /// One of [`TASKS`].
    pub task: String,
    /// The reward of each event.
    pub rewards: Rewards,
    /// 2 or 3. The reference's default is 2 and MacroMARL's scripts never pass `n_agent`, so
    /// as published they train 2 agents while the paper and the shipped policies use 3 (spec
    /// 5.2 item 1; see [`PAPER_N_AGENT`] and [`REFERENCE_N_AGENT`]).
    pub n_agent: usize,
    /// The runner's `env_terminate_step`: the step at which the episode is cut (truncated).
    pub horizon: usize,
    /// The view radius (`obs_radius`, 2; MacroMARL never passes it).
    pub obs_radius: usize,
    /// Whose code numbers the agents, plates and knives: gym-macro-overcooked's row-major scan
    /// or ACAC's column-major one ([`Numbering`]).
    pub numbering: Numbering,
    /// Whether the env has ACAC's global state (`get_vector_state`, [`MacroEnv::write_state`]);
    /// gym-macro-overcooked's has none.
    pub vector_state: bool,
    /// ACAC's `rand_start`: every reset draws a new start map ([`rand_start`]), from the run's
    /// environment stream unless [`Self::np_seed`] is set. Before the first reset the kitchen is
    /// the fixed start map.
    pub rand_start: bool,
    /// With `rand_start`: draw the starts from numpy's legacy stream seeded so (what ACAC's
    /// worker gave `np.random.seed`, continued across resets as ACAC's worker does), not from
    /// the run's stream. For replaying ACAC's episodes.
    pub np_seed: Option<u32>,
    /// With `rand_start`: the grid ACAC's first reset produced (the reference's codes, rows
    /// first). With `np_seed` it must be what numpy's draws give, which building checks; without,
    /// every reset starts from it.
    pub start_map: Option<Vec<Vec<u8>>>,
    /// ACAC's Large kitchen (`Overcooked_V0`'s rules and items) instead of `Overcooked_V1`'s.
    pub large: Option<LargeKitchen>,
}

/// What ACAC's `Overcooked_V0` (Overcooked-Large) is built with beyond V1's keys: its objects,
/// plates and knives. Its rules are [`Rules::V0`]; `task` is read and ignored (`self.task =
/// obj`).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LargeKitchen {
    /// `obj`: the objects' names in item order (ACAC's settings: "A".."F"). One character each,
    /// as ACAC's `_findItem` needs to find them, and distinct.
    pub obj: Vec<String>,
    /// `n_plate`: plates (ACAC's settings: 4).
    pub n_plate: usize,
    /// `n_knife`: knives (ACAC's settings: 4).
    pub n_knife: usize,
}

impl Default for LargeKitchen {
    /// ACAC's `ovcA11_N6` kitchen: objects "A".."F", 4 plates, 4 knives.
    fn default() -> Self {
        LargeKitchen {
            obj: ["A", "B", "C", "D", "E", "F"].map(String::from).to_vec(),
            n_plate: 4,
            n_knife: 4,
        }
    }
}

impl Default for OvercookedParams {
    /// The paper's kitchen: map A, the full salad, 3 agents, horizon 200 (`docs/MACROMARL.md` §3, table).
    fn default() -> Self {
        OvercookedParams {
            side: 7,
            map: MapType::A,
            task: TASKS[6].to_string(),
            rewards: Rewards::default(),
            n_agent: PAPER_N_AGENT,
            horizon: 200,
            obs_radius: 2,
            numbering: Numbering::RowMajor,
            vector_state: false,
            rand_start: false,
            np_seed: None,
            start_map: None,
            large: None,
        }
    }
}

impl OvercookedParams {
    /// What the kitchen holds and whose rules it follows.
    pub fn kit(&self) -> Kit {
        match &self.large {
            None => Kit::V1,
            Some(l) => Kit {
                rules: Rules::V0,
                n_foods: l.obj.len(),
                n_plates: l.n_plate,
                n_knives: l.n_knife,
            },
        }
    }

    /// Refuse what the reference cannot build, naming the parameter.
    pub fn validate(&self) -> Result<(), EnvError> {
        let bad = |name, reason: String| Err(EnvError::InvalidParameter { name, reason });
        if let Some(l) = &self.large {
            self.validate_large(l)?;
        } else if self.side != 7 && self.side != 9 {
            return bad(
                "grid_dim",
                format!("must be [7, 7] or [9, 9], got side {}", self.side),
            );
        }
        if self.large.is_none() && self.n_agent != 2 && self.n_agent != 3 {
            return bad(
                "n_agent",
                format!("the maps have 2 or 3 agents, got {}", self.n_agent),
            );
        }
        if !TASKS.contains(&self.task.as_str()) {
            return bad("task", format!("`{}` is not one of {TASKS:?}", self.task));
        }
        if self.horizon == 0 {
            return bad("horizon", "must be at least 1 primitive step, got 0".into());
        }
        if self.obs_radius == 0 || self.obs_radius > 9 {
            return bad(
                "obs_radius",
                format!("must be 1..=9, got {}", self.obs_radius),
            );
        }
        if !self.rand_start && (self.np_seed.is_some() || self.start_map.is_some()) {
            return bad(
                if self.np_seed.is_some() {
                    "np_seed"
                } else {
                    "start_map"
                },
                "only a random start (`rand_start = true`) draws a start map".into(),
            );
        }
        Ok(())
    }
}

impl OvercookedParams {
    /// The Large kitchen's own limits: ACAC's 11 x 11 grid (the only one its settings use),
    /// 2..=6 agents, 1..=6 distinct one-character objects, 1..=4 plates and knives (what ACAC's
    /// `make_custom_map` places on that grid without overlapping).
    fn validate_large(&self, l: &LargeKitchen) -> Result<(), EnvError> {
        let bad = |name, reason: String| Err(EnvError::InvalidParameter { name, reason });
        if self.side != 11 {
            return bad(
                "grid_dim",
                format!("the Large kitchen is [11, 11], got side {}", self.side),
            );
        }
        if !(2..=layout::MAX_AGENTS).contains(&self.n_agent) {
            return bad(
                "n_agent",
                format!("the Large kitchen holds 2..=6 agents, got {}", self.n_agent),
            );
        }
        if l.obj.is_empty() || l.obj.len() > layout::MAX_FOODS {
            return bad("obj", format!("1..=6 objects, got {}", l.obj.len()));
        }
        for (k, o) in l.obj.iter().enumerate() {
            if o.chars().count() != 1 {
                return bad(
                    "obj",
                    format!(
                        "object names are one character (ACAC's `_findItem` finds no other), \
                         got {o:?}"
                    ),
                );
            }
            if l.obj[..k].contains(o) {
                return bad("obj", format!("object {o:?} is named twice"));
            }
        }
        if !(1..=layout::MAX_PLATES).contains(&l.n_plate) {
            return bad("n_plate", format!("1..=4 plates, got {}", l.n_plate));
        }
        if !(1..=layout::MAX_KNIVES).contains(&l.n_knife) {
            return bad("n_knife", format!("1..=4 knives, got {}", l.n_knife));
        }
        Ok(())
    }
}

/// The Overcooked environment. Deterministic: the rng is never drawn from.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Overcooked {
    params: OvercookedParams,
    /// The fixed start map (`initMap`), which random starts draw from.
    init: Cells,
    /// The start map every reset uses ([`OvercookedParams::start_map`]), checked.
    fixed_start: Option<Cells>,
    /// numpy's stream when the starts replay ACAC's ([`OvercookedParams::np_seed`]).
    numpy: Option<NumpyRandom>,
    /// The kitchen at reset.
    start: World,
    world: World,
    /// The walls-only map every belief map is rebuilt from.
    base: Cells,
    beliefs: Vec<Belief>,
    macs: Vec<MacState>,
    obs: Vec<Vec<f32>>,
    obs_sizes: Vec<usize>,
    n_actions: Vec<usize>,
    executed: Vec<usize>,
    mac_done: Vec<bool>,
    t: usize,
    done: bool,
    /// Scratch of the primitive actions and of the A* search (no allocation per step).
    primitive: Vec<u8>,
    #[serde(skip)]
    heap: PyHeap,
}

impl Overcooked {
    /// A new environment in its reset state.
    pub fn new(params: OvercookedParams) -> Result<Self, EnvError> {
        params.validate()?;
        let n = params.n_agent;
        let kit = params.kit();
        let map = match &params.large {
            None => {
                start_map(params.side, params.map, n).ok_or_else(|| EnvError::InvalidParameter {
                    name: "grid_dim",
                    reason: "no map for this grid and agent count".into(),
                })?
            }
            Some(l) => large_start_map(
                params.side,
                params.map,
                l.obj.len(),
                l.n_plate,
                l.n_knife,
                n,
            )
            .map_err(|reason| EnvError::InvalidParameter {
                name: "obj",
                reason: format!("ACAC's make_custom_map refuses the kitchen: {reason}"),
            })?,
        };
        let start = World::from_map(map, params.side, params.numbering, kit).map_err(|e| {
            EnvError::InvalidParameter {
                name: "map_type",
                reason: format!("the map has no {}", e.0),
            }
        })?;
        let numpy = params.np_seed.map(NumpyRandom::seed);
        let fixed_start = match &params.start_map {
            None => None,
            Some(rows) => Some(checked_start_map(rows, &map, &params, numpy.clone())?),
        };
        let len = obs_len(n, &kit);
        let mut env = Overcooked {
            base: belief_base(params.side, params.map),
            init: map,
            fixed_start,
            numpy,
            world: start.clone(),
            start,
            beliefs: vec![
                Belief {
                    obs: vec![0.0; len],
                    pomap: [[layout::Tile::Counter; layout::MAX_SIDE]; layout::MAX_SIDE],
                };
                n
            ],
            macs: vec![MacState::FRESH; n],
            obs: vec![vec![0.0; len]; n],
            obs_sizes: vec![len; n],
            n_actions: vec![Macro::count(params.map, &kit); n],
            executed: vec![0; n],
            mac_done: vec![true; n],
            t: 0,
            done: false,
            primitive: vec![STAY; n],
            heap: PyHeap::for_grid(params.side),
            params,
        };
        env.reset_state();
        Ok(env)
    }

    /// The parameters the environment was built with.
    pub fn params(&self) -> &OvercookedParams {
        &self.params
    }

    /// The kitchen now.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Agent `agent`'s belief (its last vector observation and belief map).
    pub fn belief(&self, agent: usize) -> &Belief {
        &self.beliefs[agent]
    }

    /// Agent `agent`'s macro-action bookkeeping.
    pub fn mac_state(&self, agent: usize) -> &MacState {
        &self.macs[agent]
    }

    fn radius(&self) -> i32 {
        self.params.obs_radius as i32
    }

    /// ACAC's `reset` with `rand_start`: a new start kitchen (`_make_new_rand_map`, then
    /// `_createItems`), from the fixed start map, numpy's stream or the run's `rng`.
    fn draw_start(&mut self, rng: &mut EnvRng) {
        let map = match (&mut self.numpy, &self.fixed_start) {
            (Some(numpy), _) => random_start_map(&self.init, &self.params, numpy),
            (None, Some(map)) => *map,
            (None, None) => random_start_map(&self.init, &self.params, rng),
        };
        self.start
            .restart_from(map, self.params.numbering)
            .expect("a random start keeps every item of the start map");
    }

    /// `Overcooked_MA_V1.reset`: the start kitchen, full beliefs then the first view, every
    /// agent free, fresh macro-observations.
    fn reset_state(&mut self) {
        self.world.clone_from(&self.start);
        let r = self.radius();
        for (i, b) in self.beliefs.iter_mut().enumerate() {
            reset_belief(&self.world, &self.params.task, b);
            update_belief(&self.world, i, &self.base, r, b);
        }
        self.macs.fill(MacState::FRESH);
        for (i, o) in self.obs.iter_mut().enumerate() {
            macro_obs(&self.world, i, r, &self.params.task, o);
        }
        self.executed.fill(0);
        self.mac_done.fill(true);
        self.t = 0;
        self.done = false;
    }

    /// One step of `run(macro_actions)` as `MacEnvWrapper.step` calls it.
    fn run(&mut self, actions: &[usize]) -> Result<StepOutcome, EnvError> {
        let n = self.params.n_agent;
        if self.done {
            return Err(EnvError::EpisodeOver);
        }
        if actions.len() != n {
            return Err(EnvError::WrongActionCount {
                expected: n,
                got: actions.len(),
            });
        }
        for (agent, (&a, s)) in actions.iter().zip(&self.macs).enumerate() {
            if s.done && a >= self.n_actions[agent] {
                return Err(EnvError::ActionOutOfRange {
                    agent,
                    action: a,
                    n_actions: self.n_actions[agent],
                });
            }
        }
        let r = self.radius();
        {
            let ctx = Ctx {
                world: &self.world,
                map: self.params.map,
                radius: r,
            };
            for (i, &chosen) in actions.iter().enumerate() {
                self.primitive[i] = low_level(
                    &ctx,
                    i,
                    chosen,
                    &self.beliefs[i],
                    &mut self.macs[i],
                    &mut self.heap,
                );
            }
        }
        let (reward, delivered) = primitive_step(
            &mut self.world,
            &self.primitive,
            &self.params.task,
            &self.params.rewards,
        );
        for (i, b) in self.beliefs.iter_mut().enumerate() {
            update_belief(&self.world, i, &self.base, r, b);
        }
        let ctx = Ctx {
            world: &self.world,
            map: self.params.map,
            radius: r,
        };
        for i in 0..n {
            self.macs[i].done = ended_after_step(&ctx, i, &self.beliefs[i], &self.macs[i]);
            self.executed[i] = self.macs[i].current;
            self.mac_done[i] = self.macs[i].done;
            if self.macs[i].done {
                macro_obs(&self.world, i, r, &self.params.task, &mut self.obs[i]);
            }
        }
        self.t += 1;
        if delivered || self.t >= self.params.horizon {
            self.done = true;
            return Ok(StepOutcome::ended(reward, delivered));
        }
        Ok(StepOutcome::running(reward))
    }
}

impl MacroEnv for Overcooked {
    fn n_agents(&self) -> usize {
        self.params.n_agent
    }

    fn obs_sizes(&self) -> &[usize] {
        &self.obs_sizes
    }

    fn n_actions(&self) -> &[usize] {
        &self.n_actions
    }

    fn action_names(&self, agent: usize) -> &'static [&'static str] {
        assert!(agent < self.params.n_agent, "agent {agent} out of range");
        match &self.params.large {
            None => names(self.params.map),
            Some(l) => large_names(self.params.map, &l.obj, &self.params.kit()),
        }
    }

    fn obs_names(&self, agent: usize) -> Vec<String> {
        assert!(agent < self.params.n_agent, "agent {agent} out of range");
        let kit = self.params.kit();
        match &self.params.large {
            None => observe::obs_names(self.params.n_agent, &FOOD_NAMES, &kit),
            Some(l) => {
                let foods: Vec<&str> = l.obj.iter().map(String::as_str).collect();
                observe::obs_names(self.params.n_agent, &foods, &kit)
            }
        }
    }

    fn horizon(&self) -> usize {
        self.params.horizon
    }

    fn reset(&mut self, rng: &mut EnvRng) {
        if self.params.rand_start {
            self.draw_start(rng);
        }
        self.reset_state();
    }

    fn step(&mut self, actions: &[usize], _rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        self.run(actions)
    }

    fn obs(&self, agent: usize) -> &[f32] {
        &self.obs[agent]
    }

    /// After reset (before any step) this is all 0 and means nothing.
    fn executed(&self) -> &[usize] {
        &self.executed
    }

    fn mac_done(&self) -> &[bool] {
        &self.mac_done
    }

    fn t(&self) -> usize {
        self.t
    }

    fn render_ascii(&self) -> String {
        render::render(&self.world)
    }

    fn describe(&self) -> String {
        format!(
            "Overcooked{} map {} {}x{}, {} agents, horizon {}",
            if self.params.large.is_some() {
                "-Large (ACAC's Overcooked-MA-v0)"
            } else {
                ""
            },
            self.params.map.letter(),
            self.params.side,
            self.params.side,
            self.params.n_agent,
            self.params.horizon
        )
    }

    fn draw(&self) -> Option<crate::draw::Picture> {
        Some(draw::draw(self))
    }

    /// ACAC's `get_vector_state()`: the observation's items at their true places, without the
    /// task one-hot (25 values for 3 agents); none for gym-macro-overcooked's env.
    fn state_size(&self) -> usize {
        if self.params.vector_state {
            let kit = self.params.kit();
            obs_len(self.params.n_agent, &kit) - task_len(&kit)
        } else {
            0
        }
    }

    fn write_state(&self, out: &mut [f32]) {
        assert_eq!(out.len(), self.state_size(), "state buffer length");
        observe::vector_state(&self.world, out);
    }
}

/// A random start map of `init` (see [`rand_start`]) with the draws of `draws`.
fn random_start_map(init: &Cells, p: &OvercookedParams, draws: &mut impl DrawInt) -> Cells {
    let kit = p.kit();
    let mut codes = [[0u8; layout::MAX_SIDE]; layout::MAX_SIDE];
    for (row, tiles) in codes.iter_mut().zip(init) {
        for (c, t) in row.iter_mut().zip(tiles) {
            *c = kit.rules.code(*t);
        }
    }
    let drawn = rand_start::random_start(&codes, p.side, p.map, draws);
    let mut out = *init;
    for (row, codes) in out.iter_mut().zip(&drawn) {
        for (t, &c) in row.iter_mut().zip(codes) {
            *t = kit
                .rules
                .tile(c, kit.n_foods)
                .expect("a random start moves the start map's own codes");
        }
    }
    out
}

/// `rows` as a start map after checking it: the side's square grid of the reference's codes,
/// with the walls of `init` and its items, and equal to numpy's first draw when `numpy` is given.
fn checked_start_map(
    rows: &[Vec<u8>],
    init: &Cells,
    p: &OvercookedParams,
    numpy: Option<NumpyRandom>,
) -> Result<Cells, EnvError> {
    let bad = |reason: String| {
        Err(EnvError::InvalidParameter {
            name: "start_map",
            reason,
        })
    };
    let side = p.side;
    let kit = p.kit();
    if rows.len() != side || rows.iter().any(|r| r.len() != side) {
        return bad(format!("must be {side} rows of {side} cells (grid_dim)"));
    }
    let mut map = *init;
    // Codes are at most 5 + 6 objects.
    let (mut given, mut wanted) = ([0usize; 12], [0usize; 12]);
    for (x, row) in rows.iter().enumerate() {
        for (y, &code) in row.iter().enumerate() {
            let Some(t) = kit.rules.tile(code, kit.n_foods) else {
                return bad(format!(
                    "cell ({x}, {y}) holds {code}, not a code of this kitchen"
                ));
            };
            let walkable = |t: Tile| matches!(t, Tile::Space | Tile::Agent);
            if walkable(t) != walkable(init[x][y]) {
                return bad(format!(
                    "cell ({x}, {y}) holds {code}, but the {} map has {} there",
                    p.map.letter(),
                    if walkable(init[x][y]) {
                        "floor"
                    } else {
                        "a counter"
                    }
                ));
            }
            given[code as usize] += 1;
            wanted[kit.rules.code(init[x][y]) as usize] += 1;
            map[x][y] = t;
        }
    }
    if given[2..] != wanted[2..] {
        return bad(format!(
            "holds {:?} agents and items of codes 2.., the start map {:?}",
            &given[2..],
            &wanted[2..]
        ));
    }
    if let Some(mut numpy) = numpy {
        let drawn = random_start_map(init, p, &mut numpy);
        if let Some((x, y)) = (0..side)
            .flat_map(|x| (0..side).map(move |y| (x, y)))
            .find(|&(x, y)| drawn[x][y] != map[x][y])
        {
            return bad(format!(
                "disagrees with numpy's draws from np_seed {}: cell ({x}, {y}) is {} in \
                 start_map, {} by the draws",
                p.np_seed.unwrap_or_default(),
                kit.rules.code(map[x][y]),
                kit.rules.code(drawn[x][y])
            ));
        }
    }
    Ok(map)
}
