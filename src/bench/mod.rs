//! `macdec bench ...`: timing of the hot paths (`nets`: one Q-net training update).

pub mod nets;
pub mod train;
