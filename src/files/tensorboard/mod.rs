//! TensorBoard event files, written by hand (no TensorFlow, no protobuf crate): the one writer
//! `macdec train --tensorboard` logs through. Layers, each its own file: the checksum
//! ([`crc32c`]), the protobuf wire pieces ([`protobuf`]), the `Event` message ([`event`]), the
//! TFRecord framing ([`record`]), and the file ([`writer`]). A reader of the same subset is here
//! too, for tests; TensorBoard's own reader is checked against these files by
//! `python/tests/test_tensorboard.py`.

pub mod crc32c;
pub mod event;
pub mod protobuf;
pub mod record;
pub mod writer;

pub use event::{Event, Scalar, What};
pub use writer::{event_files, read_events, EventWriter};
