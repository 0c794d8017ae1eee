//! The hand-checkable scenarios of `docs/BOX_PUSHING.md` §14 (values from the reference),
//! the S9 macro-rewards of section 10, the optimum of section 11, and input errors.

use rand::SeedableRng;

use super::geometry::{Cell, Heading};
use super::state::Boxes;
use super::BoxPushing;
use crate::envs::{EnvError, EnvRng, MacroEnv};

const GAMMA: f64 = 0.98;
/// Value the scripts pass for a busy robot; the reference passes -1, any value must be ignored.
const BUSY: usize = usize::MAX;

const SB0: usize = 0;
const SB1: usize = 1;
const BB0: usize = 2;
const BB1: usize = 3;
const PUSH: usize = 4;
const T_L: usize = 5;
const T_R: usize = 6;
const STAY: usize = 7;

/// Everything observable after one step.
#[derive(Debug, Clone)]
struct Rec {
    executed: [usize; 2],
    reward: f64,
    done: bool,
    flags: [bool; 2],
    obs: [String; 2],
    cells: [Cell; 2],
    headings: [Heading; 2],
    boxes: Boxes,
    joint: bool,
}

impl Rec {
    fn cell(&self, i: usize) -> (i32, i32) {
        (self.cells[i].col, self.cells[i].row)
    }
}

fn bits(o: &[f32]) -> String {
    o.iter()
        .map(|&v| match v {
            0.0 => '0',
            1.0 => '1',
            _ => panic!("observation value {v} is not 0 or 1"),
        })
        .collect()
}

fn rng() -> EnvRng {
    EnvRng::seed_from_u64(0)
}

fn new_env(n: usize) -> BoxPushing {
    let horizon = if n == 30 { 200 } else { 100 };
    BoxPushing::new(n, horizon).unwrap()
}

/// Run queues of macro-actions (`docs/BOX_PUSHING.md` §14 conventions): a free robot takes its next queue entry, or
/// Stay when the queue is empty; a busy robot passes [`BUSY`]. Stops at done or `max_steps`.
/// `trace[k]` is step k+1.
fn run_queues_on(env: &mut BoxPushing, queues: [&[usize]; 2], max_steps: usize) -> Vec<Rec> {
    let mut rng = rng();
    let mut next = [0usize; 2];
    let mut trace = Vec::new();
    while trace.len() < max_steps {
        let mut actions = [BUSY; 2];
        for i in 0..2 {
            if env.is_free(i) {
                actions[i] = queues[i].get(next[i]).copied().unwrap_or(STAY);
                next[i] += 1;
            }
        }
        let out = env.step(&actions, &mut rng).unwrap();
        trace.push(Rec {
            executed: [env.executed()[0], env.executed()[1]],
            reward: out.reward,
            done: out.done,
            flags: [env.mac_done()[0], env.mac_done()[1]],
            obs: [bits(env.obs(0)), bits(env.obs(1))],
            cells: [env.robot(0).cell, env.robot(1).cell],
            headings: [env.robot(0).heading, env.robot(1).heading],
            boxes: *env.boxes(),
            joint: env.joint_push_active(),
        });
        if out.done {
            break;
        }
    }
    trace
}

fn run_queues(n: usize, queues: [&[usize]; 2], max_steps: usize) -> Vec<Rec> {
    run_queues_on(&mut new_env(n), queues, max_steps)
}

/// Evaluation return G = sum_k gamma^k r_{k+1} (`docs/BOX_PUSHING.md` §8).
fn discounted(trace: &[Rec]) -> f64 {
    let mut g = 0.0;
    let mut discount = 1.0;
    for rec in trace {
        g += discount * rec.reward;
        discount *= GAMMA;
    }
    g
}

fn assert_close(got: f64, want: f64) {
    assert!((got - want).abs() < 1e-9, "got {got}, want {want}");
}

/// Steps (1-based) at which robot `i`'s flag is set.
fn flag_steps(trace: &[Rec], i: usize) -> Vec<usize> {
    (0..trace.len())
        .filter(|&k| trace[k].flags[i])
        .map(|k| k + 1)
        .collect()
}

/// The runner's macro-rewards (`docs/BOX_PUSHING.md` §10): per robot, (step, r^c) at each of its flags, and the
/// joint (step, r^c) at each step where any flag is set.
#[allow(clippy::type_complexity)]
fn macro_rewards(trace: &[Rec]) -> ([Vec<(usize, f64)>; 2], Vec<(usize, f64)>) {
    let mut prev = [true; 2];
    let mut prev_joint = true;
    let mut acc = [0.0f64; 2];
    let mut acc_joint = 0.0;
    let mut per_robot = [Vec::new(), Vec::new()];
    let mut joint = Vec::new();
    for (k, rec) in trace.iter().enumerate() {
        for i in 0..2 {
            acc[i] = if prev[i] {
                rec.reward
            } else {
                acc[i] + rec.reward
            };
            if rec.flags[i] {
                per_robot[i].push((k + 1, acc[i]));
            }
        }
        acc_joint = if prev_joint {
            rec.reward
        } else {
            acc_joint + rec.reward
        };
        prev = rec.flags;
        prev_joint = rec.flags[0] || rec.flags[1];
        if prev_joint {
            joint.push((k + 1, acc_joint));
        }
    }
    (per_robot, joint)
}

fn assert_macro_rewards(got: &[(usize, f64)], want: &[(usize, f64)]) {
    assert_eq!(got.len(), want.len(), "got {got:?}, want {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert_eq!(g.0, w.0, "got {got:?}, want {want:?}");
        assert_close(g.1, w.1);
    }
}

#[test]
fn s1_reset_observations_are_empty_and_layout_is_standard() {
    let mut env = new_env(10);
    env.reset(&mut rng());
    assert_eq!(bits(env.obs(0)), "00100");
    assert_eq!(bits(env.obs(1)), "00100");
    assert_eq!(env.mac_done(), &[true, true]);
    assert_eq!(env.t(), 0);
    assert_eq!(env.robot(0).cell, Cell::new(1, 1));
    assert_eq!(env.robot(0).heading, Heading::East);
    assert_eq!(env.robot(1).cell, Cell::new(8, 1));
    assert_eq!(env.robot(1).heading, Heading::West);
    assert_eq!(env.boxes().small, [Cell::new(1, 5), Cell::new(8, 5)]);
    assert_eq!(env.boxes().big_left, Cell::new(4, 5));
}

#[test]
fn s2_full_trace_of_the_optimal_10x10_episode() {
    let trace = run_queues(10, [&[BB0, PUSH], &[BB1, PUSH]], 100);
    assert_eq!(trace.len(), 11);
    use Heading::{East as E, North as N, West as W};
    // (robot 0 cell, heading), (robot 1 cell, heading), big box row, flags.
    let expected = [
        ((2, 1), E, (7, 1), W, 5, false),
        ((3, 1), E, (6, 1), W, 5, false),
        ((4, 1), E, (5, 1), W, 5, false),
        ((4, 1), N, (5, 1), N, 5, false),
        ((4, 2), N, (5, 2), N, 5, false),
        ((4, 3), N, (5, 3), N, 5, false),
        ((4, 4), N, (5, 4), N, 5, true),
        ((4, 5), N, (5, 5), N, 6, false),
        ((4, 6), N, (5, 6), N, 7, false),
        ((4, 7), N, (5, 7), N, 8, false),
        ((4, 8), N, (5, 8), N, 9, true),
    ];
    for (k, (rec, e)) in trace.iter().zip(expected).enumerate() {
        let step = k + 1;
        assert_eq!(
            (rec.cell(0), rec.headings[0], rec.cell(1), rec.headings[1]),
            (e.0, e.1, e.2, e.3),
            "step {step}"
        );
        assert_eq!(rec.boxes.big_left.row, e.4, "step {step}");
        assert_eq!(rec.flags, [e.5, e.5], "step {step}");
        let executed = if step <= 7 { [BB0, BB1] } else { [PUSH, PUSH] };
        assert_eq!(rec.executed, executed, "step {step}");
        let reward = if step == 11 { 99.9 } else { -0.1 };
        assert_eq!(rec.reward, reward, "step {step}");
        assert_eq!(rec.done, step == 11, "step {step}");
        let obs = if step >= 7 { "01000" } else { "00100" };
        assert_eq!(rec.obs, [obs, obs], "step {step}");
    }
    assert!(!trace[6].joint);
    assert!(trace[7].joint);
    let (per_robot, joint) = macro_rewards(&trace);
    for r in &per_robot {
        assert_macro_rewards(r, &[(7, -0.7), (11, 99.6)]);
    }
    assert_macro_rewards(&joint, &[(7, -0.7), (11, 99.6)]);
    assert_close(discounted(&trace), 80.71093744250365);
}

#[test]
fn s2_remembered_waypoints_are_w2_and_w3_on_arrival() {
    let mut env = new_env(10);
    run_queues_on(&mut env, [&[BB0], &[BB1]], 7);
    assert_eq!(env.robot(0).waypoint, Some(2));
    assert_eq!(env.robot(1).waypoint, Some(3));
}

#[test]
fn s3_optimal_30x30_episode() {
    let trace = run_queues(30, [&[BB0, PUSH], &[BB1, PUSH]], 200);
    assert_eq!(trace.len(), 41);
    assert_eq!(flag_steps(&trace, 0), vec![27, 41]);
    assert_eq!(flag_steps(&trace, 1), vec![27, 41]);
    assert_eq!((trace[26].cell(0), trace[26].cell(1)), ((14, 14), (15, 14)));
    assert_eq!(trace[26].headings, [Heading::North, Heading::North]);
    assert_eq!(trace[40].reward, 99.9);
    assert!(trace[40].done);
    assert!(trace[..40].iter().all(|r| r.reward == -0.1 && !r.done));
    let (per_robot, _) = macro_rewards(&trace);
    for r in &per_robot {
        assert_macro_rewards(r, &[(27, -2.7), (41, 98.6)]);
    }
    assert_close(discounted(&trace), 41.75397237445474);
}

#[test]
fn s4_swapped_waypoints_still_allow_the_joint_push() {
    let trace = run_queues(10, [&[BB1, PUSH], &[BB0, PUSH]], 100);
    assert_eq!(flag_steps(&trace, 0), vec![8, 12]);
    assert_eq!(flag_steps(&trace, 1), vec![8, 12]);
    assert_eq!((trace[7].cell(0), trace[7].cell(1)), ((5, 4), (4, 4)));
    assert_eq!(trace.len(), 12);
    assert_eq!(trace[11].reward, 99.9);
    assert_close(discounted(&trace), 78.99671869365359);
}

#[test]
fn s5_same_waypoint_pushes_alone_and_never_jointly() {
    let trace = run_queues(10, [&[BB0, PUSH], &[BB0, PUSH]], 30);
    assert_eq!(trace[6].cell(0), (4, 4));
    assert_eq!(trace[6].flags, [true, false]);
    assert_eq!(trace[7].cell(1), (4, 4));
    assert_eq!(trace[7].reward, -5.1);
    assert_eq!(trace[7].flags, [true, true]);
    assert_eq!(trace[7].cell(0), (4, 4));
    assert_eq!(trace[8].executed, [STAY, PUSH]);
    assert_eq!(trace[8].reward, -5.1);
    assert!(trace[9..].iter().all(|r| r.reward == -0.1));
    assert!(trace.iter().all(|r| !r.joint));
}

#[test]
fn s6_both_remembering_w2_gives_a_double_penalty() {
    let trace = run_queues(10, [&[BB0, STAY, PUSH], &[BB0, PUSH]], 10);
    assert_eq!(trace[6].cell(0), (4, 4));
    assert_eq!(trace[7].executed, [STAY, BB0]);
    assert_eq!(trace[7].cell(1), (4, 4));
    let s9 = &trace[8];
    assert_eq!(s9.executed, [PUSH, PUSH]);
    assert_eq!(s9.reward, -10.1);
    assert_eq!(s9.flags, [true, true]);
    assert_eq!((s9.cell(0), s9.cell(1)), ((4, 4), (4, 4)));
    assert_eq!(s9.obs, ["01000", "01000"]);
    assert!(!s9.joint);
    assert_eq!(trace[9].executed, [STAY, STAY]);
    assert_close(discounted(&trace), -9.42226619138012);
}

#[test]
fn s7_robot_zero_delivers_small_box_zero() {
    let trace = run_queues(10, [&[SB0, PUSH], &[]], 100);
    assert_eq!(flag_steps(&trace, 0), vec![4, 8]);
    assert_eq!(trace[3].cell(0), (1, 4));
    assert_eq!(trace[3].headings[0], Heading::North);
    assert_eq!(trace[3].obs[0], "10000");
    let rows: Vec<i32> = trace[4..8].iter().map(|r| r.boxes.small[0].row).collect();
    assert_eq!(rows, vec![6, 7, 8, 9]);
    assert_eq!(trace.len(), 8);
    assert_eq!(trace[7].reward, 9.9);
    assert!(trace[7].done);
    let (per_robot, _) = macro_rewards(&trace);
    assert_macro_rewards(&per_robot[0], &[(4, -0.4), (8, 9.6)]);
    let mut robot1: Vec<(usize, f64)> = (1..8).map(|k| (k, -0.1)).collect();
    robot1.push((8, 9.9));
    assert_macro_rewards(&per_robot[1], &robot1);
    assert_close(discounted(&trace), 7.935070445376128);
}

#[test]
fn s8_push_from_the_start_after_turning_north_carries_the_box() {
    let trace = run_queues(10, [&[T_L, PUSH], &[]], 100);
    assert_eq!(trace[0].headings[0], Heading::North);
    assert!(trace[0].flags[0]);
    let cells: Vec<(i32, i32)> = trace[1..4].iter().map(|r| r.cell(0)).collect();
    assert_eq!(cells, vec![(1, 2), (1, 3), (1, 4)]);
    assert_eq!(trace[3].boxes.small[0].row, 5);
    assert_eq!(trace[4].boxes.small[0].row, 6);
    assert_eq!(trace.len(), 8);
    assert_eq!(trace[7].boxes.small[0].row, 9);
    assert_eq!(trace[7].reward, 9.9);
    assert_eq!(trace[7].cell(0), (1, 8));
    let (per_robot, _) = macro_rewards(&trace);
    assert_macro_rewards(&per_robot[0], &[(1, -0.1), (8, 9.3)]);
    assert_close(discounted(&trace), 7.935070445376128);
}

#[test]
fn s9_waiting_robots_and_section_10_macro_rewards() {
    let trace = run_queues(
        10,
        [&[BB0, STAY, STAY, PUSH], &[STAY, STAY, BB1, PUSH]],
        100,
    );
    assert_eq!(flag_steps(&trace, 0), vec![7, 8, 9, 13]);
    assert_eq!(flag_steps(&trace, 1), vec![1, 2, 9, 13]);
    assert!(trace[..9].iter().all(|r| !r.joint));
    assert!(trace[9..]
        .iter()
        .all(|r| r.joint && r.executed == [PUSH, PUSH]));
    assert_eq!(trace.len(), 13);
    assert_eq!(trace[12].reward, 99.9);
    let (per_robot, joint) = macro_rewards(&trace);
    assert_macro_rewards(
        &per_robot[0],
        &[(7, -0.7), (8, -0.1), (9, -0.1), (13, 99.6)],
    );
    assert_macro_rewards(
        &per_robot[1],
        &[(1, -0.1), (2, -0.1), (9, -0.7), (13, 99.6)],
    );
    assert_macro_rewards(
        &joint,
        &[
            (1, -0.1),
            (2, -0.1),
            (7, -0.5),
            (8, -0.1),
            (9, -0.1),
            (13, 99.6),
        ],
    );
    assert_close(discounted(&trace), 77.31678431978051);
}

#[test]
fn s10_both_small_boxes_arrive_together() {
    let trace = run_queues(10, [&[SB0, PUSH], &[SB1, PUSH]], 100);
    assert_eq!(trace[3].flags, [true, true]);
    assert_eq!(trace[3].obs, ["10000", "10000"]);
    assert_eq!(trace.len(), 8);
    assert_eq!(trace[7].reward, 19.9);
    assert!(trace[7].done);
    assert_close(discounted(&trace), 16.616325777843326);
}

#[test]
fn s10_counts_a_both_small_boxes_delivery() {
    let mut env = new_env(10);
    run_queues_on(&mut env, [&[SB0, PUSH], &[SB1, PUSH]], 100);
    env.reset(&mut rng());
    run_queues_on(&mut env, [&[SB0, PUSH], &[]], 100);
    let stats = env.delivery_stats();
    assert_eq!(
        (
            stats.single_small_box,
            stats.both_small_boxes,
            stats.big_box
        ),
        (1, 1, 0)
    );
}

#[test]
fn s11_pushing_the_big_box_alone_costs_five() {
    let trace = run_queues(10, [&[BB0, PUSH], &[]], 30);
    let s8 = &trace[7];
    assert_eq!(s8.reward, -5.1);
    assert_eq!(s8.cell(0), (4, 4));
    assert_eq!(s8.headings[0], Heading::North);
    assert!(s8.flags[0]);
    assert_eq!(s8.obs[0], "01000");
    assert_eq!(s8.boxes.big_left, Cell::new(4, 5));
    assert_close(discounted(&trace), -6.6132060693214);
}

#[test]
fn s12_arriving_at_the_edge_is_free_pushing_out_costs_five() {
    let trace = run_queues(10, [&[T_R, PUSH, PUSH], &[]], 12);
    assert_eq!(trace[0].headings[0], Heading::South);
    assert_eq!(trace[1].cell(0), (1, 0));
    assert!(trace[1].flags[0]);
    assert_eq!(trace[1].obs[0], "00010");
    assert_eq!(trace[1].reward, -0.1);
    assert_eq!(trace[2].reward, -5.1);
    assert_eq!(trace[2].cell(0), (1, 0));
    assert!(trace[2].flags[0]);
    assert_close(discounted(&trace), -5.878416381326);
}

#[test]
fn s13_push_walks_to_the_wall_and_the_teammate_is_seen() {
    let trace = run_queues(10, [&[PUSH], &[]], 12);
    let cells: Vec<(i32, i32)> = trace[..8].iter().map(|r| r.cell(0)).collect();
    let expected: Vec<(i32, i32)> = (2..=9).map(|c| (c, 1)).collect();
    assert_eq!(cells, expected);
    assert_eq!(flag_steps(&trace, 0)[0], 8);
    assert!(trace[..7].iter().all(|r| !r.flags[0]));
    assert_eq!(trace[7].obs[0], "00010");
    let (per_robot, _) = macro_rewards(&trace);
    assert_eq!(per_robot[0][0].0, 8);
    assert_close(per_robot[0][0].1, -0.8);
    assert_eq!(trace[5].obs[1], "00001");
    assert_eq!(trace[6].obs[1], "00100");
    assert_eq!(trace[7].obs[1], "00100");
    assert_close(discounted(&trace), -1.0764163813260);
}

#[test]
fn s14_push_east_turn_push_north_then_detour_to_w1() {
    let trace = run_queues(10, [&[PUSH, T_L, PUSH, SB1], &[]], 40);
    assert_eq!(flag_steps(&trace, 0)[..4], [8, 9, 17, 31]);
    assert_eq!(trace[7].cell(0), (9, 1));
    assert_eq!(trace[16].cell(0), (9, 9));
    assert_eq!(trace[16].obs[0], "00010");
    assert!(trace[17..30]
        .iter()
        .all(|r| r.executed[0] == SB1 && !r.flags[0]));
    assert_eq!(trace[30].cell(0), (8, 4));
    assert_eq!(trace[30].headings[0], Heading::North);
    assert_eq!(trace[30].obs[0], "10000");
    let (per_robot, _) = macro_rewards(&trace);
    assert_eq!(per_robot[0][3].0, 31);
    assert_close(per_robot[0][3].1, -1.4);
    assert_close(discounted(&trace), -2.7714979802452);
}

#[test]
fn s15_teleport_push_starts_away_from_the_waypoint() {
    let mut q1 = vec![BB1];
    q1.extend([STAY; 7]);
    q1.push(PUSH);
    let trace = run_queues(10, [&[BB0, T_R, PUSH, T_L, PUSH], &q1], 100);
    assert_eq!(trace[7].headings[0], Heading::East);
    assert_eq!(trace[7].obs[0], "00001");
    let cells: Vec<(i32, i32)> = trace[8..13].iter().map(|r| r.cell(0)).collect();
    assert_eq!(cells, vec![(5, 4), (6, 4), (7, 4), (8, 4), (9, 4)]);
    assert!(trace[12].flags[0] && !trace[11].flags[0]);
    assert_eq!(trace[12].obs[0], "00010");
    assert_eq!(trace[13].headings[0], Heading::North);
    assert_eq!(trace[13].obs[0], "00100");
    assert!(!trace[13].joint && trace[14].joint);
    let rows: Vec<i32> = trace[14..18].iter().map(|r| r.boxes.big_left.row).collect();
    assert_eq!(rows, vec![6, 7, 8, 9]);
    assert_eq!(trace.len(), 18);
    assert_eq!(trace[17].reward, 99.9);
    assert_eq!((trace[17].cell(0), trace[17].cell(1)), ((9, 8), (5, 8)));
    assert_close(discounted(&trace), 69.40785327234973);
}

#[test]
fn s16_move_to_the_current_waypoint_snaps_north() {
    let trace = run_queues(10, [&[BB0, T_R, BB0], &[]], 9);
    assert_eq!(trace[6].obs[0], "01000");
    assert_eq!(trace[7].headings[0], Heading::East);
    assert_eq!(trace[7].obs[0], "00100");
    assert_eq!(trace[8].executed[0], BB0);
    assert_eq!(trace[8].headings[0], Heading::North);
    assert!(trace[8].flags[0]);
    assert_eq!(trace[8].obs[0], "01000");
    assert_eq!(trace[8].cell(0), (4, 4));
}

#[test]
fn s17_staying_until_the_horizon() {
    for (n, horizon, g) in [(10, 100, -4.33690222052623), (30, 200, -4.912060266971386)] {
        let trace = run_queues(n, [&[], &[]], 1000);
        assert_eq!(trace.len(), horizon);
        assert!(trace
            .iter()
            .all(|r| r.reward == -0.1 && r.flags == [true, true]));
        assert!(trace.iter().all(|r| r.obs == ["00100", "00100"]));
        assert!(trace[..horizon - 1].iter().all(|r| !r.done));
        assert!(trace[horizon - 1].done);
        assert_close(discounted(&trace), g);
    }
}

#[test]
fn s18_small_box_on_30x30() {
    let trace = run_queues(30, [&[SB0, PUSH], &[]], 200);
    assert_eq!(trace[13].cell(0), (1, 14));
    assert_eq!(trace[13].headings[0], Heading::North);
    assert_eq!(trace[13].obs[0], "10000");
    assert_eq!(flag_steps(&trace, 0), vec![14, 28]);
    assert_eq!(trace.len(), 28);
    assert_eq!(trace[27].reward, 9.9);
    assert_close(discounted(&trace), 3.635556144546821);
}

/// The optimal joint policy of `docs/BOX_PUSHING.md` §11 as a state-feedback rule: each robot goes to its big-box
/// waypoint (robot 0 to W2, robot 1 to W3), then pushes.
fn optimal_policy(env: &BoxPushing, agent: usize) -> usize {
    if env.robot(agent).waypoint.is_none() {
        [BB0, BB1][agent]
    } else {
        PUSH
    }
}

fn optimal_return(n: usize, horizon: usize) -> (f64, usize) {
    let mut env = BoxPushing::new(n, horizon).unwrap();
    let mut rng = rng();
    env.reset(&mut rng);
    let (mut g, mut discount) = (0.0, 1.0);
    loop {
        let actions = [0, 1].map(|i| {
            if env.is_free(i) {
                optimal_policy(&env, i)
            } else {
                BUSY
            }
        });
        let out = env.step(&actions, &mut rng).unwrap();
        g += discount * out.reward;
        discount *= GAMMA;
        if out.done {
            return (g, env.t());
        }
    }
}

#[test]
fn optimal_policy_reproduces_g_star() {
    let (g10, t10) = optimal_return(10, 100);
    assert_eq!(t10, 11);
    assert_close(g10, 80.71093744250365);
    let (g30, t30) = optimal_return(30, 200);
    assert_eq!(t30, 41);
    assert_close(g30, 41.75397237445474);
}

#[test]
fn optimal_policy_takes_three_halves_n_minus_four_steps_on_any_grid() {
    // `docs/BOX_PUSHING.md` §11: T* = 3N/2 - 4 and G* = -0.1 (1 - g^(T*-1)) / (1 - g) + 99.9 g^(T*-1).
    for n in [8usize, 12, 16, 20, 40] {
        let (g, t) = optimal_return(n, 10 * n);
        let t_star = 3 * n / 2 - 4;
        assert_eq!(t, t_star, "n={n}");
        let d = GAMMA.powi(t_star as i32 - 1);
        assert_close(g, -0.1 * (1.0 - d) / (1.0 - GAMMA) + 99.9 * d);
    }
}

#[test]
fn out_of_range_action_for_a_free_robot_is_an_error_and_changes_nothing() {
    let mut env = new_env(10);
    let before = format!("{env:?}");
    let err = env.step(&[0, 8], &mut rng()).unwrap_err();
    assert_eq!(
        err,
        EnvError::ActionOutOfRange {
            agent: 1,
            action: 8,
            n_actions: 8
        }
    );
    assert_eq!(format!("{env:?}"), before);
}

#[test]
fn a_busy_robots_entry_is_ignored_whatever_its_value() {
    let mut env = new_env(10);
    let mut rng = rng();
    env.step(&[BB0, BB1], &mut rng).unwrap();
    assert!(!env.is_free(0) && !env.is_free(1));
    env.step(&[usize::MAX, 12345], &mut rng).unwrap();
    assert_eq!(env.executed(), &[BB0, BB1]);
}

#[test]
fn wrong_number_of_actions_is_an_error() {
    let mut env = new_env(10);
    let err = env.step(&[0, 1, 2], &mut rng()).unwrap_err();
    assert_eq!(
        err,
        EnvError::WrongActionCount {
            expected: 2,
            got: 3
        }
    );
}

#[test]
fn stepping_after_done_is_an_error_until_reset() {
    let mut env = BoxPushing::new(10, 3).unwrap();
    let mut rng = rng();
    for _ in 0..2 {
        assert!(!env.step(&[STAY, STAY], &mut rng).unwrap().done);
    }
    assert!(env.step(&[STAY, STAY], &mut rng).unwrap().done);
    assert_eq!(
        env.step(&[STAY, STAY], &mut rng).unwrap_err(),
        EnvError::EpisodeOver
    );
    env.reset(&mut rng);
    assert!(env.step(&[STAY, STAY], &mut rng).is_ok());
}

#[test]
fn reset_restores_the_start_and_the_reset_observation() {
    let mut env = new_env(10);
    run_queues_on(&mut env, [&[BB0, PUSH], &[BB1, PUSH]], 100);
    assert!(env.is_done());
    env.reset(&mut rng());
    let fresh = new_env(10);
    assert_eq!(env.robots, fresh.robots);
    assert_eq!(env.boxes, fresh.boxes);
    assert!(!env.joint_push_active());
    assert_eq!(env.t(), 0);
    assert_eq!(bits(env.obs(0)), "00100");
    assert_eq!(env.mac_done(), &[true, true]);
}

#[test]
fn reset_observation_is_empty_even_facing_a_box() {
    // Quirk Q8: the reset observation ignores the front cell; the first finished step sees it.
    let mut env = new_env(10);
    env.place_robot(0, Cell::new(1, 4), Heading::North);
    assert_eq!(bits(env.obs(0)), "00100");
    env.step(&[STAY, STAY], &mut rng()).unwrap();
    assert_eq!(bits(env.obs(0)), "10000");
}

#[test]
fn joint_push_from_rows_near_the_top_lifts_robots_out_of_the_grid() {
    // Quirk Q2: the latch looks at remembered waypoints and headings, not positions. Robot 0
    // remembers W2 but stands at (0,8); the push lifts it to row 12, above the 10x10 grid.
    let mut env = new_env(10);
    let mut rng = rng();
    env.robots[0].waypoint = Some(2);
    env.robots[1].waypoint = Some(3);
    env.place_robot(0, Cell::new(0, 8), Heading::North);
    env.place_robot(1, Cell::new(5, 4), Heading::North);
    for k in 1..=4 {
        let out = env.step(&[PUSH, PUSH], &mut rng).unwrap();
        assert_eq!(out.done, k == 4);
    }
    assert_eq!(env.robot(0).cell, Cell::new(0, 12));
    assert_eq!(env.boxes().big_left.row, 9);
    assert_eq!(bits(env.obs(0)), "00010");
}
