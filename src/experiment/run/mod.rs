//! Running it and what a run writes: the parallel runner ([`runner`], [`work_queue`], with the
//! [`progress`] a run reports to it), every run of an experiment ([`train_all`], stopped early by
//! a [`stop`] signal), one run on disk with resume ([`train_run`]), its files ([`results_tree`]
//! names them; [`checkpoint`], [`metrics`], [`provenance`]; its `policy/` directory is of the one
//! format in [`crate::policy_files`]), its live TensorBoard log ([`tensorboard`]), the terminal
//! summary ([`report`]) and every run of a tree as one table ([`tidy_table`]).

pub mod checkpoint;
pub mod metrics;
pub mod progress;
pub mod provenance;
pub mod report;
pub mod results_tree;
pub mod runner;
pub mod stop;
pub mod tensorboard;
pub mod tidy_table;
pub mod train_all;
pub mod train_run;
pub mod work_queue;
