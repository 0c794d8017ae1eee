//! `macdec bench train`: whole training, end to end (acting, env steps, replay, squeezing,
//! updates, evaluation), single run, one thread, at the papers' settings for the first episodes.
//!
//! The reference's figures quoted in the issues were taken the same way (first 200 episodes of
//! Box Pushing 10x10, all costs included), so the rates compare like for like.

use crate::algos::families::AnyLoop;
use crate::algos::families::{Family, Method};
use crate::algos::training_loop::{Advance, TrainError};
use crate::envs::EnvSpec;
use crate::experiment::run::train_run::run_rngs;
use std::time::Instant;

/// What one benchmarked run did and how fast.
#[derive(Debug, Clone)]
pub struct TrainBench {
    /// The benchmark's label.
    pub name: String,
    /// Training episodes run.
    pub episodes: u64,
    /// Primitive steps taken.
    pub env_steps: u64,
    /// Training updates done.
    pub updates: u64,
    /// Wall-clock time of the run.
    pub seconds: f64,
}

impl TrainBench {
    /// Episodes per wall-clock second.
    pub fn episodes_per_second(&self) -> f64 {
        self.episodes as f64 / self.seconds
    }
    /// Primitive steps per wall-clock second.
    pub fn env_steps_per_second(&self) -> f64 {
        self.env_steps as f64 / self.seconds
    }
    /// Updates per wall-clock second.
    pub fn updates_per_second(&self) -> f64 {
        self.updates as f64 / self.seconds
    }
}

/// The configurations benchmarked: every value method on BP 10x10 (Our-2 is episode-buffer only,
/// quirk Q10) and on Warehouse; every actor-critic method on MacroMARL's Box Pushing 10x10 and
/// Mac-IAICC on its Warehouse A, at the published settings (issue 28's side-by-side pair is
/// `bpma10 mac-iaisc`, 32 environments, and `osd-d-v7 mac-iaicc`, 4).
pub fn suite() -> Vec<(EnvSpec, Method)> {
    let bp10 = crate::envs::box_pushing::paper_spec(10);
    // A method whose paper settings a domain refuses (Our-2 on windows) is not benchmarked there.
    let runs_on = |env: &EnvSpec, m: Method| {
        crate::envs::EnvShape::of(env).is_ok_and(|shape| m.check(&m.defaults(env), &shape).is_ok())
    };
    let value = Family::Value.methods();
    let mut v: Vec<(EnvSpec, Method)> = value
        .iter()
        .filter(|&&m| runs_on(&bp10, m))
        .map(|&m| (bp10.clone(), m))
        .collect();
    v.extend(
        value
            .iter()
            .map(|&m| (crate::envs::warehouse::paper_spec(), m)),
    );
    v.extend(
        Family::ActorCritic
            .methods()
            .into_iter()
            .map(|m| (crate::envs::bp_ma_v0::spec(10, 100), m)),
    );
    let warehouse_a = EnvSpec::new("OSD-D-v7", &toml::Table::new()).expect("a built-in domain");
    v.push((warehouse_a, "mac-iaicc".parse().expect("a method")));
    v
}

/// Train `method` on `env` at the paper's settings for `episodes` episodes (seed 0) and time it.
pub fn bench_train(
    env: EnvSpec,
    method: Method,
    episodes: usize,
) -> Result<TrainBench, TrainError> {
    let mut config = method.defaults(&env);
    config.set_total_epi(episodes);
    let start = Instant::now();
    let mut trainer = AnyLoop::new(&config, method, 0, run_rngs(0), || env.build())?;
    while trainer.advance()? != Advance::Finished {}
    let seconds = start.elapsed().as_secs_f64();
    Ok(TrainBench {
        name: name(&env, method),
        episodes: trainer.episodes(),
        env_steps: trainer.env_steps(),
        updates: trainer.updates(),
        seconds,
    })
}

/// The row name of a configuration, e.g. `bp10 our1`.
pub fn name(env: &EnvSpec, method: Method) -> String {
    format!("{} {method}", env.short_name())
}

/// A Markdown table of the results.
pub fn format_table(rows: &[TrainBench]) -> String {
    let mut s = String::from(
        "| run | episodes | env steps | updates | seconds | episodes/s | env steps/s | updates/s | ms per update (all costs) |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        s += &format!(
            "| {} | {} | {} | {} | {:.1} | {:.1} | {:.0} | {:.1} | {:.2} |\n",
            r.name,
            r.episodes,
            r.env_steps,
            r.updates,
            r.seconds,
            r.episodes_per_second(),
            r.env_steps_per_second(),
            r.updates_per_second(),
            1e3 * r.seconds / r.updates.max(1) as f64
        );
    }
    s
}
