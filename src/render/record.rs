//! Play one episode and keep a picture of every primitive step.

use super::{draw_frame, Frame, RenderError};
use crate::envs::{EnvRng, MacroEnv};

/// Reset `env`, then let `choose` fill the actions and step until the episode ends, drawing a
/// frame after the reset and after every step (so an episode of T steps gives T + 1 frames; the
/// last is marked [`Frame::hold`]). Keeps every frame: [`play_episode`] streams them instead.
///
/// `choose(env, actions)` sees the state before each step and writes `actions[i]` for every free
/// agent ([`MacroEnv::is_free`]); entries of busy agents are ignored by the environment (spec
/// `algorithms.md` 1.1) and keep whatever was there. `actions` starts as zeros. At most
/// `env.horizon()` steps are taken, so a loop that never sees `done` still stops. A step the
/// environment refuses (an out-of-range action) is returned as [`RenderError::Env`]; a domain
/// that draws no picture, as [`RenderError::NoPicture`] before any step.
pub fn record_episode<E: MacroEnv>(
    env: &mut E,
    rng: &mut EnvRng,
    mut choose: impl FnMut(&E, &mut [usize]),
) -> Result<Vec<Frame>, RenderError> {
    let mut frames = Vec::new();
    let choose = |env: &E, actions: &mut [usize]| {
        choose(env, actions);
        Ok::<(), String>(())
    };
    play_episode(env, rng, choose, |frame| {
        frames.push(frame);
        Ok(())
    })?;
    Ok(frames)
}

/// [`record_episode`] that hands each frame to `each` as soon as the next one is drawn (the last
/// once it is known to be last, marked [`Frame::hold`]) instead of keeping them, so memory stays
/// at two frames whatever the episode's length. Returns the undiscounted team return.
pub fn play_episode<E: MacroEnv>(
    env: &mut E,
    rng: &mut EnvRng,
    mut choose: impl FnMut(&E, &mut [usize]) -> Result<(), String>,
    mut each: impl FnMut(Frame) -> Result<(), RenderError>,
) -> Result<f64, RenderError> {
    env.reset(rng);
    let mut actions = vec![0usize; env.n_agents()];
    let mut team_return = 0.0;
    let mut pending = Frame::capture(env, team_return)?;
    for _ in 0..env.horizon() {
        choose(env, &mut actions).map_err(|message| RenderError::Policy {
            t: env.t() + 1,
            message,
        })?;
        let out = env.step(&actions, rng).map_err(|source| RenderError::Env {
            t: env.t() + 1,
            source,
        })?;
        team_return += out.reward;
        each(std::mem::replace(
            &mut pending,
            Frame::capture(env, team_return)?,
        ))?;
        if out.done {
            break;
        }
    }
    pending.hold = true;
    each(pending)?;
    Ok(team_return)
}

impl Frame {
    /// Draw `env` now. Not held. [`RenderError::NoPicture`] if its domain draws none.
    pub fn capture(env: &impl MacroEnv, team_return: f64) -> Result<Self, RenderError> {
        let image = draw_frame(env, team_return).ok_or_else(|| RenderError::NoPicture {
            domain: env.describe(),
        })?;
        Ok(Self {
            image,
            t: env.t(),
            team_return,
            hold: false,
        })
    }
}
