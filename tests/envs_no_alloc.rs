//! Stepping allocates nothing (issues 4, 27): a counting global allocator watches the test
//! thread while it steps every domain with random macro-actions, resets included. Only
//! allocations made on the test's own thread are counted, so the test harness cannot disturb
//! the count.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use macdec::envs::bench::random_macro_steps;
use macdec::envs::{EnvRng, EnvSpec};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn note_allocation() {
    if COUNTING.with(Cell::get) {
        ALLOCATIONS.with(|n| n.set(n.get() + 1));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note_allocation();
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note_allocation();
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made on this thread while `f` runs.
fn allocations_during(f: impl FnOnce()) -> u64 {
    ALLOCATIONS.with(|n| n.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.with(Cell::get)
}

#[test]
fn stepping_and_resetting_allocate_nothing() {
    let mut specs = vec![
        macdec::envs::box_pushing::spec(10, 100),
        macdec::envs::box_pushing::spec(30, 200),
        macdec::envs::warehouse::spec(150, 0.0),
        macdec::envs::warehouse::spec(150, 0.1),
        macdec::envs::bp_ma_v0::spec(6, 100),
    ];
    // MacroMARL's Warehouse A-E at the published settings and with both noise sources on.
    let noisy = toml::toml! { TB_move_noisy = 0.1  fetch_manip_noisy = 1.0  obs_human_wait = true };
    for id in ["OSD-D-v7", "OSD-T-v0", "OSD-T-v1", "OSD-F-v0"] {
        specs.push(EnvSpec::new(id, &toml::Table::new()).unwrap());
        specs.push(EnvSpec::new(id, &noisy).unwrap());
    }
    // Overcooked's maps A-C with 2 and 3 agents, both grid sizes.
    for map in ["A", "B", "C"] {
        for (n_agent, side) in [(2, 7), (3, 7), (3, 9)] {
            let mut keys = toml::Table::new();
            keys.insert("map_type".into(), map.into());
            keys.insert("n_agent".into(), n_agent.into());
            keys.insert("grid_dim".into(), vec![side, side].into());
            specs.push(EnvSpec::new("Overcooked-MA-v1", &keys).unwrap());
        }
    }
    // ACAC's copy, fixed and random starts (drawn from the run's stream at every reset).
    for rand_start in [false, true] {
        let keys = toml::toml! { map_type = "B" };
        let mut keys = keys.clone();
        keys.insert("rand_start".into(), rand_start.into());
        specs.push(EnvSpec::new("ACAC-Overcooked-MA-v1", &keys).unwrap());
    }
    // ACAC's Overcooked-Large, maps A-C, and map B's random starts.
    for (map, rand_start) in [("A", false), ("B", false), ("C", false), ("B", true)] {
        let mut keys = toml::Table::new();
        keys.insert("map_type".into(), map.into());
        keys.insert("rand_start".into(), rand_start.into());
        specs.push(EnvSpec::new("ACAC-Overcooked-MA-v0", &keys).unwrap());
    }
    for spec in specs {
        let mut env = spec.build().unwrap();
        let mut policy_rng = ChaCha8Rng::seed_from_u64(3);
        let mut env_rng = EnvRng::seed_from_u64(4);
        // `random_macro_steps` allocates its action buffers once per call, so the count over a
        // long run must equal the count over a short one.
        let short = allocations_during(|| {
            random_macro_steps(&mut env, 10, &mut policy_rng, &mut env_rng).unwrap();
        });
        let long = allocations_during(|| {
            random_macro_steps(&mut env, 200_000, &mut policy_rng, &mut env_rng).unwrap();
        });
        assert_eq!(
            long, short,
            "{spec:?}: allocations grew with the number of steps"
        );
        // The counter does see allocations (the test can fail).
        assert!(allocations_during(|| drop(vec![0u8; 16])) >= 1);
    }
}
