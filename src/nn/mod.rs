//! Layers, the reference's recurrent Q-net, Adam, and weight files, on top of `autograd`.
//!
//! - [`QNet`]: fc1 -> fc2 -> LSTM -> fc3 -> fc4 with leaky ReLU (`docs/ALGORITHMS.md` §2.1),
//!   run on a tape over a batch of sequences (training), without a tape (targets), or one step
//!   at a time with an [`LstmState`] (acting).
//! - [`GruParams`]: a one-layer GRU as PyTorch's `nn.GRU` (gate order, init, state_dict
//!   names), run on a tape over packed sequences (`Tape::gru_packed`) or one step at a time
//!   with a [`GruState`] (acting).
//! - [`GruActor`]: MacroMARL's actor fc1 -> fc2 -> GRU -> fc3 -> fc4 -> log_softmax (and its
//!   history critic), for acting and training; [`StateCritic`]: its MLP critic on the state.
//! - [`Adam`]: PyTorch's Adam (`docs/ALGORITHMS.md` §2.4); [`Updater::td_step`]: one full TD gradient step.
//! - `safetensors_io`: weight files with PyTorch's state_dict names.

mod acting_net;
mod adam;
pub mod argmax;
pub mod demo;
mod gru;
mod gru_actor;
pub mod init;
mod linear;
pub mod loss;
mod lstm;
mod params;
mod qnet;
pub mod safetensors_io;
pub mod sampling;
mod state_critic;
mod update;

/// Widest layer of any net a config or a policy file may ask for (paper: 32 and 64), so neither
/// can make the process allocate beyond what a net needs (README "Limits and guarantees").
pub const MAX_NET_WIDTH: usize = 2_048;

pub use acting_net::{ActingNet, ActingNetRef, ActingState};
pub use adam::{Adam, AdamConfig};
pub use argmax::argmax;
pub use gru::{GruState, GRU_TENSOR_NAMES};
pub use gru_actor::{
    GruActor, GruActorConfig, GruActorState, GruActorVars, GRU_ACTOR_TENSOR_NAMES,
};
pub use linear::LinearVars;
pub use lstm::LstmState;
pub use params::{GruParams, LinearParams, LstmParams, Params};
pub use qnet::{
    flatten_padded, Dim, QNet, QNetConfig, QNetParams, QNetVars, TensorSpec, TENSORS, TENSOR_NAMES,
};
pub use safetensors_io::WeightsError;
pub use state_critic::{StateCritic, StateCriticVars, STATE_CRITIC_TENSOR_NAMES};
pub use update::{TdBatch, Updater};
