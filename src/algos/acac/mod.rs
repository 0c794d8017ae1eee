//! ACAC (Jung, Hong, Yoon, Lee, Lim, *Agent-Centric Actor-Critic for Asynchronous Multi-Agent
//! Reinforcement Learning*, ICML 2025; GitHub `LGAI-Research/acac`): `acac`, `acac-vanilla` and
//! `acac-micro-gae`, ACAC's three `--alg_name`s.
//!
//! A family of its own: per-agent GRU actors over each agent's own macro-observations, a critic
//! that encodes each agent's history with its own GRU and attends over the agents with a GPT-2
//! block, macro-level GAE and PPO, on ACAC's settings layered from its own parameter files
//! ([`config`]). The nets are in `crate::nn` (`gpt2*`, `layer_norm`, `popart`,
//! `time_embedding`, `value_head`, `acac_joint_value`).
//!
//! The learner ([`learner`]) drives one update per batch ([`train_step`]): [`update`] for `acac`
//! and `acac-micro-gae` (PPO), [`vanilla`] for `acac-vanilla`; each is replayed against ACAC's own
//! `train()` by `tests/golden_acac.rs`.

pub mod batch;
pub mod config;
pub mod error;
pub mod family;
pub mod gae;
pub mod learner;
pub mod method;
pub mod nets;
pub mod nstep;
pub mod train_step;
pub mod update;
pub mod vanilla;
