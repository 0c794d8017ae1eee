//! `BP-MA-v0`: Box Pushing as MacroMARL configures it (`docs/MACROMARL.md` §3.1).
//!
//! The dynamics are the ICRA paper's ([`super::box_pushing`]; MacroMARL's core file only adds
//! the `penalty` parameter), under [`super::box_pushing::Rules::MACROMARL`]: rewards 300 / 20 /
//! -10 with -0.1 per step, fixed layouts for 6 x 6 (and 4 x 4) grids, the 18-value global state
//! of `get_state()`, and no horizon inside the environment: the runner's `env_terminate_step`
//! cuts the episode, and the cut is a truncation a learner bootstraps from (not terminal, the
//! opposite of the ICRA code's Q7). The environment type is [`super::box_pushing::BoxPushing`];
//! this folder holds what configs, runs and files know of the domain.

mod domain;
mod spec;

pub use domain::{grid_of, BpMaV0Domain};
pub use spec::spec;
