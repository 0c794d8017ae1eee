//! Animated rollouts of a trained run's greedy policy (`macdec render`).

use crate::algos::acting::ActScratch;
use crate::algos::evaluate::GreedyActor;
use crate::algos::trainer::env_spec;
use crate::experiment::seeds::{stream, Role};
use crate::experiment::train_run::{load_checkpoint, RunError, CHECKPOINT};
use crate::render::{record_episode, write_gif, RenderError};
use std::path::Path;

/// Why a rollout could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RolloutError {
    #[error(transparent)]
    Run(#[from] RunError),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error("{0}: cannot build the run's environment: {1}")]
    Env(String, crate::envs::EnvError),
}

/// Render `episodes` greedy episodes of the run in `run_dir` (its last checkpoint) into one GIF.
/// Returns each episode's undiscounted team return.
pub fn render_run(
    run_dir: &Path,
    episodes: usize,
    out: &Path,
    frame_ms: u32,
) -> Result<Vec<f64>, RolloutError> {
    let trainer = load_checkpoint(&run_dir.join(CHECKPOINT))?;
    let mut env = env_spec(trainer.config())
        .build()
        .map_err(|e| RolloutError::Env(run_dir.display().to_string(), e))?;
    let dec = trainer.dec_policies();
    let policy = trainer.greedy_policy(&dec);
    let mut rng = stream(trainer.seed(), Role::EvalEnv);
    let mut scratch = ActScratch::new(&env);
    let mut frames = Vec::new();
    let mut returns = Vec::new();
    for _ in 0..episodes.max(1) {
        let mut actor = GreedyActor::new(policy);
        let episode = record_episode(&mut env, &mut rng, |e, a| actor.choose(e, &mut scratch, a))?;
        returns.push(episode.last().map_or(0.0, |f| f.team_return));
        frames.extend(episode);
    }
    write_gif(&frames, out, frame_ms)?;
    Ok(returns)
}
