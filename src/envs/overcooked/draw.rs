//! One Overcooked frame. (filled in below)
use super::Overcooked;
use crate::draw::{Canvas, Colour, Picture};

/// Status-bar labels of the agents.
pub static LABELS: [&str; 3] = ["A0", "A1", "A2"];

/// The picture of `env`'s current state.
pub fn draw(env: &Overcooked) -> Picture {
    let _ = env;
    Picture {
        world: Canvas::new(10, 10, Colour::Background),
        agent_labels: &LABELS[..env.params().n_agent],
    }
}
