//! Animated rollouts of a trained run's policy (`macdec render`): reads the run's policy files,
//! whatever the method's family (Q-nets or actors, one per agent or one for the team), and draws
//! its episodes. Per-agent nets act exactly as `macdec eval` runs them (the same in-process
//! links, greedy or sampled); a centralized Q-net acts with the conditional argmax, Mac-CAC's
//! centralized actor as one team policy choosing joint macro-actions.

use crate::algos::value::acting::ActScratch;
use crate::algos::value::evaluate::{GreedyActor, GreedyPolicy};
use crate::deploy::drive::link::{LocalLink, RobotLink};
use crate::deploy::drive::local_eval::{local_links, sampler, Choice, TEAM_STREAM};
use crate::deploy::policy::net_policy::NetPolicy;
use crate::envs::{EnvRng, MacroEnv};
use crate::experiment::definition::seeds::{stream, Role};
use crate::nn::sampling::{conditioned_joint, Pick};
use crate::nn::{ActingNet, GruActor, QNet};
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

/// Who acts in a rendered episode.
enum Team<'a> {
    /// Each agent's own net (a Q-net or an actor), through the links `macdec eval` uses.
    Agents(Vec<LocalLink<NetPolicy>>),
    /// A centralized Q-net with the conditional argmax.
    CenQ(&'a QNet, ActScratch),
    /// Mac-CAC's centralized actor: joint macro-actions for the whole team.
    CenActor(&'a GruActor, Option<Box<EnvRng>>),
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
    let mut rng = stream(manifest.run.seed, Role::EvalEnv);
    let cen_net;
    let mut team = match net.unwrap_or(manifest.evaluated) {
        NetRole::Dec => {
            let verified = (0..manifest.agents.len())
                .map(|i| manifest.verify_agent(&dir, i))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| match e {
                    PolicyError::NoAgentNet { .. } => missing("decentralized"),
                    e => e.into(),
                })?;
            Team::Agents(local_links(&manifest, &verified, choice, &rng)?)
        }
        NetRole::Cen => {
            let index = manifest.cen_net().ok_or_else(|| missing("centralized"))?;
            cen_net = manifest.load_acting_net(&dir, index)?;
            let (input, output) = (env.joint_obs_size(), env.n_joint_actions());
            if (cen_net.obs_len(), cen_net.n_actions()) != (input, output) {
                return Err(RolloutError::NetSize(
                    at(),
                    format!(
                        "the centralized net has {} inputs and {} outputs, the domain needs {input} and {output}",
                        cen_net.obs_len(),
                        cen_net.n_actions()
                    ),
                ));
            }
            match &cen_net {
                ActingNet::Q(_) if choice == Choice::Sampled => {
                    return Err(PolicyError::NotAnActor { agent: 0 }.into())
                }
                ActingNet::Q(q) => Team::CenQ(q, ActScratch::new(&env)),
                ActingNet::Actor(a) => Team::CenActor(
                    a,
                    (choice == Choice::Sampled).then(|| Box::new(sampler(&rng, TEAM_STREAM))),
                ),
            }
        }
    };
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
    team: &mut Team<'_>,
    rng: &mut EnvRng,
    each: impl FnMut(crate::render::Frame) -> Result<(), RenderError>,
) -> Result<f64, RenderError> {
    match team {
        Team::Agents(links) => {
            for link in links.iter_mut() {
                link.reset().map_err(|e| RenderError::Policy {
                    t: 0,
                    message: e.to_string(),
                })?;
            }
            let choose = |e: &E, actions: &mut [usize]| {
                for (agent, link) in links.iter_mut().enumerate() {
                    let chosen = link
                        .observe(e.obs(agent), e.is_free(agent))
                        .map_err(|err| format!("agent {agent}: {err}"))?;
                    if let Some(a) = chosen {
                        actions[agent] = a;
                    }
                }
                Ok(())
            };
            play_episode(env, rng, choose, each)
        }
        Team::CenQ(net, scratch) => {
            let mut actor = GreedyActor::new(GreedyPolicy::Cen(net));
            let choose = |e: &E, actions: &mut [usize]| {
                actor.choose(e, scratch, actions);
                Ok(())
            };
            play_episode(env, rng, choose, each)
        }
        Team::CenActor(actor, sampler) => {
            let mut state = actor.zero_state();
            let (mut joint, mut probs) = (Vec::new(), Vec::new());
            let choose = |e: &E, actions: &mut [usize]| {
                let free: Vec<bool> = (0..e.n_agents()).map(|i| e.is_free(i)).collect();
                if !free.iter().any(|&f| f) {
                    return Ok(());
                }
                joint.resize(e.joint_obs_size(), 0.0);
                e.write_joint_obs(&mut joint);
                let logp = actor.act_step(&joint, &mut state);
                if let Some(bad) = logp.iter().find(|x| !x.is_finite()) {
                    return Err(format!("the centralized actor answered {bad}"));
                }
                let pick = match sampler.as_mut() {
                    Some(s) => Pick::Sample(s),
                    None => Pick::MostProbable,
                };
                let running = e.executed().to_vec();
                conditioned_joint(
                    logp,
                    None,
                    &free,
                    &running,
                    e.n_actions(),
                    pick,
                    &mut probs,
                    actions,
                );
                Ok(())
            };
            play_episode(env, rng, choose, each)
        }
    }
}
