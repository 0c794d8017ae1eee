//! A free list of float buffers, so a tape that is reset and rebuilt every update reuses the same
//! memory instead of asking the allocator (and the OS, for large blocks) again.

use ndarray::Array2;

/// Returned buffers, reused best-fit. Holds at most as many buffers as were alive at once, so
/// repeating the same computation never grows it.
#[derive(Debug, Default)]
pub struct Pool {
    free: Vec<Vec<f32>>,
}

impl Pool {
    /// A buffer of `len` floats. Its contents are unspecified (old values from an earlier use):
    /// the caller overwrites every element.
    pub fn take(&mut self, len: usize) -> Vec<f32> {
        // A buffer of exactly this length if there is one (an update loop asks for the same
        // sizes every time, so this is the common case and needs no fill), else the smallest
        // that can hold `len` without reallocating.
        let mut best: Option<usize> = self.free.iter().position(|b| b.len() == len);
        if best.is_none() {
            for (i, buf) in self.free.iter().enumerate() {
                if buf.capacity() >= len
                    && best.is_none_or(|b| buf.capacity() < self.free[b].capacity())
                {
                    best = Some(i);
                }
            }
        }
        match best {
            Some(i) => {
                let mut buf = self.free.swap_remove(i);
                buf.resize(len, 0.0);
                buf
            }
            None => vec![0.0; len],
        }
    }

    /// A [rows, cols] array with unspecified contents (see [`Pool::take`]).
    pub fn array(&mut self, rows: usize, cols: usize) -> Array2<f32> {
        Array2::from_shape_vec((rows, cols), self.take(rows * cols))
            .expect("pool buffer has exactly rows * cols elements")
    }

    /// A [rows, cols] array of zeros.
    pub fn zeros(&mut self, rows: usize, cols: usize) -> Array2<f32> {
        let mut a = self.array(rows, cols);
        a.fill(0.0);
        a
    }

    /// Give a buffer back for reuse.
    pub fn give(&mut self, buf: Vec<f32>) {
        if buf.capacity() > 0 {
            self.free.push(buf);
        }
    }

    /// Give an array's storage back for reuse.
    pub fn give_array(&mut self, a: Array2<f32>) {
        self.give(a.into_raw_vec_and_offset().0);
    }

    /// Total floats held (for tests that check memory stays bounded).
    pub fn floats_held(&self) -> usize {
        self.free.iter().map(Vec::capacity).sum()
    }

    /// Number of buffers held.
    pub fn buffers_held(&self) -> usize {
        self.free.len()
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
