//! Experiments: configs, seeds, the parallel runner, metrics and checkpoints.

pub mod atomic;
pub mod audit;
pub mod config;
pub mod metrics;
pub mod provenance;
pub mod report;
pub mod rollout;
pub mod runner;
pub mod seeds;
pub mod slurm;
pub mod train_run;
