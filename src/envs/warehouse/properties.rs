//! Property tests over many seeded random episodes, and the noisy mode's reproducibility.

// Trajectories are indexed by step number t, as in the spec's tables.
#![allow(clippy::needless_range_loop)]

use rand::{Rng, RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::testkit::{SimplePolicy, BUSY};
use super::{Warehouse, WarehouseParams, WAYPOINTS};
use crate::envs::{EnvRng, MacroEnv};

/// The per-step rewards that can occur (`docs/WAREHOUSE.md` §10).
const REWARDS: [f64; 4] = [-1.0, 99.0, -11.0, 89.0];

/// Joint action: the simple policy, each free agent's choice replaced by a uniform one with
/// probability `eps` (so episodes both wander and reach deliveries).
fn mixed_action(
    env: &Warehouse,
    p: &mut SimplePolicy,
    eps: f64,
    rng: &mut ChaCha8Rng,
) -> [usize; 3] {
    let mut a = p.act(env);
    for (i, n) in env.n_actions().iter().enumerate() {
        if env.is_free(i) && rng.gen_bool(eps) {
            a[i] = rng.gen_range(0..*n);
        } else if !env.is_free(i) {
            a[i] = BUSY;
        }
    }
    a
}

fn check_turtlebot_obs(env: &Warehouse, i: usize) {
    let ob = env.obs(i);
    assert!(ob.iter().all(|&v| v == 0.0 || v == 1.0), "{ob:?}");
    assert_eq!(ob[0..4].iter().sum::<f32>(), 1.0, "one location: {ob:?}");
    let at_ws = ob[0] == 1.0;
    let human: f32 = ob[4..8].iter().sum();
    assert_eq!(
        human,
        if at_ws { 1.0 } else { 0.0 },
        "human step only at the workshop"
    );
    let ready: f32 = ob[11..13].iter().sum();
    assert!(ready <= 1.0);
    if at_ws {
        assert_eq!(ready, 0.0, "no ready signal at the workshop");
    }
    if env.mac_done()[i] {
        // Freshly computed: it matches the state.
        let tb = env.turtlebot(i);
        assert_eq!(ob[tb.loc.unwrap_or(3)], 1.0);
        for t in 0..3 {
            assert_eq!(f64::from(ob[8 + t]), tb.basket[t]);
        }
    }
}

fn check_fetch(env: &Warehouse) {
    let ob = env.obs(2);
    assert!(ob.iter().all(|&v| v == 0.0 || v == 1.0), "{ob:?}");
    assert!(ob[0] + ob[1] <= 1.0);
    let f = env.fetch();
    let want = match f.staged().len() {
        0 => [0.0, 0.0],
        1 => [1.0, 0.0],
        _ => [0.0, 1.0],
    };
    assert_eq!(f.ready, want, "ready encodes the staging size");
    if env.mac_done()[2] {
        assert_eq!(ob[2] == 1.0, env.turtlebot(0).at_table());
        assert_eq!(ob[3] == 1.0, env.turtlebot(1).at_table());
    }
}

/// Each tool is in exactly one place once found: staging, a basket, or delivered.
fn check_tool_conservation(env: &Warehouse, deliveries: usize) {
    let f = env.fetch();
    for tool in 0..3 {
        assert!(f.found_count[tool] <= 1);
        let staged = f.staged().iter().filter(|&&t| t == tool).count() as f64;
        let carried = env.turtlebot(0).basket[tool] + env.turtlebot(1).basket[tool];
        let delivered = if tool < deliveries { 1.0 } else { 0.0 };
        assert_eq!(
            staged + carried + delivered,
            f.found_count[tool] as f64,
            "tool {tool}"
        );
    }
}

#[test]
fn random_episodes_keep_every_invariant() {
    let mut rng = ChaCha8Rng::seed_from_u64(2020);
    let mut env_rng = EnvRng::seed_from_u64(1);
    let mut env = Warehouse::paper(150).unwrap();
    let mut seen = [false; 4];
    let mut terminal_episodes = 0;
    for episode in 0..3000 {
        let eps = [1.0, 0.5, 0.2, 0.05][episode % 4];
        let mut policy = SimplePolicy {
            searches: 0,
            search_first: episode % 2 == 0,
        };
        env.reset(&mut env_rng);
        let (mut ret, mut deliveries) = (0.0, 0);
        loop {
            let prev_obs: Vec<Vec<f32>> = (0..3).map(|i| env.obs(i).to_vec()).collect();
            let prev_exec = env.executed().to_vec();
            let was_free: Vec<bool> = (0..3).map(|i| env.is_free(i)).collect();
            let a = mixed_action(&env, &mut policy, eps, &mut rng);
            let out = env.step(&a, &mut env_rng).unwrap();
            let k = REWARDS.iter().position(|&r| r == out.reward);
            seen[k.unwrap_or_else(|| panic!("reward {} not in {REWARDS:?}", out.reward))] = true;
            ret += out.reward;
            if out.reward > 0.0 {
                deliveries += 1;
            }
            for i in 0..3 {
                if was_free[i] {
                    assert_eq!(env.executed()[i], a[i]);
                } else {
                    assert_eq!(
                        env.executed()[i],
                        prev_exec[i],
                        "busy agent keeps its action"
                    );
                }
                if !env.mac_done()[i] {
                    assert_eq!(env.obs(i), prev_obs[i], "held observation");
                }
            }
            check_turtlebot_obs(&env, 0);
            check_turtlebot_obs(&env, 1);
            check_fetch(&env);
            check_tool_conservation(&env, deliveries);
            for i in 0..2 {
                let tb = env.turtlebot(i);
                if tb.done {
                    assert!(WAYPOINTS[i].contains(&tb.pos), "free only at a waypoint");
                }
                assert!(tb.tl >= -11.0);
            }
            assert!(env.t() <= 150);
            assert_eq!(out.done, deliveries == 3 || env.t() == 150, "t {}", env.t());
            if out.done {
                break;
            }
        }
        assert!(ret <= 262.0, "return {ret} above the optimum");
        if deliveries == 3 {
            terminal_episodes += 1;
            assert!(env.t() >= 38);
        }
    }
    assert_eq!(seen, [true; 4], "every reward value occurred");
    assert!(
        terminal_episodes > 100,
        "only {terminal_episodes} terminal episodes"
    );
}

#[test]
fn paper_settings_draw_nothing_and_ignore_the_seed() {
    let run = |seed: u64| {
        let mut env = Warehouse::paper(150).unwrap();
        let mut env_rng = EnvRng::seed_from_u64(seed);
        let mut policy_rng = ChaCha8Rng::seed_from_u64(5);
        let mut trace = Vec::new();
        env.reset(&mut env_rng);
        for _ in 0..150 {
            let a = [0, 1, 2].map(|i| policy_rng.gen_range(0..env.n_actions()[i]));
            let out = env.step(&a, &mut env_rng).unwrap();
            trace.push((out.reward, env.turtlebot(0).pos, env.turtlebot(1).pos));
            if out.done {
                break;
            }
        }
        (
            trace,
            env_rng.next_u64(),
            EnvRng::seed_from_u64(seed).next_u64(),
        )
    };
    let (a, after_a, fresh_a) = run(1);
    let (b, _, _) = run(2);
    assert_eq!(a, b);
    assert_eq!(after_a, fresh_a, "no draws consumed with zero noise");
}

fn noisy_trace(seed: u64, std: f64) -> Vec<(f64, [u64; 4], Vec<f32>)> {
    let mut env = Warehouse::new(WarehouseParams {
        tb_move_noisy: std,
        ..WarehouseParams::default()
    })
    .unwrap();
    let mut env_rng = EnvRng::seed_from_u64(seed);
    let mut policy_rng = ChaCha8Rng::seed_from_u64(99);
    let mut trace = Vec::new();
    for _ in 0..5 {
        env.reset(&mut env_rng);
        loop {
            let a = [0, 1, 2].map(|i| policy_rng.gen_range(0..env.n_actions()[i]));
            let out = env.step(&a, &mut env_rng).unwrap();
            assert!(REWARDS.contains(&out.reward));
            let p = [env.turtlebot(0).pos, env.turtlebot(1).pos];
            let bits = [p[0][0], p[0][1], p[1][0], p[1][1]].map(f64::to_bits);
            let mut obs = Vec::new();
            let mut joint = vec![0.0; env.joint_obs_size()];
            env.write_joint_obs(&mut joint);
            obs.extend(joint);
            trace.push((out.reward, bits, obs));
            if out.done {
                break;
            }
        }
    }
    trace
}

#[test]
fn noisy_runs_repeat_with_the_same_seed_and_differ_across_seeds() {
    let a = noisy_trace(7, 0.1);
    assert_eq!(a, noisy_trace(7, 0.1));
    let b = noisy_trace(8, 0.1);
    assert_ne!(
        a.iter().map(|s| s.1).collect::<Vec<_>>(),
        b.iter().map(|s| s.1).collect::<Vec<_>>()
    );
}

#[test]
fn noise_draws_x_then_y_for_t0_then_t1() {
    let std = 0.05;
    let mut env = Warehouse::new(WarehouseParams {
        tb_move_noisy: std,
        ..WarehouseParams::default()
    })
    .unwrap();
    let mut env_rng = EnvRng::seed_from_u64(3);
    let mut oracle = env_rng.clone();
    let normal = Normal::new(0.0, std).unwrap();
    let z: Vec<f64> = (0..4).map(|_| normal.sample(&mut oracle)).collect();
    // Both drive to the workshop from their starts: both travel, so four draws.
    env.step(&[0, 0, 0], &mut env_rng).unwrap();
    for (i, start) in super::TURTLEBOT_STARTS.iter().enumerate() {
        let (gx, gy) = (6.0 - start[0], 3.0 - start[1]);
        let d = super::round2((gx * gx + gy * gy).sqrt());
        let want = [
            start[0] + (0.6 / d * gx + z[2 * i]),
            start[1] + (0.6 / d * gy + z[2 * i + 1]),
        ];
        assert_eq!(env.turtlebot(i).pos, want, "Turtlebot {i}");
    }
    assert_eq!(env_rng.next_u64(), oracle.next_u64(), "exactly four draws");
}

#[test]
fn noisy_robots_still_snap_onto_waypoints() {
    let mut env = Warehouse::new(WarehouseParams {
        tb_move_noisy: 0.2,
        ..WarehouseParams::default()
    })
    .unwrap();
    let mut env_rng = EnvRng::seed_from_u64(11);
    let mut policy_rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..200 {
        env.reset(&mut env_rng);
        loop {
            let a = [0, 1, 2].map(|i| policy_rng.gen_range(0..env.n_actions()[i]));
            let out = env.step(&a, &mut env_rng).unwrap();
            for i in 0..2 {
                if env.turtlebot(i).done {
                    assert!(WAYPOINTS[i].contains(&env.turtlebot(i).pos));
                }
            }
            check_fetch(&env);
            if out.done {
                assert!(env.t() <= 150);
                break;
            }
        }
    }
}
