//! Your own domain with macdec's whole command line: a small macro-action task defined here, and
//! a `main` that is macdec's command line with the task registered.
//!
//! Rendezvous: two robots on a corridor of 9 cells must meet at one of three waypoints (cells 0,
//! 4 and 8). Robot 0 starts at cell 1, robot 1 at cell 7. Each macro-action is "go to waypoint k"
//! and lasts until the robot is there (one step of waiting if it already is). Every primitive step
//! costs 1; the episode ends with a bonus when both robots stand on the same waypoint (20 at
//! the left end, 5 in the middle, 8 at the right end), or after `env_terminate_step` steps
//! (default 20). Each robot sees only its own cell, so the team must agree on the far, rich left
//! waypoint without communicating; the near middle one is the trap.
//!
//! ```text
//! cargo run --release --example custom_domain -- train --config examples/custom_domain.toml --out results
//! cargo run --release --example custom_domain -- plot --results results --out results
//! cargo run --release --example custom_domain -- export --run results/custom_domain/our1/seed-0 --out policy
//! cargo run --release --example custom_domain -- eval --policy policy
//! ```
//!
//! Configs select the task with `env_name = "rendezvous"`; its one key is `env_terminate_step`.
//! Runs resume after a kill, plots draw its optimal return, and `render` says it has no picture
//! (implement `MacroEnv::draw` to give it one). A crate of your own does the same: depend on
//! macdec, implement `MacroEnv` and `Domain`, and call `macdec::cli::main_with`.

use macdec::envs::domain::{fill_keys, key_table, key_usize, Domain, KeyError, HORIZON_KEY};
use macdec::{EnvError, EnvRng, MacroEnv, StepOutcome};

/// Corridor cells.
const CELLS: usize = 9;
/// Waypoint cells, one macro-action each.
const WAYPOINTS: [usize; 3] = [0, 4, 8];
/// Team bonus for meeting at each waypoint.
const BONUS: [f64; 3] = [20.0, 5.0, 8.0];
/// Start cells of the two robots.
const STARTS: [usize; 2] = [1, 7];
/// Team cost of one primitive step.
const STEP_COST: f64 = 1.0;
/// Default horizon in primitive steps.
const HORIZON: usize = 20;

const ACTION_NAMES: [&str; 3] = ["go_left_end", "go_middle", "go_right_end"];

/// The domain's whole state. `Clone` and serde are what the trainer asks of a domain it keeps.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Rendezvous {
    pos: [usize; 2],
    /// The waypoint index each robot is heading to.
    target: [usize; 2],
    executed: [usize; 2],
    mac_done: [bool; 2],
    /// Held macro-observations: one-hot of the robot's cell, refreshed when its macro-action ends.
    obs: [[f32; CELLS]; 2],
    t: usize,
    done: bool,
    horizon: usize,
}

impl Rendezvous {
    fn new(horizon: usize) -> Self {
        let mut env = Rendezvous {
            pos: STARTS,
            target: [0; 2],
            executed: [0; 2],
            mac_done: [true; 2],
            obs: [[0.0; CELLS]; 2],
            t: 0,
            done: false,
            horizon,
        };
        env.reset(&mut <EnvRng as rand::SeedableRng>::seed_from_u64(0));
        env
    }

    fn observe(&mut self, agent: usize) {
        self.obs[agent] = [0.0; CELLS];
        self.obs[agent][self.pos[agent]] = 1.0;
    }
}

impl MacroEnv for Rendezvous {
    fn n_agents(&self) -> usize {
        2
    }
    fn obs_sizes(&self) -> &[usize] {
        &[CELLS, CELLS]
    }
    fn n_actions(&self) -> &[usize] {
        &[3, 3]
    }
    fn action_names(&self, _agent: usize) -> &'static [&'static str] {
        &ACTION_NAMES
    }
    fn obs_names(&self, _agent: usize) -> Vec<String> {
        (0..CELLS).map(|c| format!("at_cell_{c}")).collect()
    }
    fn horizon(&self) -> usize {
        self.horizon
    }

    fn reset(&mut self, _rng: &mut EnvRng) {
        self.pos = STARTS;
        self.mac_done = [true; 2];
        self.t = 0;
        self.done = false;
        for agent in 0..2 {
            self.observe(agent);
        }
    }

    fn step(&mut self, actions: &[usize], _rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        if self.done {
            return Err(EnvError::EpisodeOver);
        }
        if actions.len() != 2 {
            return Err(EnvError::WrongActionCount {
                expected: 2,
                got: actions.len(),
            });
        }
        for (agent, &action) in actions.iter().enumerate() {
            if self.mac_done[agent] {
                if action >= WAYPOINTS.len() {
                    return Err(EnvError::ActionOutOfRange {
                        agent,
                        action,
                        n_actions: WAYPOINTS.len(),
                    });
                }
                self.target[agent] = action;
            }
        }
        for agent in 0..2 {
            let goal = WAYPOINTS[self.target[agent]];
            let p = &mut self.pos[agent];
            *p = match (*p).cmp(&goal) {
                std::cmp::Ordering::Less => *p + 1,
                std::cmp::Ordering::Greater => *p - 1,
                std::cmp::Ordering::Equal => *p,
            };
            self.executed[agent] = self.target[agent];
            self.mac_done[agent] = *p == goal;
            if self.mac_done[agent] {
                self.observe(agent);
            }
        }
        self.t += 1;
        let mut reward = -STEP_COST;
        let met = WAYPOINTS
            .iter()
            .position(|&w| self.pos == [w, w])
            .map(|k| BONUS[k]);
        if let Some(bonus) = met {
            reward += bonus;
        }
        self.done = met.is_some() || self.t >= self.horizon;
        if self.done {
            // Every macro-action ends with the episode.
            self.mac_done = [true; 2];
            for agent in 0..2 {
                self.observe(agent);
            }
        }
        Ok(StepOutcome {
            reward,
            done: self.done,
            // The horizon cut counts as terminal, as in the ICRA domains.
            truncated: false,
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
        self.t
    }
    fn render_ascii(&self) -> String {
        (0..CELLS)
            .map(|c| match (self.pos[0] == c, self.pos[1] == c) {
                (true, true) => 'X',
                (true, false) => '0',
                (false, true) => '1',
                _ if WAYPOINTS.contains(&c) => '+',
                _ => '.',
            })
            .collect()
    }

    /// Both robots walk straight to one waypoint: meeting at waypoint w cannot happen before
    /// the farther robot arrives, the bonus is paid only at the meeting and every step costs the
    /// same, so the best return is the best such walk (at the default horizon, which all walks
    /// fit in).
    fn optimal_return(&self, discount: f64) -> Option<f64> {
        if self.horizon != HORIZON {
            return None;
        }
        WAYPOINTS
            .iter()
            .zip(BONUS)
            .map(|(&w, bonus)| {
                let steps = STARTS.iter().map(|&s| s.abs_diff(w)).max().unwrap().max(1);
                let cost: f64 = (0..steps)
                    .map(|k| -STEP_COST * discount.powi(k as i32))
                    .sum();
                cost + bonus * discount.powi(steps as i32 - 1)
            })
            .reduce(f64::max)
    }

    fn describe(&self) -> String {
        format!("Rendezvous corridor, horizon {}", self.horizon)
    }
}

/// The task as configs, runs and policy files know it.
struct RendezvousDomain;

impl Domain for RendezvousDomain {
    type Env = Rendezvous;

    fn name(&self) -> &'static str {
        "rendezvous"
    }

    /// One key, the horizon; the walks to the waypoints need at least 7 steps.
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        let keys = fill_keys(given, key_table([(HORIZON_KEY, (HORIZON as i64).into())]))?;
        let horizon = key_usize(&keys, HORIZON_KEY)?;
        if !(7..=10_000).contains(&horizon) {
            return Err(KeyError::new(
                HORIZON_KEY,
                format!("must be 7 to 10000 (a meeting takes 7 steps), got {horizon}"),
            ));
        }
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<Rendezvous, KeyError> {
        Ok(Rendezvous::new(key_usize(keys, HORIZON_KEY)?))
    }
}

fn main() -> std::process::ExitCode {
    macdec::cli::main_with(&[&RendezvousDomain])
}
