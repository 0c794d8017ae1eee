//! ACAC's Overcooked-MA-v0, "Overcooked-Large" (GitHub `LGAI-Research/acac`,
//! `acac/env/overcooked_env/overcooked_MA_V0.py` on `overcooked_V0.py`; no counterpart elsewhere):
//! an 11 x 11 kitchen, 6 agents, six objects "A".."F", 4 plates and 4 knives, maps A, B, C. It runs
//! the Overcooked engine (`../overcooked/`) under ACAC's V0 rules
//! ([`crate::envs::overcooked::layout::Rules::V0`]); what differs from Overcooked-MA-v1 is listed in
//! `../shared/spec/acac_envs.md` §Overcooked-MA-v0 and `docs/ACAC.md`, and sits where it happens:
//!
//! - the start map (`make_custom_map`: [`crate::envs::overcooked::layout::large_start_map`]), its
//!   codes (plate 3, knife 4, delivery 5, objects 6..) and row-major numbering;
//! - foods start "chopped" (`GeneralFood` passes its name as `chopped`) until a wrong delivery
//!   refreshes them ([`crate::envs::overcooked::world::World::restart_from`]); `_findItem` of an
//!   object finds the first food of any kind on the cell
//!   ([`crate::envs::overcooked::world::World::food_at`]);
//! - the dish is every object on one plate; every chop through earns "subtask finished";
//! - a closed cycle of agents moves at once (`four_chain_case`, `step.rs`);
//! - the macro-action "delivery" is not V1's "deliver", so V1's two special cases never fire;
//! - observations have 48 values and no task one-hot; there is no global state.

pub mod domain;

pub use domain::OvercookedLargeDomain;
