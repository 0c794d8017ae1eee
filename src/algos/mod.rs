//! Learning: one training loop ([`training_loop::TrainingLoop`]) over a learner interface
//! ([`learner::Learner`]) that each method family implements in its own folder.
//!
//! The loop owns what every family shares: the lanes of environments and their random streams,
//! the evaluation schedule, the counters (episodes, primitive steps, updates), the metrics rows
//! and the wall clock; a checkpoint is the whole loop. A family owns what its papers define: its
//! nets, how they act while training and when evaluated, what it records and replays, and what a
//! training iteration and a target sync do.
//!
//! The families are one list ([`families`]): [`value`] (the ICRA 2020 Q-learning methods) and
//! [`actor_critic`] (MacroMARL's macro-action actor-critic methods). Each folder owns its methods
//! (one enum, a [`family::FamilyMethod`]), its typed config and checks, its published settings,
//! its quick start and its learner; within a family, methods differ in exhaustive `match`es on its
//! own enum, and nothing outside the folder matches on one of its methods.

pub mod acac;
pub mod actor_critic;
pub mod config_checks;
pub mod families;
pub mod family;
pub mod learner;
pub mod mac_value;
pub mod scratch;
pub mod train_error;
pub mod training_loop;
pub mod update_means;
pub mod value;
