//! Packing a batch of variable-length sequences for a time-major LSTM pass.
//!
//! Spec `algorithms.md` 2.3: every sequence unrolls from a zero state over its own valid length
//! only. Sorting the sequences by decreasing length (stable, so ties keep batch order) makes the
//! sequences still running at step t a prefix of the batch: step t then touches the contiguous
//! packed rows `offset(t) .. offset(t) + batch_size(t)`, and its predecessors sit at the same
//! positions of step t-1. This is PyTorch's `PackedSequence` layout.
//!
//! "Flat" order, used by every API outside the LSTM kernel, is row-major over valid positions:
//! sequence first, time second (`flat = start(s) + t`).

/// Where each (sequence, step) lives in flat and in packed order.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct SeqPacking {
    lengths: Vec<usize>,
    starts: Vec<usize>,
    batch_sizes: Vec<usize>,
    offsets: Vec<usize>,
    packed_to_flat: Vec<usize>,
    flat_to_packed: Vec<usize>,
}

impl SeqPacking {
    /// The packing of sequences with these lengths (zero-length sequences are allowed and take
    /// no rows).
    pub fn new(lengths: &[usize]) -> Self {
        let mut p = SeqPacking::default();
        p.rebuild(lengths);
        p
    }

    /// Recompute for new lengths, reusing the allocations.
    pub fn rebuild(&mut self, lengths: &[usize]) {
        self.lengths.clear();
        self.lengths.extend_from_slice(lengths);
        self.starts.clear();
        let mut at = 0;
        for &l in lengths {
            self.starts.push(at);
            at += l;
        }
        let mut order: Vec<usize> = (0..lengths.len()).collect();
        order.sort_by(|&a, &b| lengths[b].cmp(&lengths[a]));
        let max_len = lengths.iter().copied().max().unwrap_or(0);
        self.batch_sizes.clear();
        self.offsets.clear();
        self.packed_to_flat.clear();
        let mut active = order.len();
        for t in 0..max_len {
            while active > 0 && lengths[order[active - 1]] <= t {
                active -= 1;
            }
            self.offsets.push(self.packed_to_flat.len());
            self.batch_sizes.push(active);
            for &s in &order[..active] {
                self.packed_to_flat.push(self.starts[s] + t);
            }
        }
        self.offsets.push(self.packed_to_flat.len());
        self.flat_to_packed.clear();
        self.flat_to_packed.resize(self.packed_to_flat.len(), 0);
        for (p, &f) in self.packed_to_flat.iter().enumerate() {
            self.flat_to_packed[f] = p;
        }
    }

    /// Each sequence's valid length, in batch order.
    pub fn lengths(&self) -> &[usize] {
        &self.lengths
    }

    /// Total number of valid positions K (rows of the flat and packed layouts).
    pub fn total(&self) -> usize {
        self.packed_to_flat.len()
    }

    /// Number of steps T (the longest length).
    pub fn n_steps(&self) -> usize {
        self.batch_sizes.len()
    }

    /// Sequences still running at step t (they are packed positions 0..batch_size(t)).
    pub fn batch_size(&self, t: usize) -> usize {
        self.batch_sizes.get(t).copied().unwrap_or(0)
    }

    /// First packed row of step t.
    pub fn offset(&self, t: usize) -> usize {
        self.offsets[t]
    }

    /// Flat row (sequence-major) of packed row p.
    pub fn packed_to_flat(&self) -> &[usize] {
        &self.packed_to_flat
    }

    /// Packed row of flat row f (the inverse of [`SeqPacking::packed_to_flat`]).
    pub fn flat_to_packed(&self) -> &[usize] {
        &self.flat_to_packed
    }

    /// Flat row of (sequence s, step t). Panics if t is past the sequence's end.
    pub fn flat_row(&self, s: usize, t: usize) -> usize {
        assert!(t < self.lengths[s], "step {t} past the end of sequence {s}");
        self.starts[s] + t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn running_sequences_form_a_prefix_at_every_step() {
        // lengths 2, 0, 3, 3: sorted order by decreasing length is 2, 3, 0, 1 (ties keep order)
        let p = SeqPacking::new(&[2, 0, 3, 3]);
        assert_eq!(p.total(), 8);
        assert_eq!(p.n_steps(), 3);
        assert_eq!(
            (0..3).map(|t| p.batch_size(t)).collect::<Vec<_>>(),
            vec![3, 3, 2]
        );
        // flat starts: seq0 0, seq1 2, seq2 2, seq3 5
        // t=0: seqs 2, 3, 0 -> flat 2, 5, 0; t=1: 3, 6, 1; t=2: 4, 7
        assert_eq!(p.packed_to_flat(), &[2, 5, 0, 3, 6, 1, 4, 7]);
        assert_eq!(p.offset(2), 6);
        assert_eq!(p.flat_row(3, 2), 7);
    }

    #[test]
    fn packing_is_a_permutation_of_the_flat_rows() {
        let p = SeqPacking::new(&[5, 1, 4, 4, 0, 2]);
        let mut seen = p.packed_to_flat().to_vec();
        seen.sort_unstable();
        assert_eq!(seen, (0..16).collect::<Vec<_>>());
        for (pk, &f) in p.packed_to_flat().iter().enumerate() {
            assert_eq!(p.flat_to_packed()[f], pk);
        }
    }
}
