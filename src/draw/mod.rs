//! Pixels without a domain: an indexed [`Canvas`] with the few shapes pictures need, the fixed
//! [`palette`] and a built-in 3 x 5 [`font`]. Domains draw their pictures with it (each in its own
//! folder, [`crate::envs::MacroEnv::draw`]); the renderer (`src/render`) adds the status bar and writes GIFs.

pub mod canvas;
pub mod font;
pub mod palette;

pub use canvas::Canvas;
pub use palette::Colour;

/// A domain's picture of its state, without the status bar: the world, and the short label of
/// each agent (`R0`, `T1`, `F`) that the status bar prints in the agent's colour.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// The world drawn in pixels.
    pub world: Canvas,
    /// One label per agent, in agent order.
    pub agent_labels: &'static [&'static str],
}
