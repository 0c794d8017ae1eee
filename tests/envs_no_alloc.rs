//! Stepping allocates nothing (issue 4): count heap allocations made while stepping environments
//! with random macro-actions. One test per binary, so no other thread allocates meanwhile.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

use macdec::envs::bench::random_macro_steps;
use macdec::envs::{EnvRng, EnvSpec};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn stepping_and_resetting_allocate_nothing() {
    let specs = [
        EnvSpec::BoxPushing {
            grid: 10,
            horizon: 100,
        },
        EnvSpec::BoxPushing {
            grid: 30,
            horizon: 200,
        },
    ];
    for spec in specs {
        let mut env = spec.build().unwrap();
        let mut policy_rng = ChaCha8Rng::seed_from_u64(3);
        let mut env_rng = EnvRng::seed_from_u64(4);
        // Warm up, then count: `random_macro_steps` allocates its action buffers once per call,
        // so the count over a long run must equal the count over a short one.
        let before_short = ALLOCATIONS.load(Ordering::Relaxed);
        random_macro_steps(&mut env, 10, &mut policy_rng, &mut env_rng).unwrap();
        let short = ALLOCATIONS.load(Ordering::Relaxed) - before_short;
        let before_long = ALLOCATIONS.load(Ordering::Relaxed);
        random_macro_steps(&mut env, 200_000, &mut policy_rng, &mut env_rng).unwrap();
        let long = ALLOCATIONS.load(Ordering::Relaxed) - before_long;
        assert_eq!(
            long, short,
            "{spec:?}: allocations grew with the number of steps"
        );
    }
}
