//! The ground floor: generic file I/O that every layer may use (atomic writes onto regular files
//! only, bounded reads of regular files only, no links followed inside a results tree) and the
//! TensorBoard event-file format.
//! It names nothing of the crate above it, so a lower layer (deploy, render, plot) writing a
//! file never depends on the experiment layer.

pub mod atomic;
pub mod bounded_read;
pub mod dir_swap;
pub mod links;
pub mod tensorboard;
