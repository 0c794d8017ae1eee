//! Animated rollouts of a trained run's policy (`macdec render`): reads the run's policy files,
//! whatever the method's family (Q-nets or actors, one per agent or one for the team), and draws
//! its episodes. The nets act exactly as `macdec eval` runs them ([`Team`]): per-agent nets
//! through the same in-process links, greedy or sampled; a centralized Q-net with the
//! conditional argmax, Mac-CAC's centralized actor as one team policy choosing joint
//! macro-actions.

use crate::deploy::drive::driver::TeamDecisions;
use crate::deploy::drive::local_eval::Choice;
use crate::deploy::drive::team::Team;
use crate::envs::{EnvRng, MacroEnv};
use crate::experiment::definition::seeds::{stream, Role};
use crate::policy_files::{Manifest, NetRole, PolicyError, POLICY_DIR};
use crate::render::{play_episode, write_gif_with, RenderError};
use std::path::Path;

/// Why a rollout could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RolloutError {
    /// The run's policy files could not be read.
    #[error(transparent)]
    Policy(#[from] PolicyError),
    /// Recording or writing the GIF failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The run's domain is not in this binary: the run directory and why.
    #[error("{0}: {1}")]
    NotInBinary(String, crate::policy_files::NotInBinary),
    /// The run's environment cannot be built: the run directory and the error.
    #[error("{0}: cannot build the run's environment: {1}")]
    Env(String, crate::envs::EnvError),
    /// The nets do not fit the domain: the run directory and why.
    #[error("{0}: the policy files' nets do not fit the domain: {1}")]
    NetSize(String, String),
    /// The run has no net of the kind asked for: the run directory, the kind, the method.
    #[error("{0}: the run has no {1} net (method {2}); leave out --net to show the nets its evaluations used")]
    NoNet(String, &'static str, String),
}

/// Render `episodes` episodes of the run in `run_dir` (its policy files, as of its last
/// checkpoint) into one GIF.
///
/// `net` picks which nets act: `None` the ones the run's evaluations used; `Some(Cen)` the
/// centralized net that Our-1, Our-1-R and Our-2 train beside their decentralized ones, so their
/// joint policy can be set against what decentralized execution reached. `choice` is how actors
/// pick (greedy, or sampled as MacroMARL evaluates; Q-nets are always greedy and refuse
/// [`Choice::Sampled`], as `eval` does). Returns each episode's undiscounted team return.
pub fn render_run(
    run_dir: &Path,
    net: Option<NetRole>,
    choice: Choice,
    episodes: usize,
    out: &Path,
    frame_ms: u32,
) -> Result<Vec<f64>, RolloutError> {
    let dir = run_dir.join(POLICY_DIR);
    if !dir
        .join(crate::policy_files::manifest::POLICY_FILE)
        .exists()
    {
        return Err(PolicyError::MissingRun {
            dir: run_dir.to_path_buf(),
        }
        .into());
    }
    let manifest = Manifest::read(&dir)?;
    let at = || run_dir.display().to_string();
    let spec = manifest
        .env
        .known()
        .map_err(|e| RolloutError::NotInBinary(at(), e))?;
    let mut env = spec.build().map_err(|e| RolloutError::Env(at(), e))?;
    let missing = |what| RolloutError::NoNet(at(), what, manifest.run.method.clone());
    let rng = stream(manifest.run.seed, Role::EvalEnv);
    let mut team = Team::load(
        &manifest,
        &dir,
        net.unwrap_or(manifest.evaluated),
        choice,
        &rng,
    )
    .map_err(|e| match e {
        PolicyError::NoAgentNet { .. } => missing("decentralized"),
        PolicyError::NoCentralNet { .. } => missing("centralized"),
        e => e.into(),
    })?;
    if let Team::Central(central) = &team {
        let (input, output) = (env.joint_obs_size(), env.n_joint_actions());
        let net = central.net();
        if (net.obs_len(), net.n_actions()) != (input, output) {
            return Err(RolloutError::NetSize(
                at(),
                format!(
                    "the centralized net has {} inputs and {} outputs, the domain needs {input} and {output}",
                    net.obs_len(),
                    net.n_actions()
                ),
            ));
        }
    }
    let mut rng = rng;
    // Frames go to the file as they are drawn: memory is two frames, whatever the episodes.
    let returns = write_gif_with(out, frame_ms, |gif| {
        (0..episodes.max(1))
            .map(|_| play_team_episode(&mut env, &mut team, &mut rng, |f| gif.push(&f)))
            .collect::<Result<Vec<f64>, RenderError>>()
    })?;
    Ok(returns)
}

/// One episode of `team` on `env`, every frame handed to `each`; the undiscounted team return.
fn play_team_episode<E: MacroEnv>(
    env: &mut E,
    team: &mut Team,
    rng: &mut EnvRng,
    each: impl FnMut(crate::render::Frame) -> Result<(), RenderError>,
) -> Result<f64, RenderError> {
    team.reset().map_err(|e| RenderError::Policy {
        t: 0,
        message: e.to_string(),
    })?;
    let choose = |e: &E, actions: &mut [usize]| team.decide(e, actions).map_err(|e| e.to_string());
    play_episode(env, rng, choose, each)
}
