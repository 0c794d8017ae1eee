//! The robot side: the JSON-lines protocol ([`protocol`]), one agent's policy served over
//! stdin/stdout or a stream ([`robot`]) and over TCP ([`server`]), with bounded line reads
//! ([`line_reader`]) and deadlines ([`deadline`]).

pub mod deadline;
pub mod line_reader;
pub mod protocol;
pub mod robot;
pub mod server;
