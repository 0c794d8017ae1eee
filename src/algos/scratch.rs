//! A learner's scratch memory: what an update reuses instead of allocating again (the autodiff
//! tape, gradient buffers). It holds nothing of the run: every buffer is overwritten before it is
//! read, so it is not saved in a checkpoint, a clone starts with an empty one, and neither changes
//! a number.

/// Scratch `T` kept beside a learner's state (mark the field `#[serde(skip, default)]`); a clone
/// is empty, as a learner resumed from a checkpoint is.
#[derive(Debug, Default)]
pub struct Scratch<T>(pub T);

impl<T: Default> Clone for Scratch<T> {
    fn clone(&self) -> Self {
        Scratch::default()
    }
}
