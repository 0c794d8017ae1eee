//! Running trained decentralized policies on robots (issue 7): the exported policy directory
//! ([`manifest`], [`architecture`]), the JSON-lines robot protocol ([`protocol`]), the robot stub
//! that serves one agent's policy over stdin/stdout or TCP ([`robot`], [`server`]), and
//! decentralized deployment: one process runs the domain and talks to one robot per agent, each
//! seeing only its own macro-observations ([`driver`], [`link`], [`processes`]).
//!
//! The robot side knows no learner: a policy is anything implementing [`AgentPolicy`] (the real
//! net, [`net_policy::NetPolicy`] over a Q-net or an actor, or [`mock::MockPolicy`] in tests and behind the
//! CLI's hidden `--mock` flag). [`remote`] drives robots that already run elsewhere (`macdec
//! domain`, the ROS bridge of issue 14). Only [`export`] reads a run directory, and only its
//! policy files ([`crate::policy_files`]), never its checkpoint; deploy imports nothing
//! of the learner (`src/algos`). [`import`] builds the same policy directory from the reference code's PyTorch state_dicts, and [`local_eval`] runs
//! any policy directory's greedy episodes in-process, exactly as deployment does. A policy may be
//! of a domain defined outside this binary ([`policy_env`]): robots serve it, the commands that
//! simulate a domain refuse it by name.
//!
//! Three folders by job: [`policy`] (the policy directory: format, export, import, the Q-net
//! acting from it), [`serve`] (the robot side: protocol, stdio and TCP servers) and [`drive`]
//! (the domain side: episodes against robot links, processes, remote robots, local evaluation).
//! Their modules are re-exported here, so `macdec::deploy::<module>` paths stay.

pub mod drive;
pub mod policy;
pub mod serve;

pub use drive::{driver, link, local_eval, processes, remote};
pub use policy::{
    architecture, export, import, import_actors, manifest, mock, net_policy, policy_env,
};
pub use serve::{deadline, line_reader, protocol, robot, server};

pub use driver::{run_episode, run_episodes, run_episodes_with, EpisodeTrace, StepRecord};
pub use link::{JsonLink, LinkError, LocalLink, RobotLink};
pub use manifest::{Manifest, VerifiedAgent};
pub use policy_env::{CustomEnv, NotInBinary, PolicyEnv};
pub use robot::{serve_stdio, serve_stream, RobotSpec, Session};
pub use server::{serve_tcp, spawn_server, Limits, RobotServer};

/// One agent's decentralized policy with its recurrent state, as a robot runs it: the agent's own
/// macro-observation in, one Q-value per macro-action out (`docs/ALGORITHMS.md` §4.2, greedy).
///
/// The hidden state lives inside the value, so a robot keeps it across messages and each TCP
/// connection gets its own (a fresh value from a factory).
pub trait AgentPolicy: Send {
    /// Length of the observation the policy reads.
    fn obs_len(&self) -> usize;
    /// Number of macro-actions (length of the Q-vector).
    fn n_actions(&self) -> usize;
    /// Zero the hidden state, as at the start of an episode.
    fn reset(&mut self);
    /// Q-values of every macro-action for `obs` (length [`Self::obs_len`]) written into `q`
    /// (length [`Self::n_actions`]); advances the hidden state by one macro-step, but only when
    /// every Q-value (and the new state) is finite: a non-finite answer is refused by the robot,
    /// and the refused step must leave the hidden state exactly as it was. Callers check both
    /// lengths first; an implementation may panic on wrong lengths.
    fn q_values(&mut self, obs: &[f32], q: &mut [f32]);
}

impl<P: AgentPolicy + ?Sized> AgentPolicy for Box<P> {
    fn obs_len(&self) -> usize {
        (**self).obs_len()
    }
    fn n_actions(&self) -> usize {
        (**self).n_actions()
    }
    fn reset(&mut self) {
        (**self).reset()
    }
    fn q_values(&mut self, obs: &[f32], q: &mut [f32]) {
        (**self).q_values(obs, q)
    }
}

/// Index of the first maximal Q-value: the greedy macro-action, with ties going to the lowest
/// index exactly as in training and evaluation (quirk Q14). Callers reject non-finite Q first.
pub fn greedy_action(q: &[f32]) -> usize {
    crate::nn::argmax(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn greedy_action_takes_the_first_of_equal_maxima() {
        assert_eq!(greedy_action(&[1.0, 3.0, 3.0, -1.0]), 1);
        assert_eq!(greedy_action(&[-2.0, -3.0]), 0);
        assert_eq!(greedy_action(&[0.0, 0.5, 0.25, 0.5001]), 3);
    }
}
