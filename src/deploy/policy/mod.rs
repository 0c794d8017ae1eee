//! Policies for robots: writing a policy directory (the one format of [`crate::policy_files`])
//! from a run ([`export`]) or from the reference's PyTorch files ([`import`]), the Q-net that acts
//! from it ([`qnet_policy`]) and a mock policy for tests ([`mock`]). [`manifest`],
//! [`architecture`] and [`policy_env`] re-export the format's parts under their older paths.

pub mod export;
pub mod import;
pub mod manifest;
pub mod mock;
pub mod qnet_policy;

pub use crate::policy_files::{architecture, policy_env};
