//! macdec: macro-action multi-agent deep reinforcement learning.
//!
//! A pure-Rust reproduction of *Learning Multi-Robot Decentralized Macro-Action-Based Policies via
//! a Centralized Q-Net* (Xiao, Hoffman, Xia, Amato, ICRA 2020). Data flows one way:
//! `experiment` (config, runner) -> `algos` (trainer) -> `envs` + `nn` (on `autograd`), and the
//! results feed `plot` and `deploy`. Lower layers never name higher ones.
//!
//! Your own domain: implement [`MacroEnv`] and call [`train`], or [`train_policy`] and
//! [`TrainedPolicy::export`] to put the trained policy on robots (see `examples/custom_domain.rs`).

pub mod algos;
pub mod api;
pub mod autograd;
pub mod bench;
pub mod cli;
pub mod curve_stats;
pub mod deploy;
pub mod draw;
pub mod envs;
pub mod experiment;
pub mod files;
pub mod nn;
pub mod plot;
pub mod policy_files;
pub mod render;

pub use algos::any_loop::AnyLoop;
pub use algos::hyper::RunConfig;
pub use algos::method::Method;
pub use algos::training_loop::EvalPoint;
pub use api::{train, train_policy, LibraryTrainError, TrainedPolicy};
pub use deploy::PolicyEnv;
pub use envs::{EnvError, EnvRng, EnvSpec, FirstRecordObs, MacroEnv, StepOutcome};
pub use experiment::paper::{actor_critic_defaults, paper_defaults, value_paper_defaults};
