//! Experiments, in three folders by job: [`definition`] (what to run: configs, paper settings,
//! seeds, limits), [`run`] (running it: the runner, one run on disk, checkpoints, metrics, policy
//! files, the results tree) and [`cluster`] (Slurm and audits over a results tree). The modules
//! are re-exported here, so `macdec::experiment::train_run` and the like keep their paths.

pub mod cluster;
pub mod definition;
pub mod run;

pub use cluster::{audit, slurm};
pub use definition::{config, limits, names, paper, run_settings, seeds};
pub use run::{
    checkpoint, metrics, policy_files, provenance, report, results_tree, runner, stop, tidy_table,
    train_all, train_run, work_queue,
};
