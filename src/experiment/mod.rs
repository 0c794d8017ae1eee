//! Experiments, in three folders by job: [`definition`] (what to run: configs, paper settings,
//! seeds, limits), [`run`] (running it: the runner, one run on disk, checkpoints, metrics and the
//! results tree) and [`cluster`] (Slurm and audits over a results tree). Each module has one
//! path, through its folder: `macdec::experiment::run::train_run`, `experiment::definition::paper`.

pub mod cluster;
pub mod definition;
pub mod run;
