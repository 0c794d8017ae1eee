//! Your own domain in one file: a small macro-action task defined here, trained with Our-1 and
//! Dec-HDDRQN through the library entry point `macdec::train_policy`, learning curves printed, the
//! known optimum checked, and the Our-1 policy exported as a policy directory that `macdec robot`
//! serves.
//!
//! Rendezvous: two robots on a corridor of 9 cells must meet at one of three waypoints (cells 0,
//! 4 and 8). Robot 0 starts at cell 1, robot 1 at cell 7. Each macro-action is "go to waypoint k"
//! and lasts until the robot is there (one step of waiting if it already is). Every primitive step
//! costs 1; the episode ends with a bonus when both robots stand on the same waypoint (20 at
//! the left end, 5 in the middle, 8 at the right end), or after 20 steps. Each robot sees only its
//! own cell, so the team must agree on the far, rich left waypoint without communicating; the
//! near middle one is the trap.
//!
//! Run: `cargo run --release --example custom_domain [-- OUT_DIR]`. With `OUT_DIR` the curves are
//! also written as `OUT_DIR/custom_domain/<method>/seed-0/metrics.csv`, which
//! `macdec plot --results OUT_DIR` draws like any other experiment.
//!
//! The Our-1 policy is written to `<temp dir>/macdec-rendezvous-our1` (rewritten on every run);
//! serve agent 0 with `macdec robot --policy <that dir> --agent 0`. `macdec eval`, `deploy`,
//! `domain` and `render` refuse it: Rendezvous is not built into the binary.

use macdec::experiment::metrics;
use macdec::{paper_defaults, EnvError, EnvRng, MacroEnv, Method, PolicyEnv, StepOutcome};

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
/// Horizon in primitive steps.
const HORIZON: usize = 20;
/// Discount per primitive step in evaluation (and per macro-transition in the targets).
const DISCOUNT: f64 = 0.95;

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
}

impl Rendezvous {
    fn new() -> Self {
        let mut env = Rendezvous {
            pos: STARTS,
            target: [0; 2],
            executed: [0; 2],
            mac_done: [true; 2],
            obs: [[0.0; CELLS]; 2],
            t: 0,
            done: false,
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
        HORIZON
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
        self.done = met.is_some() || self.t >= HORIZON;
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
    /// same, so the best return is the best such walk.
    fn optimal_return(&self, discount: f64) -> Option<f64> {
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
        format!("Rendezvous corridor, horizon {HORIZON}")
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out_dir = std::env::args().nth(1).map(std::path::PathBuf::from);
    let optimum = Rendezvous::new()
        .optimal_return(DISCOUNT)
        .expect("the optimum is known");
    println!("Rendezvous: optimal return {optimum:.4}");
    let mut all_reached = true;
    for method in [Method::Our1, Method::DecHddrqn] {
        // Start from the paper's Warehouse settings (whole-episode replay) and scale them down.
        // The config's `env` stays Warehouse's: `macdec::train` trains on Rendezvous instead and
        // takes the horizon from it.
        let mut config = paper_defaults(&macdec::envs::warehouse::paper_spec(), method);
        config.discount = DISCOUNT;
        config.total_epi = 3000;
        config.eps_l_d_steps = 1500;
        config.h_stable_at = 1500;
        config.eps_end = 0.05;
        config.replay_buffer_size = 500;
        config.batch_size = 16;
        config.train_freq = 5;
        config.target_update_freq = 200;
        config.l_rate = 0.001;
        config.dec_rnn_h_size = 32;
        config.cen_rnn_h_size = 32;
        config.eval_freq = 200;
        let trained = macdec::train_policy(Rendezvous::new_ok, &config, method, 0, |_| {})?;
        let evals = &trained.evals;
        println!("\n{} ({}):", method.legend(), method);
        println!("  episode   return");
        for e in evals {
            println!("  {:>7}  {:>7.3}", e.episode, e.eval_return);
        }
        let last = evals.last().map_or(f64::NEG_INFINITY, |e| e.eval_return);
        let reached = (last - optimum).abs() < 1e-9;
        all_reached &= reached;
        println!(
            "  final {last:.4}: {}",
            if reached { "optimal" } else { "NOT optimal" }
        );
        if let Some(dir) = &out_dir {
            let run = dir.join("custom_domain").join(method.name()).join("seed-0");
            std::fs::create_dir_all(&run)?;
            metrics::write(
                &run.join(metrics::METRICS_FILE),
                trained.metric_columns,
                evals,
            )?;
        }
        if method == Method::Our1 {
            // The layout (observation and macro-action names) comes from the env object.
            let env = Rendezvous::new();
            let policy = std::env::temp_dir().join("macdec-rendezvous-our1");
            trained.export(&policy, &env, PolicyEnv::custom("rendezvous", &env))?;
            println!(
                "  policy exported to {}\n  serve agent 0: macdec robot --policy {} --agent 0",
                policy.display(),
                policy.display()
            );
        }
    }
    if !all_reached {
        return Err("a method did not reach the optimum".into());
    }
    Ok(())
}

impl Rendezvous {
    /// The factory `macdec::train` calls for every environment it needs.
    fn new_ok() -> Result<Self, EnvError> {
        Ok(Self::new())
    }
}
