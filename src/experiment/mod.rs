//! Experiments: configs, seeds, the parallel runner, metrics and checkpoints.

pub mod audit;
pub mod checkpoint;
pub mod config;
pub mod limits;
pub mod metrics;
pub mod names;
pub mod paper;
pub mod policy_files;
pub mod provenance;
pub mod report;
pub mod results_tree;
pub mod rollout;
pub mod run_settings;
pub mod runner;
pub mod seeds;
pub mod slurm;
pub mod train_run;
pub mod work_queue;
