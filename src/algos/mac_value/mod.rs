//! MacroMARL's value-based macro-action methods (Xiao, Hoffman and Amato, CoRL 2019; the
//! reference's `scripts/value_based_main.py --alg MacDecQ | MacCenQ`, `docs/MACROMARL.md` §8):
//! MacDec-Q (decentralized hysteretic double DRQNs over squeezed per-agent experience) and MacCen-Q
//! (one centralized joint macro-action Q-net with the conditional argmax).
//!
//! A family of its own, not variants of [`crate::algos::value`] (the ICRA 2020 LSTM code): the net
//! is MacroMARL's GRU `DDRQN` ([`crate::nn::GruActor`]'s layers), the runner discounts rewards
//! inside a macro-action and bootstraps with gamma^duration, the next-history input continues the
//! same unroll, exploration and hysteresis follow other counters, and the published settings are
//! MacroMARL's. Sharing the ICRA family's code would thread every one of these through paths whose
//! numbers are frozen.
//!
//! The data flow: lanes record primitive steps as the reference's runner does ([`episode`]); two
//! memories ([`memory`]: windows of `trace_len` or whole episodes) hand out batches of record
//! ranges; `squeeze` cuts them down to the records each net learns from, and [`update`] takes
//! one Adam step on them; [`learner`] ties it to the training
//! loop and acts ([`acting`]).

pub mod acting;
pub mod choice;
pub mod config;
pub mod episode;
pub mod family;
pub mod learner;
pub mod memory;
pub mod method;
mod prefetch;
pub mod published;
mod squeeze;
pub mod update;
