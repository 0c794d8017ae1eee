//! Animated rollouts for the README (issue 6, `macdec render`): play an episode of either domain,
//! draw every primitive step into a small indexed picture, and write the pictures as a GIF.
//!
//! No fonts or image libraries: [`crate::draw`] draws rectangles, discs and lines into palette
//! indices, a built-in 3 x 5 font writes the status bar, and the `gif` crate encodes. Each
//! domain draws its own picture in its folder ([`MacroEnv::draw`]); a domain that draws none
//! cannot be rendered, and [`draw_frame`] says so.
//!
//! ```no_run
//! # use macdec::envs::{EnvRng, MacroEnv};
//! # use rand::SeedableRng;
//! let mut env = macdec::envs::box_pushing::spec(10, 100).build()?;
//! let mut rng = EnvRng::seed_from_u64(0);
//! let frames = macdec::render::record_episode(&mut env, &mut rng, |env, actions| {
//!     for i in 0..env.n_agents() {
//!         if env.is_free(i) {
//!             actions[i] = 7; // Stay
//!         }
//!     }
//! })?;
//! macdec::render::write_gif(&frames, "rollout.gif".as_ref(), 120)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::PathBuf;

use crate::envs::{EnvError, MacroEnv};

mod gif_out;
mod hud;
mod record;
pub mod rollout;

pub use crate::draw::{canvas, palette, Canvas, Colour};
pub use gif_out::{write_gif, write_gif_with, GifWriter, HOLD_MS};
pub use record::{play_episode, record_episode};

/// One drawn primitive step of an episode.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// The picture: the domain on top, a status bar (step, return, executed macro-actions) below.
    pub image: Canvas,
    /// Primitive steps since reset when it was drawn.
    pub t: usize,
    /// Undiscounted team reward summed over steps 1..=t.
    pub team_return: f64,
    /// Last frame of an episode: [`write_gif`] shows it for at least [`HOLD_MS`].
    pub hold: bool,
}

/// Why recording or writing a rollout failed. File errors name the path.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The domain implements no `draw`.
    #[error("the domain `{domain}` draws no picture (its MacroEnv has no `draw`), so it cannot be rendered; `macdec replay --verbose` prints its text form")]
    NoPicture {
        /// The domain's name.
        domain: String,
    },
    /// The policy could not choose the actions of a step (a net answered with a non-finite score,
    /// or an observation of the wrong length).
    #[error("step {t}: the policy could not act: {message}")]
    Policy {
        /// Primitive step it was to choose for.
        t: usize,
        /// Why.
        message: String,
    },
    /// The environment refused a step of the recorded episode.
    #[error("step {t} of the recorded episode was refused: {source}")]
    Env {
        /// Primitive step at which it refused.
        t: usize,
        /// The environment's error.
        #[source]
        source: EnvError,
    },
    /// Nothing was recorded, so there is no GIF to write.
    #[error("{}: no frames to write", .path.display())]
    NoFrames {
        /// The GIF that would have been written.
        path: PathBuf,
    },
    /// Frames of different sizes (a GIF has one size).
    #[error("{}: frame {index} is {}x{} pixels but frame 0 is {}x{}; one GIF holds one size (record one domain per file)", .path.display(), .got.0, .got.1, .expected.0, .expected.1)]
    SizeMismatch {
        /// The GIF.
        path: PathBuf,
        /// The first frame whose size differs.
        index: usize,
        /// Its (width, height) in pixels.
        got: (usize, usize),
        /// Frame 0's (width, height) in pixels.
        expected: (usize, usize),
    },
    /// Frames wider or taller than a GIF's 65535 pixels.
    #[error("{}: frames of {width}x{height} pixels exceed the GIF limit of 65535", .path.display())]
    TooLarge {
        /// The GIF.
        path: PathBuf,
        /// Frame width in pixels.
        width: usize,
        /// Frame height in pixels.
        height: usize,
    },
    /// The GIF encoder failed.
    #[error("{}: GIF encoding failed: {source}", .path.display())]
    Encode {
        /// The GIF.
        path: PathBuf,
        /// The encoder's error.
        #[source]
        source: gif::EncodingError,
    },
    /// Writing the GIF failed.
    #[error("{}: writing the GIF failed: {source}", .path.display())]
    Io {
        /// The GIF.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// The domain's picture of `env`'s current state ([`MacroEnv::draw`]) with the status bar
/// below it, `team_return` in it; `None` for a domain that draws none. Sizes: Box Pushing
/// 10 x 10 is 321 pixels wide (32 per cell), 30 x 30 is 361 (12 per cell); Warehouse is 420 (60
/// per metre); the status bar adds a few dozen rows.
pub fn draw_frame(env: &impl MacroEnv, team_return: f64) -> Option<Canvas> {
    let picture = env.draw()?;
    let (w, h) = (picture.world.width(), picture.world.height());
    // A picture must label every agent; a domain that labels too few gets numbered labels.
    const NUMBERED: [&str; 16] = [
        "A0", "A1", "A2", "A3", "A4", "A5", "A6", "A7", "A8", "A9", "A10", "A11", "A12", "A13",
        "A14", "A15",
    ];
    let labels = match picture.agent_labels {
        l if l.len() >= env.n_agents() => l,
        _ => NUMBERED.get(..env.n_agents())?,
    };
    let mut canvas = Canvas::new(w, h + hud::hud_height(env, labels, w), Colour::Background);
    canvas.paste(&picture.world, 0, 0);
    hud::draw_hud(&mut canvas, h, env, labels, team_return);
    Some(canvas)
}

#[cfg(test)]
mod tests;
