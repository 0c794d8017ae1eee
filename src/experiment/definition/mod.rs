//! What to run: experiment files and `--set` overrides resolved into runs ([`config`]; the
//! papers' settings come from each method's family), a run's domain beside its hyperparameters ([`run_settings`]),
//! seed lists and per-role random streams ([`seeds`]), size bounds ([`limits`]) and safe names
//! ([`names`]).

pub mod config;
pub mod limits;
pub mod names;
pub mod run_settings;
pub mod seeds;
