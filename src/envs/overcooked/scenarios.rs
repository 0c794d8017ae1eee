//! Scenarios with numbers from the reference (gym-macro-overcooked run under Python, see
//! `scripts/macromarl_traces.py`): chopping, wrong and correct deliveries, the horizon cut,
//! swaps and waits in the primitive step, A* tie-breaking, and the belief's quirks.

use rand::SeedableRng;

use super::astar::{navigate, PyHeap};
use super::layout::MapType;
use super::step::{primitive_step, Rewards};
use super::world::{Cell, Held, STAY};
use super::{Overcooked, OvercookedParams};
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};

fn kitchen(map: MapType, n_agent: usize, task: &str, horizon: usize) -> Overcooked {
    Overcooked::new(OvercookedParams {
        map,
        n_agent,
        task: task.into(),
        horizon,
        ..OvercookedParams::default()
    })
    .unwrap()
}

/// Run `plan` as the trace script's `--plan` does: each agent starts its list's macro-actions in
/// order whenever it is free, repeating the last one. Returns every step's outcome.
fn run_plan(env: &mut Overcooked, plan: &[&[usize]], steps: usize) -> Vec<StepOutcome> {
    let mut rng = EnvRng::seed_from_u64(0);
    env.reset(&mut rng);
    let mut started = vec![0; plan.len()];
    let mut outs = vec![];
    for _ in 0..steps {
        let actions: Vec<usize> = (0..plan.len())
            .map(|i| {
                if env.is_free(i) {
                    started[i] += 1;
                    plan[i][(started[i] - 1).min(plan[i].len() - 1)]
                } else {
                    0
                }
            })
            .collect();
        let out = env.step(&actions, &mut rng).unwrap();
        outs.push(out);
        if out.done {
            break;
        }
    }
    outs
}

fn rewards(outs: &[StepOutcome]) -> Vec<(usize, f64)> {
    outs.iter()
        .enumerate()
        .filter(|(_, o)| (o.reward - -0.1).abs() > 1e-9)
        .map(|(t, o)| (t + 1, o.reward))
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// Tomato salad, 2 agents: agent 1 hands the raw lettuce in (-5 at step 9, the lettuce goes back
/// to its counter); agent 0 chops the tomato (+10 at step 12), plates it and delivers it (+200,
/// terminal, at step 33). The reference's trace: return 201.7.
#[test]
fn a_wrong_delivery_then_the_tomato_salad() {
    let mut env = kitchen(MapType::A, 2, "tomato salad", 200);
    let outs = run_plan(&mut env, &[&[1, 6, 9, 4, 6, 8], &[2, 8, 10, 10, 0]], 200);
    let r = rewards(&outs);
    assert_eq!(r.len(), 3, "{r:?}");
    assert_eq!((r[0].0, r[1].0, r[2].0), (9, 12, 33));
    assert!(
        close(r[0].1, -5.1) && close(r[1].1, 9.9) && close(r[2].1, 199.9),
        "{r:?}"
    );
    let last = outs.last().unwrap();
    assert!(last.done && last.terminal() && !last.truncated);
    let total: f64 = outs.iter().map(|o| o.reward).sum();
    assert!((total - 201.7).abs() < 1e-9, "{total}");
    // The lettuce handed in went back, whole, to its start counter.
    let w = env.world();
    assert_eq!(w.foods[1].at, w.foods[1].start);
    assert!(!w.foods[1].chopped && w.foods[1].chops == 0);
    assert_eq!(w.delivery.holding, Some(Held::Plate(0)));
    let err = env
        .step(&[0, 0], &mut EnvRng::seed_from_u64(0))
        .unwrap_err();
    assert_eq!(err, EnvError::EpisodeOver);
}

/// The full salad with 3 agents: +10 for each of the three vegetables (steps 11, 12, 35) and
/// +200 at step 49 (the reference's return 225.1).
#[test]
fn three_chopped_vegetables_and_the_salad() {
    let mut env = kitchen(MapType::A, 3, "lettuce-onion-tomato salad", 200);
    let zeros = [0usize; 12];
    let a0: Vec<usize> = [1, 6, 9, 4, 6, 7]
        .iter()
        .chain(&zeros)
        .chain(&[6, 8])
        .copied()
        .collect();
    let a2: Vec<usize> = [3]
        .iter()
        .chain(&zeros)
        .chain(&[0, 0, 0, 0, 0, 6, 9, 10, 10, 0])
        .copied()
        .collect();
    let outs = run_plan(&mut env, &[&a0, &[2, 7, 9, 11, 10, 10, 0], &a2], 200);
    let r = rewards(&outs);
    let steps: Vec<usize> = r.iter().map(|x| x.0).collect();
    assert_eq!(steps, [11, 12, 35, 49]);
    assert!(outs.last().unwrap().terminal());
    let total: f64 = outs.iter().map(|o| o.reward).sum();
    assert!((total - 225.1).abs() < 1e-9, "{total}");
}

/// A food of another dish chopped through earns nothing: the lettuce in the tomato salad.
#[test]
fn chopping_a_food_the_task_does_not_need_earns_nothing() {
    let mut env = kitchen(MapType::A, 2, "tomato salad", 200);
    // Agent 1 takes the lettuce to knife 2 and chops it; agent 0 stays.
    let outs = run_plan(&mut env, &[&[0], &[2, 7, 9, 0]], 40);
    assert!(env.world().foods[1].chopped);
    assert!(rewards(&outs).is_empty(), "{:?}", rewards(&outs));
}

/// No terminal within the horizon: the last step is done and truncated (the runner's cut).
#[test]
fn the_horizon_cuts_without_a_terminal() {
    let mut env = kitchen(MapType::B, 3, "lettuce-onion-tomato salad", 5);
    let outs = run_plan(&mut env, &[&[0], &[0], &[0]], 10);
    assert_eq!(outs.len(), 5);
    assert!(outs[..4].iter().all(|o| !o.done));
    assert!(outs[4].done && outs[4].truncated && !outs[4].terminal());
}

/// Primitive step: two agents walking into each other swap; an agent walking into one that
/// leaves follows it in the next pass; one walking into an agent that stays does not move.
#[test]
fn agents_swap_follow_and_block() {
    let env = kitchen(MapType::A, 3, "tomato salad", 10);
    let r = Rewards::default();
    // Agents at (1,2), (1,4), (5,2). Put agent 1 at (1,3), beside agent 0.
    let mut w = env.world().clone();
    w.set_tile(Cell::new(1, 4), super::layout::Tile::Space);
    w.cooks[1].at = Cell::new(1, 3);
    w.set_tile(Cell::new(1, 3), super::layout::Tile::Agent);
    let mut swap = w.clone();
    primitive_step(&mut swap, &[0, 2, STAY], "tomato salad", &r); // 0 right, 1 left
    assert_eq!(
        (swap.cooks[0].at, swap.cooks[1].at),
        (Cell::new(1, 3), Cell::new(1, 2))
    );
    let mut follow = w.clone();
    primitive_step(&mut follow, &[0, 1, STAY], "tomato salad", &r); // 0 right, 1 down
    assert_eq!(
        (follow.cooks[0].at, follow.cooks[1].at),
        (Cell::new(1, 3), Cell::new(2, 3))
    );
    let mut block = w.clone();
    primitive_step(&mut block, &[0, STAY, STAY], "tomato salad", &r);
    assert_eq!(
        (block.cooks[0].at, block.cooks[1].at),
        (Cell::new(1, 2), Cell::new(1, 3))
    );
    // Agent 1 (later in the order) walks into agent 0, who leaves: agent 1 follows at once.
    let mut chase = w.clone();
    primitive_step(&mut chase, &[1, 2, STAY], "tomato salad", &r); // 0 down, 1 left
    assert_eq!(
        (chase.cooks[0].at, chase.cooks[1].at),
        (Cell::new(2, 2), Cell::new(1, 2))
    );
}

/// The reference's `_navigate` from each agent's reset belief to every cell of the 7 x 7 maps
/// (`x`-major, the first move: 0 right, 1 down, 2 left, 3 up, 4 stay), printed by running it.
/// Equal-cost paths are common here, so these pin heapq's tie-breaking.
const PY_ASTAR: [(MapType, [&str; 3]); 3] = [
    (
        MapType::A,
        [
            "4230004224000011111111111111111111111111114111114",
            "4222304222240011111111111111111111111111114111114",
            "4333334333333333333333333333333333322400004210004",
        ],
    ),
    (
        MapType::B,
        [
            "4234444224044411114441111444111144411114444114444",
            "4444304444240044411114441111444111144411114444114",
            "4334444333344433334443333444333344422404444214444",
        ],
    ),
    (
        MapType::C,
        [
            "4234114224011111111111111111111111111111114111114",
            "4114304111240011111111111111111111111111114111114",
            "4334004333300033330003333000333300022400004210004",
        ],
    ),
];

#[test]
fn a_star_breaks_ties_as_the_reference() {
    let mut heap = PyHeap::default();
    for (map, rows) in PY_ASTAR {
        let env = kitchen(map, 3, "tomato salad", 10);
        for (i, expected) in rows.iter().enumerate() {
            let from = env.world().cooks[i].at;
            let ours: String = (0..49)
                .map(|k| {
                    let target = Cell::new(k / 7, k % 7);
                    let a = navigate(&env.belief(i).pomap, 7, from, target, &mut heap);
                    char::from(b'0' + a)
                })
                .collect();
            assert_eq!(&ours, expected, "map {map:?} agent {i}");
        }
    }
}

/// The belief keeps a food's chop progress while it is out of view, but divides the stored
/// fraction by 3 again at every step (the reference divides `agent.obs[idx]`, a fraction, by
/// `required_chopped_times`). Agent 1 last sees the tomato on knife 1 at step 10 (1/3 chopped);
/// at step 12 it is chopped through, and agent 1 believes 1/27 (the reference prints
/// 0.037037037037037035).
#[test]
fn remembered_chop_progress_shrinks_out_of_view() {
    let mut env = kitchen(MapType::A, 2, "tomato salad", 200);
    run_plan(&mut env, &[&[1, 6, 9, 0], &[2, 8, 10, 10, 0]], 12);
    assert!(env.world().foods[0].chopped);
    assert_eq!(env.belief(0).obs[2], 1.0);
    assert_eq!(env.belief(1).obs[2], 1.0 / 3.0 / 3.0 / 3.0);
    assert_eq!(env.belief(1).obs[2], 0.037037037037037035);
}
