//! Reverse-mode automatic differentiation over `ndarray`, in f32.
//!
//! A [`Tape`] records the forward pass as an arena of nodes addressed by `Copy` ids ([`Var`]);
//! [`Tape::backward`] replays it in reverse, accumulating gradients with `+=`. Each op is public,
//! defined once with its backward beside its forward (`ops/`, which lists them all), and has a
//! central-difference gradient check. The LSTM and the GRU are each one fused op over a batch of
//! variable-length sequences (`ops/lstm.rs`, `ops/gru.rs`), checked against their unfused
//! compositions; so are the fused layer norm, GPT-2's GELU and multi-head self-attention within
//! sets of rows (`ops/layer_norm.rs`, `ops/gelu.rs`, `ops/attention.rs`). The numeric kernels
//! (`kernels/`) are shared with the no-tape paths used for acting and for target values.
//! Nothing here knows about layers or nets.

pub mod kernels;
mod ops;
mod packing;
mod pool;
mod tape;

pub use kernels::dense::Activation;
pub use ops::{AttentionSpec, GruVars, LstmVars};
pub use packing::SeqPacking;
pub use pool::Pool;
pub use tape::{Tape, Var};
