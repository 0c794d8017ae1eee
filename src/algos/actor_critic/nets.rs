//! The nets of an actor-critic method (`docs/MACROMARL.md` §2.4, 2.7): its actors, its critics
//! and their targets, each with its own Adam (`a_lr` for actors, `c_lr` for critics).

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::config::AcConfig;
use crate::algos::actor_critic::method::{AcActor, AcCritic, AcDesign};
use crate::nn::{Adam, AdamConfig, GruActor, GruActorConfig, Params, StateCritic};

/// A critic's net: on observation histories (the actor's layers, one output) or on the state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum CriticNet {
    /// On an agent's (or the joint) observation history: the actor's layers with one output.
    History(GruActor),
    /// On the global state (Naive Mac-IASC's and Mac-IAISC's critics).
    State(StateCritic),
}

impl CriticNet {
    /// Overwrite with `other` (same kind and sizes).
    pub fn copy_from(&mut self, other: &CriticNet) {
        match (self, other) {
            (CriticNet::History(a), CriticNet::History(b)) => a.copy_values_from(b),
            (CriticNet::State(a), CriticNet::State(b)) => a.copy_values_from(b),
            _ => unreachable!("a critic's target is the same kind of net"),
        }
    }

    /// Whether every parameter is finite.
    pub fn is_finite(&self) -> bool {
        match self {
            CriticNet::History(n) => n.all_finite(),
            CriticNet::State(n) => n.all_finite(),
        }
    }

    fn adam(&self, lr: f64) -> Adam {
        let c = AdamConfig::with_lr(lr);
        match self {
            CriticNet::History(n) => Adam::new(c, n),
            CriticNet::State(n) => Adam::new(c, n),
        }
    }
}

/// An actor and its optimizer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Actor {
    /// The actor's parameters.
    pub net: GruActor,
    /// Its optimizer state (learning rate `a_lr`).
    pub adam: Adam,
}

/// A critic, its target (hard-copied every `c_target_update_freq` episodes) and its optimizer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Critic {
    /// The critic being trained.
    pub net: CriticNet,
    /// The target that computes bootstrap values, hard-copied from `net`.
    pub target: CriticNet,
    /// The optimizer state of `net` (learning rate `c_lr`).
    pub adam: Adam,
}

/// Every net of one actor-critic run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcNets {
    /// One per agent (decentralized actors), or the one centralized actor over joint actions.
    pub actors: Vec<Actor>,
    /// One per agent (Mac-IAC, Mac-IAICC, Mac-IAISC) or one shared.
    pub critics: Vec<Critic>,
}

/// Joint macro-actions Mac-CAC's actor may output (3-agent Overcooked: 14^3 = 2744).
pub const MAX_JOINT_ACTIONS: usize = 1 << 16;

/// The sizes a method's nets are built for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NetSizes {
    /// Each agent's observation length.
    pub obs_sizes: Vec<usize>,
    /// Each agent's number of macro-actions.
    pub n_actions: Vec<usize>,
    /// Length of the global state (0 for a domain without one).
    pub state_size: usize,
}

impl NetSizes {
    /// The joint observation's length.
    pub fn joint_obs(&self) -> usize {
        self.obs_sizes.iter().sum()
    }

    /// The number of joint macro-actions.
    pub fn joint_actions(&self) -> usize {
        self.n_actions.iter().product()
    }
}

/// Why a method's nets cannot be built for a domain.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NetsError {
    /// A state critic was asked of a domain without a global state.
    #[error("{method}'s critic needs the global state, and this domain has none (get_state()); use the history-critic variant")]
    NoState {
        /// The method's name.
        method: &'static str,
    },
    /// The state critic's two MLP widths differ, which the reference cannot run.
    #[error("{method}'s state critic feeds fc2's {m0} outputs into fc3, which takes c_mlp_layer_size[1] = {m1}: the widths must be equal (the reference cannot run otherwise)")]
    StateCriticWidths {
        /// The method's name.
        method: &'static str,
        /// `c_mlp_layer_size[0]`, fc2's outputs.
        m0: usize,
        /// `c_mlp_layer_size[1]`, fc3's inputs.
        m1: usize,
    },
    /// Mac-CAC's joint actor would be too wide.
    #[error("Mac-CAC's joint actor would have {count} outputs (the product of the agents' macro-actions), beyond {max}")]
    TooManyJointActions {
        /// Joint macro-actions (product of the agents' counts).
        count: u128,
        /// [`MAX_JOINT_ACTIONS`].
        max: usize,
    },
}

impl AcNets {
    /// Fresh nets for `design` (targets start as copies, `docs/MACROMARL.md` §2.4), drawn from `rng` in the
    /// order actors, then critics.
    pub fn new(
        design: AcDesign,
        c: &AcConfig,
        sizes: &NetSizes,
        rng: &mut ChaCha8Rng,
    ) -> Result<Self, NetsError> {
        let n = sizes.obs_sizes.len();
        let method = design.reference_alg;
        let actor = |input: usize, output: usize, rng: &mut ChaCha8Rng| {
            let net = GruActor::new(
                GruActorConfig {
                    input,
                    mlp: [c.a_mlp_layer_size[0], c.a_mlp_layer_size[1]],
                    hidden: c.a_rnn_layer_size,
                    output,
                },
                rng,
            );
            let adam = Adam::new(AdamConfig::with_lr(c.a_lr), &net);
            Actor { net, adam }
        };
        let actors = match design.actor {
            AcActor::Decentralized => (0..n)
                .map(|i| actor(sizes.obs_sizes[i], sizes.n_actions[i], rng))
                .collect(),
            AcActor::Centralized => {
                let count: u128 = sizes.n_actions.iter().map(|&a| a as u128).product();
                if count > MAX_JOINT_ACTIONS as u128 {
                    return Err(NetsError::TooManyJointActions {
                        count,
                        max: MAX_JOINT_ACTIONS,
                    });
                }
                vec![actor(sizes.joint_obs(), sizes.joint_actions(), rng)]
            }
        };
        let history = |input: usize, rng: &mut ChaCha8Rng| {
            CriticNet::History(GruActor::new(
                GruActorConfig {
                    input,
                    mlp: [c.c_mlp_layer_size[0], c.c_mlp_layer_size[1]],
                    hidden: c.c_rnn_layer_size,
                    output: 1,
                },
                rng,
            ))
        };
        let state = |rng: &mut ChaCha8Rng| -> Result<CriticNet, NetsError> {
            if sizes.state_size == 0 {
                return Err(NetsError::NoState { method });
            }
            let [m0, m1] = [c.c_mlp_layer_size[0], c.c_mlp_layer_size[1]];
            if m0 != m1 {
                return Err(NetsError::StateCriticWidths { method, m0, m1 });
            }
            Ok(CriticNet::State(StateCritic::new(
                sizes.state_size,
                m0,
                c.c_mid_layer_size,
                rng,
            )))
        };
        let nets: Vec<CriticNet> = match design.critic {
            AcCritic::OwnHistory => (0..n).map(|i| history(sizes.obs_sizes[i], rng)).collect(),
            AcCritic::JointHistory => vec![history(sizes.joint_obs(), rng)],
            AcCritic::JointState => vec![state(rng)?],
            AcCritic::AgentJointHistory => {
                (0..n).map(|_| history(sizes.joint_obs(), rng)).collect()
            }
            AcCritic::AgentState => (0..n).map(|_| state(rng)).collect::<Result<_, _>>()?,
        };
        let critics = nets
            .into_iter()
            .map(|net| Critic {
                adam: net.adam(c.c_lr),
                target: net.clone(),
                net,
            })
            .collect();
        Ok(AcNets { actors, critics })
    }

    /// Hard-copy every critic into its target (the unused actor targets are not kept).
    pub fn sync_targets(&mut self) {
        for c in &mut self.critics {
            c.target.copy_from(&c.net);
        }
    }

    /// Whether every parameter is finite.
    pub fn is_finite(&self) -> bool {
        self.actors.iter().all(|a| a.net.all_finite())
            && self
                .critics
                .iter()
                .all(|c| c.net.is_finite() && c.target.is_finite())
    }
}

/// The number of parameters of a net (for progress and tests).
pub fn n_params(p: &impl Params) -> usize {
    p.slices().iter().map(|s| s.len()).sum()
}
