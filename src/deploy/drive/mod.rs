//! The domain side of a deployment: episodes driven against one link per robot ([`driver`],
//! [`link`]), robot processes started here ([`processes`]) or already running elsewhere
//! ([`remote`]), and in-process evaluation of a policy directory ([`local_eval`]) by its agents'
//! nets or by one centralized net acting for the team ([`team`]).

pub mod driver;
pub mod link;
pub mod local_eval;
pub mod processes;
pub mod remote;
pub mod team;
