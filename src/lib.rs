//! macdec: macro-action multi-agent deep reinforcement learning in pure Rust.
//!
//! It reproduces *Learning Multi-Robot Decentralized Macro-Action-Based Policies via a
//! Centralized Q-Net* (Xiao, Hoffman, Xia, Amato, ICRA 2020: Dec-HDDRQN, Cen-DDRQN, Our-1,
//! Our-1-R, Our-2) and the macro-action actor-critic methods of the same authors' MacroMARL
//! (Mac-IAC, Mac-CAC, Naive Mac-IACC/IASC, Mac-IAICC/IAISC), on their domains, step for step
//! with the reference code. The `macdec` binary is [`cli`]; everything it does is a library call
//! documented here. What the methods compute and what the domains do, in words:
//! `docs/ALGORITHMS.md`, `docs/MACROMARL.md`, `docs/BOX_PUSHING.md`, `docs/WAREHOUSE.md`.
//!
//! # How data flows
//!
//! ```text
//! experiments/*.toml ─► experiment::definition ─► experiment::run ─► algos ─► envs + nn
//!   (config, methods,    (parse and validate       (runner: one job    (training   (dynamics;
//!    seeds, sweeps)       once: Experiment,         per method x seed;  loop and    nets on
//!                         RunSpec, RunConfig)       checkpoints,        learners)   autograd)
//!                                                   metrics.csv)
//!                                                        │
//!            results/<experiment>/<curve>/seed-<k>/ ◄────┘
//!              ├─► plot (figures, summaries)   ├─► experiment::run::tidy_table (one long CSV)
//!              ├─► report (IQM, bootstrap CIs, profiles, marl-eval JSON)
//!              ├─► render (GIF rollouts)       ├─► experiment::cluster::audit (retrain, compare)
//!              └─► deploy (export, eval, robot server, robot drivers) via policy_files
//! ```
//!
//! Each stage, in that order:
//!
//! 1. [`experiment::definition`]: an experiment file becomes a validated
//!    [`experiment::definition::config::Experiment`] (methods, seeds, sweeps) and per-run
//!    [`RunConfig`]s (each method's family holds the papers' settings, [`Method::defaults`];
//!    [`experiment::definition::limits`] lists every bound).
//! 2. [`experiment::run`]: [`experiment::run::runner`] trains the runs in parallel, each through
//!    [`experiment::run::train_run`] (resume from [`experiment::run::checkpoint`], write
//!    [`experiment::run::metrics`] and [`policy_files`], named by
//!    [`experiment::run::results_tree`]).
//! 3. [`algos`]: one [`algos::training_loop::TrainingLoop`] drives a learner per method family:
//!    [`algos::value`] (the ICRA methods) and [`algos::actor_critic`] (MacroMARL's); a method's
//!    choices are [`Method`].
//! 4. [`envs`]: the [`MacroEnv`] contract, one folder per domain, the [`envs::registry`] that
//!    finds a domain by name, and [`envs::replay`] of action logs.
//! 5. [`nn`] on [`autograd`]: layers, the recurrent Q-net and actors, Adam, safetensors I/O.
//! 6. After training: [`plot`] (learning curves and tables, statistics in [`curve_stats`]),
//!    [`report`] (rliable's aggregate statistics with bootstrap intervals, and marl-eval's JSON),
//!    [`experiment::run::tidy_table`], [`render`] (pictures drawn with [`draw`]), [`deploy`]
//!    (export and import of [`policy_files`], the robot protocol and server, drivers),
//!    [`experiment::cluster::audit`], and [`mod@bench`] for timings. [`files`] is the ground
//!    floor every layer writes through (atomic writes, bounded reads).
//!
//! Lower layers never name higher ones: `autograd` knows no layers, `envs` no nets and no
//! learner (a family's published settings for a domain live in the family's folder), `algos` no
//! runner, `deploy` no learner. `tests/file_circles.rs` holds the order (files, draw,
//! curve_stats < autograd < nn < envs < algos, policy_files < experiment, deploy, plot, render,
//! report < cli, api, bench) and fails on an import against it.
//!
//! # Your own domain or program
//!
//! Implement [`MacroEnv`] (and [`envs::Domain`] for configs and policy files) and either run
//! the whole command line with it ([`cli::main_with`]), or call [`train`] for a learning curve,
//! or [`train_policy`] and [`TrainedPolicy::export`] to put the trained policy on robots (see
//! `examples/custom_domain.rs`).

#![warn(missing_docs)]

pub mod algos;
pub mod api;
pub mod autograd;
pub mod bench;
pub mod cli;
pub mod curve_stats;
pub mod deploy;
pub mod draw;
pub mod envs;
pub mod experiment;
pub mod files;
pub mod nn;
pub mod plot;
pub mod policy_files;
pub mod render;
pub mod report;

pub use algos::families::{AnyLoop, Method, RunConfig};
pub use algos::training_loop::EvalPoint;
pub use api::{train, train_policy, LibraryTrainError, TrainedPolicy};
pub use envs::{EnvError, EnvRng, EnvSpec, FirstRecordObs, MacroEnv, StepOutcome};
pub use policy_files::PolicyEnv;
