//! Who acts in an episode played in this process (`macdec eval`, `macdec render`): each agent
//! through its own in-process link to its own net, exactly as a robot would (decentralized
//! execution), or one centralized net acting for the whole team: it reads the joint observation
//! whenever an agent is free and picks a joint macro-action that keeps the busy agents' running
//! ones (Cen-DDRQN's centralized Q-net, the one Our-1, Our-1-R and Our-2 train beside their
//! agents' nets, Mac-CAC's centralized actor). Which of the two comes from the policy's
//! description (the role asked for and each net's kind), never from the method's family. A
//! centralized net is not a robot's: robots (`macdec robot`, `deploy`, `domain`) refuse it.
//! [`eval_team`] plays `macdec eval`'s episodes with either, through the driver loop `deploy`
//! runs ([`play_episodes_with`]).

use crate::deploy::drive::driver::{
    play_episodes_with, DeployError, EpisodeTrace, Robots, TeamDecisions,
};
use crate::deploy::drive::link::LocalLink;
use crate::deploy::drive::local_eval::{local_links, sampler, Choice, TEAM_STREAM};
use crate::deploy::policy::net_policy::NetPolicy;
use crate::envs::{EnvRng, MacroEnv};
use crate::nn::sampling::{conditioned_argmax, conditioned_joint, Pick};
use crate::nn::{ActingNet, ActingState};
use crate::policy_files::{Manifest, NetKind, NetRole, PolicyError, VerifiedAgent};
use std::path::Path;

/// Who acts: every agent with its own net, or one centralized net for the team.
pub enum Team {
    /// Each agent's own net (a Q-net or an actor), through the links `macdec eval` has always
    /// used (one per agent, as robots are).
    Agents(Vec<LocalLink<NetPolicy>>),
    /// One centralized net choosing joint macro-actions (boxed: it carries its buffers).
    Central(Box<CentralPolicy>),
}

impl Team {
    /// The nets of role `role` of the policy `manifest` describes in `dir`, choosing by `choice`
    /// (a Q-net refuses [`Choice::Sampled`]); samplers draw from streams of `rng`'s key (agent
    /// i's as [`local_links`], the team's from [`TEAM_STREAM`]). A policy without nets of that
    /// role is refused ([`PolicyError::NoAgentNet`], [`PolicyError::NoCentralNet`]).
    pub fn load(
        manifest: &Manifest,
        dir: &Path,
        role: NetRole,
        choice: Choice,
        rng: &EnvRng,
    ) -> Result<Team, PolicyError> {
        match role {
            NetRole::Dec => {
                let verified = (0..manifest.agents.len())
                    .map(|i| manifest.verify_agent(dir, i))
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Team::Agents(local_links(manifest, &verified, choice, rng)?))
            }
            NetRole::Cen => {
                let index = manifest
                    .cen_net()
                    .ok_or_else(|| PolicyError::NoCentralNet {
                        method: manifest.run.method.clone(),
                    })?;
                let net = manifest.load_acting_net(dir, index)?;
                let n_actions = manifest.agents.iter().map(|a| a.n_actions).collect();
                let central = CentralPolicy::new(net, n_actions, choice, rng)?;
                Ok(Team::Central(Box::new(central)))
            }
        }
    }
}

impl TeamDecisions for Team {
    fn reset(&mut self) -> Result<(), DeployError> {
        match self {
            Team::Agents(links) => Robots(links).reset(),
            Team::Central(c) => {
                c.reset();
                Ok(())
            }
        }
    }

    fn decide<E: MacroEnv + ?Sized>(
        &mut self,
        env: &E,
        actions: &mut [usize],
    ) -> Result<(), DeployError> {
        match self {
            Team::Agents(links) => Robots(links).decide(env, actions),
            Team::Central(c) => c.decide(env, actions),
        }
    }
}

/// A centralized net acting for the whole team, with its recurrent state: greedy (the highest
/// allowed score, [`conditioned_argmax`]) or, for an actor, sampled from its allowed joint
/// probabilities as MacroMARL evaluates Mac-CAC ([`conditioned_joint`]).
pub struct CentralPolicy {
    core: CentralNet,
    /// How [`Self::decide`] picks.
    choice: Choice,
    /// The env's joint observation and free agents, read at each step.
    joint_obs: Vec<f32>,
    free: Vec<bool>,
}

/// The net, its state and how it picks (apart from the buffers a step fills).
struct CentralNet {
    net: ActingNet,
    state: ActingState,
    /// Where a step is computed; it becomes the state only if everything came out finite, so a
    /// refused decision leaves the team as it was (as `NetPolicy` does for one agent).
    candidate: ActingState,
    /// The scores of the last decision.
    scores: Vec<f32>,
    n_actions: Vec<usize>,
    /// The team's sampling stream, kept across episodes; `None` for a Q-net, which never
    /// samples.
    sampler: Option<EnvRng>,
    probs: Vec<f64>,
}

impl CentralPolicy {
    /// `net` over the joint macro-actions of agents with `n_actions` macro-actions each, from a
    /// zero state, picking by `choice` in [`Self::decide`]; an actor samples from stream
    /// [`TEAM_STREAM`] of `rng`'s key. Sampling a Q-net is refused: its scores are not
    /// log-probabilities.
    pub fn new(
        net: ActingNet,
        n_actions: Vec<usize>,
        choice: Choice,
        rng: &EnvRng,
    ) -> Result<Self, PolicyError> {
        let sampler = match net {
            ActingNet::Q(_) => None,
            ActingNet::Actor(_) | ActingNet::Acac(_) => Some(sampler(rng, TEAM_STREAM)),
        };
        if choice == Choice::Sampled && sampler.is_none() {
            return Err(not_an_actor());
        }
        Ok(CentralPolicy {
            choice,
            joint_obs: vec![0.0; net.obs_len()],
            free: vec![true; n_actions.len()],
            core: CentralNet {
                state: net.zero_state(),
                candidate: net.zero_state(),
                scores: Vec::new(),
                probs: Vec::new(),
                net,
                n_actions,
                sampler,
            },
        })
    }

    /// The net acting.
    pub fn net(&self) -> &ActingNet {
        &self.core.net
    }

    /// What the net is, for messages: `centralized Q-net` or `centralized actor`.
    pub fn kind_name(&self) -> &'static str {
        NetKind::of(&self.core.net).centralized_name()
    }

    /// Back to the zero state, as at an episode's start (the sampling stream goes on).
    pub fn reset(&mut self) {
        self.core.state.reset();
    }

    /// The joint decision of one primitive step, picked by `choice`: if any agent is `free`, the
    /// net reads the joint observation `joint_obs` (its state advances) and the free agents'
    /// entries of `actions` are set, the busy agents keeping `running[i]`. Returns the net's
    /// scores over joint macro-actions (`None` when no agent was free). Sampling a Q-net or a
    /// non-finite score is an error naming it. Panics if the lengths do not fit the net.
    pub fn decide_joint(
        &mut self,
        joint_obs: &[f32],
        free: &[bool],
        running: &[usize],
        choice: Choice,
        actions: &mut [usize],
    ) -> Result<Option<&[f32]>, String> {
        self.core
            .decide_joint(joint_obs, free, running, choice, actions)
    }

    /// [`Self::decide_joint`] on `env`'s joint observation, free agents and running
    /// macro-actions.
    pub fn decide<E: MacroEnv + ?Sized>(
        &mut self,
        env: &E,
        actions: &mut [usize],
    ) -> Result<(), DeployError> {
        for (i, f) in self.free.iter_mut().enumerate() {
            *f = env.is_free(i);
        }
        env.write_joint_obs(&mut self.joint_obs);
        let running = env.executed();
        self.core
            .decide_joint(&self.joint_obs, &self.free, running, self.choice, actions)
            .map(|_| ())
            .map_err(DeployError::Policy)
    }
}

impl CentralNet {
    fn decide_joint(
        &mut self,
        joint_obs: &[f32],
        free: &[bool],
        running: &[usize],
        choice: Choice,
        actions: &mut [usize],
    ) -> Result<Option<&[f32]>, String> {
        if !free.iter().any(|&f| f) {
            return Ok(None);
        }
        let sampler = match (choice, self.sampler.as_mut()) {
            (Choice::Greedy, _) => None,
            (Choice::Sampled, Some(s)) => Some(s),
            (Choice::Sampled, None) => return Err(not_an_actor().to_string()),
        };
        // No centralized net reads the step: policy files hold ACAC's actors only as agents'.
        self.candidate.copy_from(&self.state);
        let candidate_scores = self.net.act_step(joint_obs, 0, &mut self.candidate);
        self.scores.clear();
        self.scores.extend_from_slice(candidate_scores);
        let bad = self.scores.iter().find(|x| !x.is_finite()).copied();
        if bad.is_some() || !self.candidate.is_finite() {
            let what = match bad {
                Some(v) => format!("a non-finite score ({v})"),
                None => "a non-finite hidden state".into(),
            };
            return Err(format!(
                "the {} answered {what}; the observation is out of the range it was trained on (its state is unchanged)",
                NetKind::of(&self.net).centralized_name()
            ));
        }
        std::mem::swap(&mut self.state, &mut self.candidate);
        let scores = &self.scores[..];
        match sampler {
            Some(s) => conditioned_joint(
                scores,
                None,
                free,
                running,
                &self.n_actions,
                Pick::Sample(s),
                &mut self.probs,
                actions,
            ),
            None => conditioned_argmax(scores, free, running, &self.n_actions, actions),
        }
        Ok(Some(scores))
    }
}

/// Run `episodes` episodes of the manifest's domain on one random stream (`rng`, the caller's
/// choice of seed; deploy uses the evaluation stream of the run's seed), each agent choosing by
/// `choice` with its own verified net, handing each episode to `on_episode` as it ends.
pub fn eval_policy(
    manifest: &Manifest,
    verified: &[VerifiedAgent],
    episodes: usize,
    choice: Choice,
    rng: &mut EnvRng,
    on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    let links = local_links(manifest, verified, choice, rng)
        .map_err(|e| DeployError::Policy(e.to_string()))?;
    eval_team(
        manifest,
        &mut Team::Agents(links),
        episodes,
        rng,
        on_episode,
    )
}

/// [`eval_policy`] with any [`Team`]: the agents' own nets, or one centralized net.
pub fn eval_team(
    manifest: &Manifest,
    team: &mut Team,
    episodes: usize,
    rng: &mut EnvRng,
    on_episode: impl FnMut(EpisodeTrace) -> Result<(), DeployError>,
) -> Result<(), DeployError> {
    let mut env = manifest
        .env
        .build()
        .map_err(|e| DeployError::Policy(e.to_string()))?;
    if let Team::Agents(links) = team {
        if links.len() != manifest.agents.len() {
            return Err(DeployError::RobotCount {
                expected: manifest.agents.len(),
                got: links.len(),
            });
        }
    }
    play_episodes_with(&mut env, team, manifest.discount, episodes, rng, on_episode)
}

/// Why a centralized Q-net does not sample.
fn not_an_actor() -> PolicyError {
    PolicyError::NotAnActor {
        whose: "the centralized net".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::EnvSpec;
    use crate::nn::Params;
    use crate::nn::{QNet, QNetConfig};
    use crate::policy_files::load_all;
    use rand::{Rng, SeedableRng};

    fn bp8() -> EnvSpec {
        crate::envs::box_pushing::spec(8, 30)
    }

    /// A centralized Q-net with large weights, so its greedy joint action changes over an
    /// episode.
    fn cen_qnet(env: &impl MacroEnv) -> QNet {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let cfg = QNetConfig {
            input: env.joint_obs_size(),
            mlp: 16,
            hidden: 8,
            output: env.n_joint_actions(),
        };
        let mut net = QNet::new(cfg, &mut rng);
        for w in net.params.slices_mut() {
            w.iter_mut().for_each(|v| *v *= 4.0);
        }
        net
    }

    #[test]
    fn the_greedy_joint_choice_keeps_busy_agents_whatever_the_score_range() {
        // Q-values far beyond exp's range: the choice reads the scores, not probabilities.
        let n_actions = [2, 3];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        for _ in 0..200 {
            let scores: Vec<f32> = (0..6).map(|_| rng.gen_range(-2000.0..2000.0)).collect();
            let busy = rng.gen_range(0..2);
            let running = [rng.gen_range(0..2), rng.gen_range(0..3)];
            let free = [busy != 0, busy != 1];
            let mut actions = [9, 9];
            conditioned_argmax(&scores, &free, &running, &n_actions, &mut actions);
            assert_eq!(actions[busy], running[busy]);
            let best = (0..6)
                .filter(|&j| [j / 3, j % 3][busy] == running[busy])
                .max_by(|&a, &b| scores[a].total_cmp(&scores[b]))
                .unwrap();
            assert_eq!(actions, [best / 3, best % 3], "{scores:?}");
        }
        // A NaN never wins; ties go to the first.
        let mut actions = [9, 9];
        let scores = [f32::NAN, 1.0, 5.0, 5.0, f32::NAN, 0.0];
        conditioned_argmax(&scores, &[true, true], &[0, 0], &n_actions, &mut actions);
        assert_eq!(actions, [0, 2]);
    }

    #[test]
    fn a_central_q_net_refuses_to_sample_and_names_the_centralized_net() {
        let env = bp8().build().unwrap();
        let err = CentralPolicy::new(
            ActingNet::Q(cen_qnet(&env)),
            env.n_actions().to_vec(),
            Choice::Sampled,
            &EnvRng::seed_from_u64(0),
        )
        .err()
        .expect("a Q-net cannot sample")
        .to_string();
        assert!(
            err.contains("the centralized net is a Q-net") && err.contains("--sample"),
            "{err}"
        );
    }

    #[test]
    fn a_callback_error_stops_the_run() {
        let spec = crate::envs::box_pushing::spec(10, 100);
        let dir = tempfile::tempdir().unwrap();
        crate::deploy::policy::mock::write_mock_policy(dir.path(), spec).unwrap();
        let (manifest, verified) = load_all(dir.path()).unwrap();
        let mut calls = 0;
        let err = eval_policy(
            &manifest,
            &verified,
            5,
            Choice::Greedy,
            &mut EnvRng::seed_from_u64(0),
            |_| {
                calls += 1;
                Err(DeployError::Policy("stdout closed".into()))
            },
        )
        .unwrap_err();
        assert_eq!(calls, 1);
        assert!(err.to_string().contains("stdout closed"), "{err}");
    }
}
