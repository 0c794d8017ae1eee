//! The domain side of a deployment: episodes driven against one link per robot ([`driver`],
//! [`link`]), robot processes started here ([`processes`]) or already running elsewhere
//! ([`remote`]), and in-process greedy evaluation of a policy directory ([`local_eval`]).

pub mod driver;
pub mod link;
pub mod local_eval;
pub mod processes;
pub mod remote;
