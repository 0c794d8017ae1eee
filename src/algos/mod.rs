//! The five learning methods: replay, squeezing, exploration, targets and the training loop.

pub mod hyper;
pub mod method;
