//! ACAC's copy of Overcooked-MA-v1 (GitHub `LGAI-Research/acac`, `acac/env/overcooked_env/`), beside
//! gym-macro-overcooked's that MacroMARL trains on (`../overcooked/`). It runs the same engine with
//! ACAC's differences as parameters (`../shared/spec/acac_envs.md` §Overcooked-MA-v1, `docs/ACAC.md`):
//!
//! - agents, plates and knives are numbered column by column ([`Numbering::ColumnMajor`]), which
//!   also decides who wins a contended cell;
//! - `rand_start` draws a new start map at every reset ([`crate::envs::overcooked::rand_start`]);
//! - a global state, `get_vector_state()` (25 values for 3 agents);
//! - ACAC's runner passes `n_agent` (3), so the published settings train 3 agents.
//!
//! [`Numbering::ColumnMajor`]: crate::envs::overcooked::world::Numbering::ColumnMajor

pub mod domain;

pub use domain::OvercookedAcacDomain;
