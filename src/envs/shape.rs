//! The sizes a learner's nets and batches are made from: what a method's config checks need to
//! bound every allocation with all its factors before a run starts.

use super::{EnvError, EnvSpec, MacroEnv};

/// An environment's sizes as the nets see them: episode length, per-agent observation and
/// macro-action counts, and the global state's length (0 without one).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EnvShape {
    /// The horizon in primitive steps (`env_terminate_step`).
    pub horizon: usize,
    /// Each agent's observation length.
    pub obs_sizes: Vec<usize>,
    /// Each agent's macro-action count.
    pub n_actions: Vec<usize>,
    /// The global state's length (0 for a domain without one).
    pub state_size: usize,
}

impl EnvShape {
    /// The shape of `spec`'s environment (built once, in its reset state).
    pub fn of(spec: &EnvSpec) -> Result<EnvShape, EnvError> {
        Ok(EnvShape::of_env(&spec.build()?))
    }

    /// The shape of an environment instance.
    pub fn of_env(env: &impl MacroEnv) -> EnvShape {
        EnvShape {
            horizon: env.horizon(),
            obs_sizes: env.obs_sizes().to_vec(),
            n_actions: env.n_actions().to_vec(),
            state_size: env.state_size(),
        }
    }

    /// The joint observation's length, a centralized net's input.
    pub fn joint_obs_size(&self) -> u128 {
        self.obs_sizes.iter().map(|&s| s as u128).sum()
    }

    /// The widest agent observation, a decentralized net's input.
    pub fn widest_obs(&self) -> u128 {
        self.obs_sizes.iter().copied().max().unwrap_or(0) as u128
    }

    /// The joint macro-action count (the product of the agents' counts, saturating), a
    /// centralized actor's or Q-net's output width.
    pub fn n_joint_actions(&self) -> u128 {
        self.n_actions
            .iter()
            .fold(1u128, |p, &n| p.saturating_mul(n as u128))
    }

    /// The most macro-actions of any agent, a decentralized net's output width.
    pub fn widest_actions(&self) -> u128 {
        self.n_actions.iter().copied().max().unwrap_or(0) as u128
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_pushing_shape_has_its_joint_sizes() {
        let shape = EnvShape::of(&crate::envs::box_pushing::spec(10, 100)).unwrap();
        assert_eq!(shape.horizon, 100);
        assert_eq!(shape.n_joint_actions(), 64);
        assert_eq!(shape.widest_actions(), 8);
        assert_eq!(
            shape.joint_obs_size(),
            shape.obs_sizes.iter().sum::<usize>() as u128
        );
    }

    #[test]
    fn the_joint_action_count_saturates_instead_of_overflowing() {
        let shape = EnvShape {
            horizon: 1,
            obs_sizes: vec![1; 40],
            n_actions: vec![1 << 20; 40],
            state_size: 0,
        };
        assert_eq!(shape.n_joint_actions(), u128::MAX);
    }
}
