//! Loading a sampled batch's records ahead of the squeeze.
//!
//! A batch (64 windows of up to 10 records in the published settings) is drawn at random from a
//! replay memory of tens of megabytes, and each [`Step`] keeps its fields in separate heap
//! blocks, so reading a record is two cache misses in a row (the record, then the block it points
//! to). The squeeze tests `valid[i]` and branches on it before it reads the next record, which
//! leaves the CPU waiting for one miss at a time: `perf annotate` put more than half of
//! `Squeezed::of` on that test. Asking for every line first, with prefetches that neither branch
//! nor wait, lets the misses overlap. Nothing is computed, so no number depends on it.

use super::episode::Step;

/// Bytes per cache line on the CPUs this targets (x86-64).
const LINE: usize = 64;

/// Asks the CPU to bring every record of `batch` and the heap blocks the update reads (the
/// observations, actions, rewards, gammas, next availability and `valid`) into its caches. A hint
/// only: on CPUs other than x86-64 it does nothing.
pub fn prefetch_batch(batch: &[&[Step]]) {
    // The records first: a window's records are contiguous, so every line of its byte range
    // (a record straddles up to four lines).
    for seq in batch {
        let (start, bytes) = (seq.as_ptr() as *const u8, std::mem::size_of_val(*seq));
        let first_line = start as usize % LINE;
        for offset in (0..first_line + bytes).step_by(LINE) {
            prefetch(start.wrapping_sub(first_line).wrapping_add(offset));
        }
    }
    // Then the blocks they point to; reading the pointers waits for no branch, so these loads
    // overlap too.
    for seq in batch {
        for r in seq.iter() {
            prefetch(r.valid.as_ptr() as *const u8);
            prefetch(r.obs.as_ptr() as *const u8);
            prefetch(r.next_obs.as_ptr() as *const u8);
            prefetch(r.next_avail.as_ptr() as *const u8);
            prefetch(r.actions.as_ptr() as *const u8);
            prefetch(r.rewards.as_ptr() as *const u8);
            prefetch(r.gammas.as_ptr() as *const u8);
        }
    }
}

/// A prefetch of the line holding `p` into every cache level.
#[inline(always)]
fn prefetch(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint that never faults and never changes memory, whatever the
    // address (a dangling pointer of an empty Vec included); SSE is part of x86-64.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(p as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
