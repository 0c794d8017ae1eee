//! MacroMARL's macro-action actor-critic methods (Xiao, Tan and Amato, NeurIPS 2022; spec
//! `macromarl.md` 2): Mac-IAC, Mac-CAC, Naive Mac-IACC and Mac-IAICC, with history or state
//! critics.
//!
//! The data flow: lanes record episodes as the reference's runner does ([`episode`]); a batch
//! of the last `train_freq` completed episodes is squeezed to macro-actions ([`squeeze`]), the
//! critics learn SMDP returns ([`returns`]) and the actors the advantages ([`update`]) on the
//! nets of [`nets`]; [`acting`] samples the actions (or [`scripted`] replays given ones);
//! [`learner`] ties it to the training loop.

pub mod acting;
pub mod config;
pub mod episode;
pub mod family;
pub mod learner;
pub mod lockstep_eval;
pub mod method;
pub mod nets;
pub mod published;
pub mod returns;
pub mod scripted;
pub mod squeeze;
pub mod update;
