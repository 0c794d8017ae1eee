//! A free list of float buffers, so a tape that is reset and rebuilt every update reuses the same
//! memory instead of asking the allocator (and the OS, for large blocks) again.

use std::collections::BTreeMap;

use ndarray::Array2;

/// Returned buffers, reused best-fit. Holds at most as many buffers as were alive at once, so
/// repeating the same computation never grows it.
#[derive(Debug, Default)]
pub struct Pool {
    /// The free buffers by capacity, several of one capacity stacked. Ordered, so the best fit
    /// is one range lookup: the learners' tapes hold dozens of buffers whose sizes change with
    /// every batch, and scanning them all on every request took 2% of a MacDec-Q run.
    free: BTreeMap<usize, Vec<Vec<f32>>>,
}

impl Pool {
    /// A buffer of `len` floats. Its contents are unspecified (old values from an earlier use):
    /// the caller overwrites every element.
    pub fn take(&mut self, len: usize) -> Vec<f32> {
        // The smallest buffer that can hold `len` without reallocating (an update loop asks for
        // the same sizes every time, so usually one of exactly this size).
        let Some((&capacity, stack)) = self.free.range_mut(len..).next() else {
            return vec![0.0; len];
        };
        let mut buf = stack.pop().expect("no empty stacks are kept");
        if stack.is_empty() {
            self.free.remove(&capacity);
        }
        buf.resize(len, 0.0);
        buf
    }

    /// A [rows, cols] array with unspecified contents (see [`Pool::take`]).
    pub fn array(&mut self, rows: usize, cols: usize) -> Array2<f32> {
        Array2::from_shape_vec((rows, cols), self.take(rows * cols))
            .expect("pool buffer has exactly rows * cols elements")
    }

    /// A [rows, cols] array of zeros.
    pub fn zeros(&mut self, rows: usize, cols: usize) -> Array2<f32> {
        let mut a = self.array(rows, cols);
        zero(&mut a);
        a
    }

    /// Give a buffer back for reuse.
    pub fn give(&mut self, buf: Vec<f32>) {
        if buf.capacity() > 0 {
            self.free.entry(buf.capacity()).or_default().push(buf);
        }
    }

    /// Give an array's storage back for reuse.
    pub fn give_array(&mut self, a: Array2<f32>) {
        self.give(a.into_raw_vec_and_offset().0);
    }

    /// Total floats held (for tests that check memory stays bounded).
    pub fn floats_held(&self) -> usize {
        self.free.iter().map(|(&c, stack)| c * stack.len()).sum()
    }

    /// Number of buffers held.
    pub fn buffers_held(&self) -> usize {
        self.free.values().map(Vec::len).sum()
    }
}

/// a = 0 everywhere: one `memset` for a contiguous array (ndarray's `fill` stores element by
/// element).
pub(crate) fn zero(a: &mut Array2<f32>) {
    match a.as_slice_mut() {
        Some(s) => s.fill(0.0),
        None => a.fill(0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn take_reuses_the_smallest_buffer_that_fits() {
        let mut pool = Pool::default();
        pool.give(Vec::with_capacity(100));
        pool.give(Vec::with_capacity(10));
        pool.give(Vec::with_capacity(50));
        let b = pool.take(20);
        assert_eq!(b.len(), 20);
        assert_eq!(b.capacity(), 50);
        assert_eq!(pool.buffers_held(), 2);
        let c = pool.take(1000);
        assert_eq!(c.len(), 1000);
        assert_eq!(pool.buffers_held(), 2);
    }
}
