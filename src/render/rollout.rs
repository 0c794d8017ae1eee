//! Animated rollouts of a trained run's greedy policy (`macdec render`): reads the run's policy
//! files and draws its episodes.

use crate::algos::value::acting::ActScratch;
use crate::algos::value::evaluate::GreedyActor;
use crate::algos::value::evaluate::GreedyPolicy;
use crate::envs::MacroEnv;
use crate::experiment::definition::seeds::{stream, Role};
use crate::nn::QNet;
use crate::policy_files::{read_policy_files, NetRole, PolicyError};
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
    #[error("{0}: the run has no {1} Q-net (method {2}); leave out --net to show the nets its evaluations used")]
    NoNet(String, &'static str, String),
}

/// Render `episodes` greedy episodes of the run in `run_dir` (its policy files, as of its last
/// checkpoint) into one GIF.
///
/// `net` picks which nets act: `None` the ones the run's evaluations used; `Some(Cen)` the
/// centralized net that Our-1, Our-1-R and Our-2 train beside their decentralized ones, so their
/// joint policy can be set against what decentralized execution reached.
/// Returns each episode's undiscounted team return.
pub fn render_run(
    run_dir: &Path,
    net: Option<NetRole>,
    episodes: usize,
    out: &Path,
    frame_ms: u32,
) -> Result<Vec<f64>, RolloutError> {
    let run = read_policy_files(run_dir)?;
    let spec = run
        .manifest
        .env
        .known()
        .map_err(|e| RolloutError::NotInBinary(run_dir.display().to_string(), e))?;
    let mut env = spec
        .build()
        .map_err(|e| RolloutError::Env(run_dir.display().to_string(), e))?;
    let dec: Vec<&QNet> = run.dec.iter().collect();
    let missing = |what| {
        RolloutError::NoNet(
            run_dir.display().to_string(),
            what,
            run.manifest.run.method.clone(),
        )
    };
    let policy = match (net.unwrap_or(run.manifest.evaluated), &run.cen) {
        (NetRole::Cen, Some(cen)) => GreedyPolicy::Cen(cen),
        (NetRole::Cen, None) => return Err(missing("centralized")),
        (NetRole::Dec, _) if dec.is_empty() => return Err(missing("decentralized")),
        (NetRole::Dec, _) => GreedyPolicy::Dec(&dec),
    };
    check_sizes(&env, policy)
        .map_err(|m| RolloutError::NetSize(run_dir.display().to_string(), m))?;
    let mut rng = stream(run.manifest.run.seed, Role::EvalEnv);
    let mut scratch = ActScratch::new(&env);
    // Frames go to the file as they are drawn: memory is two frames, whatever the episodes.
    let returns = write_gif_with(out, frame_ms, |gif| {
        (0..episodes.max(1))
            .map(|_| {
                let mut actor = GreedyActor::new(policy);
                play_episode(
                    &mut env,
                    &mut rng,
                    |e, a| actor.choose(e, &mut scratch, a),
                    |frame| gif.push(&frame),
                )
            })
            .collect::<Result<Vec<f64>, RenderError>>()
    })?;
    Ok(returns)
}

/// The nets' input and output sizes against the domain's, so a mismatched file is an error here
/// rather than a panic while acting.
fn check_sizes(env: &impl MacroEnv, policy: GreedyPolicy<'_>) -> Result<(), String> {
    let expect = |what: String, net: &QNet, input: usize, output: usize| {
        let c = net.config();
        if (c.input, c.output) == (input, output) {
            Ok(())
        } else {
            Err(format!(
                "{what} has {} inputs and {} outputs, the domain needs {input} and {output}",
                c.input, c.output
            ))
        }
    };
    match policy {
        GreedyPolicy::Dec(nets) => {
            if nets.len() != env.n_agents() {
                return Err(format!(
                    "{} decentralized nets for {} agents",
                    nets.len(),
                    env.n_agents()
                ));
            }
            for (i, net) in nets.iter().enumerate() {
                expect(
                    format!("agent {i}'s net"),
                    net,
                    env.obs_sizes()[i],
                    env.n_actions()[i],
                )?;
            }
            Ok(())
        }
        GreedyPolicy::Cen(net) => {
            let (input, output) = (env.joint_obs_size(), env.n_joint_actions());
            expect("the centralized net".into(), net, input, output)
        }
    }
}
