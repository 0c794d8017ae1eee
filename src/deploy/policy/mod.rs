//! Policies for robots: writing a policy directory (the one format of [`crate::policy_files`])
//! from a run ([`export`]) or from the references' PyTorch files ([`import`] for the ICRA
//! Q-nets, [`import_actors`] for MacroMARL's actors, [`import_acac`] for ACAC's), the net that acts
//! from it ([`net_policy`]) and a mock policy for tests ([`mock`]).

pub mod export;
pub mod import;
pub mod import_acac;
pub mod import_actors;
pub mod mock;
pub mod net_policy;
