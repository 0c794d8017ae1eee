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
//! - `safetensors_io`: weight files with PyTorch's state_dict names; [`StateDict`]: one module's
//!   tensors inside a larger state_dict, by name.
//! - ACAC's nets (issue 41), each matching ACAC's PyTorch modules in values and
//!   gradients and loading from their state_dict names: [`LayerNormParams`], [`Conv1dParams`]
//!   (GPT-2's transposed linear layer), [`Gpt2Block`] and the encoder [`Gpt2`] (attention over the
//!   agents of each sample, dropout masks supplied from outside: [`Gpt2Dropout`]), the
//!   sinusoidal [`TimeEmbedding`], [`PopArt`], the [`ValueHead`]s, and [`AcacJointValue`], the
//!   critic after its encoders; [`AcacActor`] and its [`AcacEncoder`], and [`TimedAcacActor`],
//!   the actor with its time table as policy files hold it and agents act with it.

mod acac_actor;
#[cfg(test)]
mod acac_fixture;
mod acac_joint_value;
mod acting_net;
mod adam;
pub mod argmax;
mod conv1d;
pub mod demo;
mod gpt2;
mod gpt2_block;
mod gpt2_dropout;
mod gru;
mod gru_actor;
pub mod init;
pub mod joint_index;
mod layer_norm;
mod linear;
pub mod loss;
mod lstm;
mod params;
mod popart;
mod qnet;
pub mod safetensors_io;
pub mod sampling;
mod state_critic;
mod state_dict;
mod time_embedding;
mod update;
mod value_head;

/// Widest layer of any net a config or a policy file may ask for (paper: 32 and 64), so neither
/// can make the process allocate beyond what a net needs (README "Limits and guarantees").
pub const MAX_NET_WIDTH: usize = 2_048;

pub use acac_actor::{
    acting_input, time_row, AcacActor, AcacActorState, AcacActorVars, AcacEncoder, AcacEncoderVars,
    TimedAcacActor, ACAC_ACTOR_TENSOR_NAMES, TIME_TABLE,
};
pub use acac_joint_value::{AcacJointValue, AcacJointValueVars, ValueLayer};
pub use acting_net::{ActingNet, ActingNetRef, ActingState};
pub use adam::{Adam, AdamConfig};
pub use argmax::argmax;
pub use conv1d::{Conv1dParams, Conv1dVars};
pub use gpt2::{gpt2_tensor_names, Gpt2, Gpt2Config, Gpt2Vars};
pub use gpt2_block::{Gpt2Block, Gpt2BlockVars, GPT2_BLOCK_BUFFERS, GPT2_BLOCK_TENSOR_NAMES};
pub use gpt2_dropout::{dropout_mask, BlockDropout, Gpt2Dropout};
pub use gru::{GruState, GRU_TENSOR_NAMES};
pub(crate) use gru_actor::log_softmax_in_place;
pub use gru_actor::{
    GruActor, GruActorConfig, GruActorState, GruActorVars, GRU_ACTOR_TENSOR_NAMES,
};
pub use layer_norm::{LayerNormParams, LayerNormVars, LAYER_NORM_EPS};
pub use linear::LinearVars;
pub use lstm::LstmState;
pub(crate) use params::{flat, flat_mut};
pub use params::{GruParams, LinearParams, LstmParams, Params};
pub use popart::{PopArt, POPART_BETA, POPART_EPSILON};
pub use qnet::{
    flatten_padded, Dim, QNet, QNetConfig, QNetParams, QNetVars, TensorSpec, TENSORS, TENSOR_NAMES,
};
pub use safetensors_io::WeightsError;
pub use state_critic::{StateCritic, StateCriticVars, STATE_CRITIC_TENSOR_NAMES};
pub use state_dict::StateDict;
pub use time_embedding::{sinusoidal_table, TimeEmbedding, TimeEmbeddingError};
pub use update::{TdBatch, Updater};
pub use value_head::{UnknownValueHead, ValueHead};
