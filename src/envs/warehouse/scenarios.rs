//! `docs/WAREHOUSE.md` §14: every scenario (values from the reference) and the S2 optimum, as tests.

// Trajectories are indexed by step number t, as in the spec's tables.
#![allow(clippy::needless_range_loop)]

use rand::SeedableRng;

use super::testkit::{o, run_policy, run_queues, Rec, SimplePolicy};
use super::Warehouse;
use crate::envs::{EnvError, EnvRng, MacroEnv};

fn ret(recs: &[Rec]) -> f64 {
    recs.iter().skip(1).map(|r| r.reward).sum()
}

/// Steps (t >= 1) at which agent `i`'s done flag is set, within `recs`.
fn done_steps(recs: &[Rec], i: usize) -> Vec<usize> {
    recs.iter()
        .skip(1)
        .filter(|r| r.mac_done[i])
        .map(|r| r.t)
        .collect()
}

fn nonstandard_rewards(recs: &[Rec]) -> Vec<(usize, f64)> {
    recs.iter()
        .skip(1)
        .filter(|r| r.reward != -1.0)
        .map(|r| (r.t, r.reward))
        .collect()
}

#[test]
fn s1_reset_observations_and_human() {
    let env = Warehouse::paper(150).unwrap();
    assert_eq!(env.obs(0), o("0001 0000 000 00"));
    assert_eq!(env.obs(1), o("0001 0000 000 00"));
    assert_eq!(env.obs(2), o("00 00"));
    assert_eq!((env.human().step_k, env.human().htl), (0, 18.0));
    assert_eq!(env.mac_done(), [true; 3]);
    assert_eq!(env.t(), 0);
}

/// S2's event table (`docs/WAREHOUSE.md` §14): step, executed, r, mac_done, T0/T1/Fetch obs after the
/// step (None = held from before), human step.
type Event = (
    usize,
    [usize; 3],
    f64,
    [u8; 3],
    Option<&'static str>,
    Option<&'static str>,
    Option<&'static str>,
    usize,
);

#[rustfmt::skip]
const S2_EVENTS: [Event; 16] = [
    (6,  [2, 2, 3], -1.0, [0, 0, 1], None, None, Some("10 11"), 0),
    (10, [2, 2, 2], -1.0, [0, 1, 1], None, Some("0010 0000 100 00"), Some("00 11"), 0),
    (16, [2, 0, 4], -1.0, [1, 0, 1], Some("0010 0000 000 10"), None, Some("10 10"), 0),
    (18, [2, 0, 1], 99.0, [0, 1, 0], None, Some("1000 0100 000 00"), None, 1),
    (20, [2, 2, 1], -1.0, [1, 0, 1], Some("0010 0000 010 00"), None, Some("00 10"), 1),
    (26, [0, 2, 5], -1.0, [0, 0, 1], None, None, Some("10 01"), 1),
    (29, [0, 2, 2], 99.0, [1, 0, 0], Some("1000 0100 000 00"), None, None, 1),
    (30, [0, 2, 2], -1.0, [1, 1, 1], Some("1000 0100 000 00"), Some("0010 0000 001 00"), Some("00 01"), 1),
    (31, [0, 0, 0], -1.0, [1, 0, 1], Some("1000 0100 000 00"), None, Some("00 00"), 1),
    (32, [0, 0, 0], -1.0, [1, 0, 1], Some("1000 0100 000 00"), None, Some("00 00"), 1),
    (33, [0, 0, 0], -1.0, [1, 0, 1], Some("1000 0100 000 00"), None, Some("00 00"), 1),
    (34, [0, 0, 0], -1.0, [1, 0, 1], Some("1000 0100 000 00"), None, Some("00 00"), 1),
    (35, [0, 0, 0], -1.0, [1, 0, 1], Some("1000 0100 000 00"), None, Some("00 00"), 1),
    (36, [0, 0, 0], -1.0, [1, 0, 1], Some("1000 0010 000 00"), None, Some("00 00"), 2),
    (37, [0, 0, 0], -1.0, [1, 0, 1], Some("1000 0010 000 00"), None, Some("00 00"), 2),
    (38, [0, 0, 0], 99.0, [1, 1, 1], Some("1000 0010 000 00"), Some("1000 0010 000 00"), Some("00 00"), 2),
];

#[test]
fn s2_scripted_plan_reaches_the_optimum_262_at_step_38() {
    let recs = run_queues(
        [&[2, 2, 0], &[2, 0, 2, 0], &[3, 2, 4, 1, 5, 2]],
        [0, 0, 0],
        150,
    );
    assert_eq!(recs.len() - 1, 38, "terminal at step 38");
    assert!(recs[38].done);
    assert!(recs[1..38].iter().all(|r| !r.done));
    assert_eq!(ret(&recs), 262.0);

    let events = &S2_EVENTS;
    for t in 1..=38 {
        let r = &recs[t];
        let prev = &recs[t - 1];
        match events.iter().find(|e| e.0 == t) {
            None => {
                assert_eq!(r.reward, -1.0, "step {t}");
                assert_eq!(r.mac_done, [false; 3], "step {t}");
                assert_eq!(r.obs, prev.obs, "step {t}: all held");
            }
            Some(&(_, exec, rew, md, t0, t1, f, hstep)) => {
                assert_eq!(r.executed, exec, "step {t} executed");
                assert_eq!(r.reward, rew, "step {t} reward");
                assert_eq!(r.mac_done, md.map(|b| b == 1), "step {t} mac_done");
                for (i, want) in [t0, t1, f].into_iter().enumerate() {
                    match want {
                        Some(s) => assert_eq!(r.obs[i], o(s), "step {t} agent {i} obs"),
                        None => assert_eq!(r.obs[i], prev.obs[i], "step {t} agent {i} held"),
                    }
                }
                assert_eq!(r.human.step_k, hstep, "step {t} human step");
            }
        }
    }
    // Timeline: T1 waits from step 5 (arrives at 4), T0 from step 6 (arrives at 5).
    assert_eq!(recs[4].tbs[1].tl, 0.0);
    assert_eq!(recs[5].tbs[1].tl, -1.0);
    assert_eq!(recs[5].tbs[0].tl, 0.0);
    assert_eq!(recs[16].tbs[0].tl, -1.0, "T0 times out at 16");
}

#[test]
fn s3_go_actions_finish_on_arrival_then_repeat_in_one_step() {
    let recs = run_queues([&[0], &[1], &[]], [0, 1, 0], 20);
    assert_eq!(done_steps(&recs, 1), (2..=20).collect::<Vec<_>>());
    assert_eq!(done_steps(&recs, 0), (6..=20).collect::<Vec<_>>());
    assert_eq!(done_steps(&recs, 2), (1..=20).collect::<Vec<_>>());
    assert_eq!(recs[2].obs[1], o("0100 0000 000 00"));
    assert_eq!(
        recs[6].obs[0],
        o("1000 1000 000 00"),
        "human step 0 seen at the workshop"
    );
    assert_eq!(
        recs[5].obs[0],
        o("0001 0000 000 00"),
        "held while travelling"
    );
    assert!(recs.iter().all(|r| r.obs[2] == o("00 00")));
    assert!(nonstandard_rewards(&recs).is_empty());
}

#[test]
fn s4_get_tool_times_out_after_eleven_waiting_steps() {
    let recs = run_queues([&[2], &[1], &[]], [1, 1, 0], 20);
    assert_eq!(recs[5].tbs[0].tl, 0.0);
    assert!(recs[5].tbs[0].at_table());
    for t in 6..=15 {
        assert_eq!(recs[t].tbs[0].tl, -((t - 5) as f64), "waiting step {t}");
        assert!(!recs[t].mac_done[0]);
    }
    assert!(recs[16].mac_done[0]);
    assert_eq!(recs[16].tbs[0].tl, -1.0);
    assert_eq!(recs[16].obs[0], o("0010 0000 000 00"));
    for t in 1..=4 {
        assert_eq!(recs[t].obs[2], o("00 00"), "step {t}");
    }
    for t in 5..=16 {
        assert_eq!(recs[t].obs[2], o("00 10"), "step {t}");
    }
    assert_eq!(recs[17].obs[2], o("00 00"), "T0 left with TR at 17");
    assert_eq!(recs[17].executed[0], 1);
}

#[test]
fn s5_searches_stage_tools_once_and_at_most_two() {
    let recs = run_queues([&[1], &[1], &[3, 3, 4, 5]], [1, 1, 0], 30);
    let fetch_done = done_steps(&recs, 2);
    assert_eq!(&fetch_done[..4], &[6, 12, 18, 24]);
    assert_eq!(fetch_done[4..], (25..=30).collect::<Vec<_>>());
    assert_eq!(recs[6].obs[2], o("10 00"));
    assert_eq!(recs[6].fetch.staged(), &[0]);
    assert_eq!(recs[12].obs[2], o("10 00"), "repeat search: no change");
    assert_eq!(recs[12].fetch.found_count, [1, 0, 0]);
    assert_eq!(recs[18].obs[2], o("01 00"));
    assert_eq!(recs[18].fetch.staged(), &[0, 1]);
    assert_eq!(recs[24].obs[2], o("01 00"), "full staging: no change");
    assert_eq!(recs[24].fetch.staged(), &[0, 1]);
    assert_eq!(recs[24].fetch.found_count, [1, 1, 0]);
    for i in 0..2 {
        assert_eq!(recs[5].obs[i], o("0100 0000 000 00"));
        assert_eq!(recs[6].obs[i], o("0100 0000 000 10"));
        assert_eq!(recs[17].obs[i], o("0100 0000 000 10"));
        assert_eq!(recs[18].obs[i], o("0100 0000 000 01"));
    }
}

#[test]
fn s6_pass_with_nobody_at_the_table_costs_ten() {
    let recs = run_queues([&[1], &[1], &[1]], [1, 1, 0], 8);
    assert_eq!(nonstandard_rewards(&recs), vec![(4, -11.0)]);
    assert!(!recs[1].mac_done[2] && !recs[2].mac_done[2] && !recs[3].mac_done[2]);
    assert!(recs[4].mac_done[2]);
    assert_eq!(recs[4].executed[2], 1);
}

#[test]
fn s7a_pass_started_on_the_arrival_step_fails() {
    let recs = run_queues([&[1], &[2], &[0, 0, 0, 2]], [1, 2, 0], 10);
    assert_eq!(recs[4].tbs[1].tl, 0.0, "T1 arrives at step 4");
    assert!(recs[4].tbs[1].at_table());
    assert_eq!(nonstandard_rewards(&recs), vec![(7, -11.0)]);
    assert!(!recs[7].mac_done[1], "T1 keeps waiting");
    assert_eq!(recs[7].tbs[1].tl, -3.0);
}

#[test]
fn s7b_pass_after_one_waiting_step_succeeds_with_empty_staging() {
    let recs = run_queues([&[1], &[2], &[0, 0, 0, 0, 2]], [1, 2, 0], 10);
    assert!(
        nonstandard_rewards(&recs).is_empty(),
        "no reward change (Q5)"
    );
    assert_eq!(done_steps(&recs, 1)[0], 8);
    assert_eq!(recs[8].obs[1], o("0010 0000 000 00"));
    assert_eq!(recs[8].tbs[1].tl, 0.0);
}

#[test]
fn s8_search_pass_deliver_late_by_one_step() {
    let recs = run_queues([&[2, 0], &[1], &[3, 1]], [0, 1, 0], 21);
    assert!(recs[5].tbs[0].at_table());
    assert!(recs[6].mac_done[2]);
    assert_eq!(recs[6].obs[2], o("10 10"));
    assert_eq!(done_steps(&recs, 0)[0], 10);
    assert_eq!(recs[10].obs[0], o("0010 0000 100 00"));
    for t in 11..=18 {
        assert!(!recs[t].mac_done[0], "WS under way at {t}");
    }
    assert_eq!(nonstandard_rewards(&recs), vec![(19, 99.0)]);
    assert!(recs[19].mac_done[0]);
    assert_eq!(recs[18].human.htl, 0.0);
    assert_eq!(recs[19].human.step_k, 1, "human advances at 19");
    assert_eq!(recs[19].obs[0], o("1000 0100 000 00"));
    assert_eq!(ret(&recs), 79.0);
}

#[test]
fn s9_wrong_tool_is_never_delivered() {
    let recs = run_queues([&[1], &[2, 0], &[4, 2]], [1, 0, 0], 150);
    assert_eq!(done_steps(&recs, 1)[0], 10);
    assert_eq!(recs[10].obs[1], o("0010 0000 010 00"));
    assert_eq!(done_steps(&recs, 1)[1..], (18..=150).collect::<Vec<_>>());
    assert_eq!(recs[18].obs[1], o("1000 1000 010 00"));
    assert!(nonstandard_rewards(&recs).is_empty());
    assert_eq!(recs[150].tbs[1].basket, [0.0, 1.0, 0.0]);
    assert_eq!(recs[150].human.htl, 18.0 - 150.0);
    assert!(recs[150].done);
}

#[test]
fn s10_horizon_ends_the_episode_and_further_steps_are_refused() {
    let mut env = Warehouse::paper(150).unwrap();
    let recs = run_policy(&mut env, 152, |_| [1, 1, 0]);
    assert_eq!(recs.len() - 1, 150);
    assert!(recs[1..150].iter().all(|r| !r.done && r.reward == -1.0));
    assert!(recs[150].done);
    assert_eq!(ret(&recs), -150.0);
    // The reference would return done = false at step 151 (Q2); this env refuses instead.
    let mut rng = EnvRng::seed_from_u64(0);
    assert_eq!(env.step(&[1, 1, 0], &mut rng), Err(EnvError::EpisodeOver));
    env.reset(&mut rng);
    assert_eq!(env.t(), 0);
    assert!(env.step(&[1, 1, 0], &mut rng).is_ok());
}

#[test]
fn s11_time_outs_coinciding_with_passes_and_queued_tool() {
    let recs = run_queues(
        [&[2, 2, 2, 0], &[2, 2, 0], &[3, 4, 2, 5, 1, 1]],
        [0, 0, 0],
        150,
    );
    assert_eq!(recs.len() - 1, 43);
    assert!(recs[43].done);
    assert_eq!(ret(&recs), 257.0);
    assert_eq!(
        nonstandard_rewards(&recs),
        vec![(24, 99.0), (39, 99.0), (43, 99.0)]
    );
    // T1 times out at 15, re-chooses GT at 16, and P1 (13..16) hands it tool 0 (FIFO).
    assert!(recs[15].mac_done[1]);
    assert_eq!(recs[15].tbs[1].tl, -1.0);
    assert_eq!(recs[16].executed[1], 2);
    assert!(recs[16].mac_done[1]);
    assert_eq!(recs[16].tbs[1].basket, [1.0, 0.0, 0.0]);
    assert_eq!((recs[24].human.step_k, recs[24].human.htl), (1, 18.0));
    // T0 times out at 26 in the step P0 completes and still gets tool 1.
    assert!(recs[26].mac_done[0]);
    assert_eq!(recs[26].tbs[0].basket, [0.0, 1.0, 0.0]);
    assert_eq!(recs[30].tbs[0].basket, [0.0, 1.0, 1.0]);
    assert!(recs[30].mac_done[0]);
    for t in 40..=42 {
        assert_eq!(recs[t].reward, -1.0);
    }
    assert_eq!(recs[41].human.step_k, 1);
    assert_eq!(recs[42].human.step_k, 2);
    assert_eq!(recs[42].obs[0], o("1000 0010 001 00"));
}

#[test]
fn s12_pass_completing_in_the_time_out_step_succeeds() {
    let recs = run_queues([&[2], &[1], &[3, 0, 0, 0, 0, 0, 0, 1]], [1, 1, 0], 20);
    assert_eq!(recs[16].executed[2], 1);
    assert!(recs[16].mac_done[0] && recs[16].mac_done[2]);
    assert_eq!(recs[16].obs[0], o("0010 0000 100 00"));
    assert!(nonstandard_rewards(&recs).is_empty());
}

#[test]
fn s13_out_of_range_actions_for_free_agents_are_rejected() {
    // The reference accepts -1 via Python negative indexing (Q11); this env refuses it and
    // leaves the state untouched.
    let mut env = Warehouse::paper(150).unwrap();
    let mut rng = EnvRng::seed_from_u64(0);
    let before = env.render_ascii();
    for (actions, agent, action, n) in [
        ([usize::MAX, 0, 0], 0, usize::MAX, 3),
        ([0, 3, 0], 1, 3, 3),
        ([0, 0, 6], 2, 6, 6),
    ] {
        assert_eq!(
            env.step(&actions, &mut rng),
            Err(EnvError::ActionOutOfRange {
                agent,
                action,
                n_actions: n
            })
        );
    }
    assert_eq!(
        env.step(&[0, 0], &mut rng),
        Err(EnvError::WrongActionCount {
            expected: 3,
            got: 2
        })
    );
    assert_eq!(env.t(), 0);
    assert_eq!(env.render_ascii(), before);
    // Busy agents' values are ignored, whatever they are.
    env.step(&[2, 2, 3], &mut rng).unwrap();
    let out = env.step(&[7, 9, 99], &mut rng).unwrap();
    assert_eq!(out.reward, -1.0);
    assert_eq!(env.executed(), [2, 2, 3]);
}

#[test]
fn simple_closed_loop_policy_returns_259_in_41_steps() {
    let mut env = Warehouse::paper(150).unwrap();
    let mut p = SimplePolicy {
        searches: 0,
        search_first: false,
    };
    let recs = run_policy(&mut env, 150, |e| p.act(e));
    assert_eq!(recs.len() - 1, 41);
    assert!(recs[41].done);
    assert_eq!(ret(&recs), 259.0);
    let deliveries: Vec<usize> = nonstandard_rewards(&recs).iter().map(|&(t, _)| t).collect();
    assert_eq!(deliveries, vec![19, 28, 41]);
}

#[test]
fn search_before_pass_policy_returns_243_in_47_steps() {
    let mut env = Warehouse::paper(150).unwrap();
    let mut p = SimplePolicy {
        searches: 0,
        search_first: true,
    };
    let recs = run_policy(&mut env, 150, |e| p.act(e));
    assert_eq!(recs.len() - 1, 47);
    assert_eq!(ret(&recs), 243.0);
    let failed = recs
        .iter()
        .filter(|r| r.reward == -11.0 || r.reward == 89.0)
        .count();
    assert_eq!(failed, 1, "one failed Pass");
}
