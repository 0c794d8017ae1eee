//! Running trained decentralized policies on robots (issue 7), in three folders by job:
//! [`policy`] (the policy directory, of the one format in [`crate::policy_files`]: writing it
//! from a run ([`policy::export`]) or from the reference code's PyTorch state_dicts
//! ([`policy::import`], [`policy::import_actors`]), the net acting from it), [`serve`] (the robot
//! side: the JSON-lines protocol ([`serve::protocol`]) and the robot stub that serves one agent's
//! policy over stdin/stdout or TCP ([`serve::robot`], [`serve::server`])) and [`drive`] (the
//! domain side: one process runs the domain and talks to one robot per agent, each seeing only
//! its own macro-observations ([`drive::driver`], [`drive::link`], [`drive::processes`])).
//!
//! The robot side knows no learner: a policy is anything implementing [`AgentPolicy`] (the real
//! net, [`policy::net_policy::NetPolicy`] over a Q-net or an actor, or
//! [`policy::mock::MockPolicy`] in tests and behind the CLI's hidden `--mock` flag).
//! [`drive::remote`] drives robots that already run elsewhere (`macdec domain`, the ROS bridge of
//! issue 14). Only [`policy::export`] reads a run directory, and only its policy files
//! ([`crate::policy_files`]), never its checkpoint; deploy imports nothing of the learner
//! (`src/algos`). [`drive::local_eval`] runs any policy directory's greedy episodes in-process,
//! exactly as deployment does. A policy may be of a domain defined outside this binary
//! ([`crate::policy_files::PolicyEnv`]): robots serve it, the commands that simulate a domain
//! refuse it by name.
//!
//! Each module has one path, through its folder. Two items keep a short path too, because the
//! README and the custom-domain error message name them so: a program with its own domain
//! drives robots with [`JsonLink::connect`] and [`run_episodes`].

pub mod drive;
pub mod policy;
pub mod serve;

pub use drive::driver::run_episodes;
pub use drive::link::JsonLink;

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
    /// Whether the policy reads when an observation was made (ACAC's actors, whose time
    /// embedding is part of their input). A caller that does not know the step must refuse
    /// such a policy rather than call [`Self::q_values`] with a made-up one.
    fn reads_step(&self) -> bool {
        false
    }
    /// Q-values of every macro-action for `obs` (length [`Self::obs_len`]), an observation made
    /// after `step` primitive steps of the episode, written into `q` (length
    /// [`Self::n_actions`]); advances the hidden state by one macro-step, but only when every
    /// Q-value (and the new state) is finite: a non-finite answer is refused by the robot, and
    /// the refused step must leave the hidden state exactly as it was. Callers check both
    /// lengths first; an implementation may panic on wrong lengths.
    fn q_values(&mut self, obs: &[f32], step: usize, q: &mut [f32]);
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
    fn reads_step(&self) -> bool {
        (**self).reads_step()
    }
    fn q_values(&mut self, obs: &[f32], step: usize, q: &mut [f32]) {
        (**self).q_values(obs, step, q)
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
