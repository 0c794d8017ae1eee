//! `macdec bench ...`: timing of the hot paths (`nets`: one Q-net training update; `gru`: the
//! GRU beside the LSTM).

pub mod gru;
pub mod nets;
pub mod train;
