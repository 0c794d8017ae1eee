//! Stepping the Warehouse allocates nothing (issue 4): a counting global allocator watches
//! thousands of random steps, including resets and noisy travel. Its own test binary, so the
//! allocator sees no other test.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use macdec::envs::warehouse::{Warehouse, WarehouseParams};
use macdec::envs::{EnvRng, MacroEnv};
use rand::{Rng, SeedableRng};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn stepping_and_resetting_allocate_nothing() {
    for noise in [0.0, 0.1] {
        let mut env = Warehouse::new(WarehouseParams {
            tb_move_noisy: noise,
            ..WarehouseParams::default()
        })
        .unwrap();
        let mut rng = EnvRng::seed_from_u64(4);
        let mut actions = [0usize; 3];
        let mut joint = vec![0.0f32; env.joint_obs_size()];
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for _ in 0..20_000 {
            for (i, a) in actions.iter_mut().enumerate() {
                *a = rng.gen_range(0..env.n_actions()[i]);
            }
            let out = env.step(&actions, &mut rng).unwrap();
            env.write_joint_obs(&mut joint);
            if out.done {
                env.reset(&mut rng);
            }
        }
        assert_eq!(ALLOCATIONS.load(Ordering::SeqCst), before, "noise {noise}");
    }
}
