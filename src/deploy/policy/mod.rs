//! The exported policy directory: its manifest and checks ([`manifest`]), the nets' architecture
//! ([`architecture`]), writing it from a run ([`export`]) or from the reference's PyTorch files
//! ([`import`]), the domain it names ([`policy_env`]), the Q-net that acts from it
//! ([`qnet_policy`]) and a mock policy for tests ([`mock`]).

pub mod architecture;
pub mod export;
pub mod import;
pub mod manifest;
pub mod mock;
pub mod policy_env;
pub mod qnet_policy;
