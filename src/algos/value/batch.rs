//! A sampled batch of sequences, as both replay buffers hand it out (`docs/ALGORITHMS.md` §3): a
//! sequence is a contiguous run of one stored episode's records, never its padding.

use std::ops::Range;

use super::record::Episode;

/// One sampled sequence: records `start..end` of `episode` in time order.
///
/// In the reference's padded form the sequence has `lead_pad` zero records before them and zero
/// records after them up to [`Batch::padded_len`].
#[derive(Debug, Clone, Copy)]
pub struct Sequence<'a> {
    /// The episode the records come from.
    pub episode: &'a Episode,
    /// First real record's index in the episode.
    pub start: usize,
    /// One past the last real record's index.
    pub end: usize,
    /// Zero records before the real ones in the padded form.
    pub lead_pad: usize,
}

impl Sequence<'_> {
    /// Number of real (non-padding) records.
    pub fn len(&self) -> usize {
        self.end - self.start
    }
    /// True if the sequence holds no real record (never produced by the buffers).
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
    /// Indices of the real records inside [`Self::episode`].
    pub fn records(&self) -> Range<usize> {
        self.start..self.end
    }
}

/// B sampled sequences (with replacement, in draw order) borrowing the buffer's storage.
#[derive(Debug, Clone)]
pub struct Batch<'a> {
    /// The B sequences, in draw order.
    pub sequences: Vec<Sequence<'a>>,
    /// T of the reference's padded `B x T` batch: trace_len (windows) or the longest sampled
    /// episode (episodes, `docs/ALGORITHMS.md` §3.2).
    pub padded_len: usize,
}
