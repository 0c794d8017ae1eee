//! Scenarios worked out by hand from the reference code (step numbers are primitive steps
//! after reset), a scripted team that serves every human, and properties of random episodes.

use rand::{Rng, SeedableRng};

use super::*;
use crate::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};

/// OSD-D-v7 with the published settings, `changes` applied.
fn d7(changes: impl FnOnce(&mut OsdParams)) -> OsdD7 {
    let mut p = OsdParams::published(OsdD7::layout());
    changes(&mut p);
    OsdD7::new(p).unwrap()
}

/// Step `env` with `actions` (busy agents' entries ignored) and return the outcome.
fn step<E: MacroEnv>(env: &mut E, actions: &[usize]) -> StepOutcome {
    env.step(actions, &mut EnvRng::seed_from_u64(0)).unwrap()
}

/// D7 action indices.
const GO_WA0: usize = 0;
const GET_TOOL: usize = 3;
const WAIT: usize = 0;
const PASS_T0: usize = 1;
const LOOK0: usize = 3;

/// Turtlebot 0 fetches tool 0 (Fetch: Look0 at steps 1-6, Pass_T0 at 7-10 while Turtlebot 0
/// waits at its table from step 4), then drives the 4.85 m to human 0 (six moves of 0.8 m,
/// 0.05 m left): it arrives at step 17. Returns the rewards of steps 1..=17 (checked against
/// the reference).
fn deliver_tool0(env: &mut OsdD7) -> Vec<f64> {
    let mut rewards = Vec::new();
    for t in 1..=17 {
        let tb0 = if t <= 10 { GET_TOOL } else { GO_WA0 };
        let fetch = match t {
            1..=6 => LOOK0,
            7..=10 => PASS_T0,
            _ => WAIT,
        };
        rewards.push(step(env, &[tb0, 2, fetch]).reward);
        if t == 10 {
            assert!(env.mac_done()[0], "the pass ends Get_Tool");
            assert_eq!(env.turtlebots()[0].basket, [1.0, 0.0, 0.0]);
        }
    }
    rewards
}

#[test]
fn a_correct_delivery_is_worth_100() {
    let mut env = d7(|_| {});
    let rewards = deliver_tool0(&mut env);
    assert!(rewards[..16].iter().all(|&r| r == -1.0), "{rewards:?}");
    assert_eq!(rewards[16], 99.0);
    assert!(env.mac_done()[0], "arrived");
    assert!(env.humans()[0].obtained);
    assert_eq!(env.turtlebots()[0].basket, [0.0; 3]);
    // The Turtlebot now observes human 0 at work step 0 and its empty basket.
    let obs = env.obs(0);
    assert_eq!(obs[0], 1.0, "at WorkArea0");
    assert_eq!(obs[5], 1.0, "human 0 on step 0");
    assert_eq!(&obs[13..16], &[0.0; 3]);
}

#[test]
fn a_delivery_to_a_waiting_human_is_worth_80_with_the_published_penalty() {
    // Human 0's first step takes 5 steps: it waits from step 5 on.
    let mut env = d7(|p| p.human_speeds[0] = [5.0, 20.0, 20.0, 20.0]);
    assert_eq!(deliver_tool0(&mut env)[16], 79.0);
    // Without the penalty (the reference tests `if ... and self.delay_delivery_penalty`).
    let mut env = d7(|p| {
        p.human_speeds[0] = [5.0, 20.0, 20.0, 20.0];
        p.delay_delivery_penalty = 0.0;
    });
    assert_eq!(deliver_tool0(&mut env)[16], 99.0);
}

#[test]
fn a_pass_to_nobody_costs_10_when_it_ends() {
    let mut env = d7(|_| {});
    let rewards: Vec<f64> = (0..4)
        .map(|_| step(&mut env, &[2, 2, PASS_T0]).reward)
        .collect();
    assert_eq!(rewards, [-1.0, -1.0, -1.0, -11.0]);
    assert!(env.mac_done()[2]);
    // A pass that starts before the Turtlebot waits fails even if it waits when the pass ends:
    // Turtlebot 0 reaches its table at step 3 (time_left 0), the pass starts at step 3.
    let mut env = d7(|_| {});
    let mut rewards = Vec::new();
    for t in 1..=6 {
        let fetch = if t < 3 { WAIT } else { PASS_T0 };
        rewards.push(step(&mut env, &[GET_TOOL, 2, fetch]).reward);
    }
    assert_eq!(rewards, [-1.0, -1.0, -1.0, -1.0, -1.0, -11.0]);
    assert!(!env.mac_done()[0], "the Turtlebot keeps waiting");
}

#[test]
fn get_tool_gives_up_after_ten_steps_of_waiting() {
    // D7: Turtlebot 0 arrives at step 3 (time_left 0), waits -1..-10 at steps 4..13.
    let mut env = d7(|_| {});
    for t in 1..=13 {
        step(&mut env, &[GET_TOOL, 2, WAIT]);
        assert_eq!(env.mac_done()[0], t == 13, "t = {t}");
    }
    assert_eq!(env.turtlebots()[0].time_left, -1.0);
    // OSD-F-v0 (core_four_room.py): Get_Tool (5) starts waiting on its arrival step, so it gives
    // up one step earlier: Turtlebot 0 (3, 4) -> (0.8, 3.7) arrives at step 3.
    let mut env = OsdF0::published(300).unwrap();
    for t in 1..=12 {
        step(&mut env, &[5, 4, 4, WAIT]);
        assert_eq!(env.mac_done()[0], t == 12, "t = {t}");
    }
}

#[test]
fn go_tool_room_takes_an_extra_step_in_osd_f_v0_only() {
    // Turtlebot 1 starts 0.5 m from ToolRoomWait in D7 ((3, 1.5) -> (3, 2.5), dist 1.0): it
    // moves at step 1 and arrives at step 2.
    let mut env = d7(|_| {});
    step(&mut env, &[2, 2, WAIT]);
    step(&mut env, &[2, 2, WAIT]);
    assert!(env.mac_done()[1]);
    // F0: Turtlebot 0 (3, 4) -> (3, 2.5), dist 1.5: moves at step 1, arrives at step 2 but
    // returns early (action 4), and ends at step 3.
    let mut env = OsdF0::published(300).unwrap();
    step(&mut env, &[4, 4, 4, WAIT]);
    step(&mut env, &[4, 4, 4, WAIT]);
    assert!(!env.mac_done()[0]);
    assert_eq!(env.turtlebots()[0].pos, [3.0, 2.5]);
    step(&mut env, &[4, 4, 4, WAIT]);
    assert!(env.mac_done()[0]);
}

#[test]
fn a_pass_to_turtlebot_2_is_not_checked_when_it_starts() {
    // OSD-T-v1: Turtlebot 2 reaches its table at step 3 (waiting from step 4); a pass started
    // at step 1 ends at step 4 and succeeds (nothing staged: it ends Get_Tool empty-handed).
    let mut env = OsdT1::published(250).unwrap();
    let rewards: Vec<f64> = (0..4)
        .map(|_| step(&mut env, &[3, 3, 4, 3]).reward)
        .collect();
    assert_eq!(rewards, [-1.0; 4]);
    assert!(env.mac_done()[2] && env.mac_done()[3]);
    // The same pass to Turtlebot 1 fails.
    let mut env = OsdT1::published(250).unwrap();
    let rewards: Vec<f64> = (0..4)
        .map(|_| step(&mut env, &[3, 4, 3, 2]).reward)
        .collect();
    assert_eq!(rewards, [-1.0, -1.0, -1.0, -11.0]);
}

#[test]
fn osd_d_v7_with_obs_human_wait_keeps_busy_observations_in_the_wrong_slot() {
    // Turtlebot 0 ends Go_Tool_Room at step 2; Turtlebot 1 is busy with Get_Tool and shows
    // Turtlebot 0's new observation (reference bug, see Layout::held_obs_slot).
    let mut env = d7(|p| p.obs_human_wait = true);
    step(&mut env, &[2, GET_TOOL, WAIT]);
    step(&mut env, &[2, GET_TOOL, WAIT]);
    assert_eq!(env.mac_done()[..2], [true, false]);
    assert_eq!(env.obs(0)[2], 1.0, "Turtlebot 0 at ToolRoomWait");
    assert_eq!(env.obs(1), env.obs(0));
    // Without the flag each keeps its own.
    let mut env = d7(|_| {});
    step(&mut env, &[2, GET_TOOL, WAIT]);
    step(&mut env, &[2, GET_TOOL, WAIT]);
    assert_eq!(
        env.obs(1)[4],
        1.0,
        "Turtlebot 1 still at its reset observation"
    );
}

#[test]
fn the_horizon_cut_is_truncated_except_in_osd_f_v0() {
    fn wait_out<E: MacroEnv>(mut env: E, wait: &[usize]) -> (usize, StepOutcome) {
        loop {
            let out = step(&mut env, wait);
            if out.done {
                return (env.t(), out);
            }
        }
    }
    let (t, out) = wait_out(d7(|p| p.horizon = 30), &[2, 2, WAIT]);
    assert_eq!((t, out.truncated, out.terminal()), (30, true, false));
    let (t, out) = wait_out(OsdT0::published(40).unwrap(), &[3, 3, WAIT]);
    assert_eq!((t, out.truncated), (40, true));
    let (t, out) = wait_out(OsdT1::published(40).unwrap(), &[3, 3, 3, WAIT]);
    assert_eq!((t, out.truncated), (40, true));
    // F0: the env is terminal at terminate_step ...
    let (t, out) = wait_out(OsdF0::published(300).unwrap(), &[4, 4, 4, WAIT]);
    assert_eq!((t, out.terminal()), (300, true));
    // ... but a shorter runner horizon still cuts.
    let p = OsdParams {
        horizon: 50,
        ..OsdParams::published(OsdF0::layout())
    };
    let (t, out) = wait_out(OsdF0::new(p).unwrap(), &[4, 4, 4, WAIT]);
    assert_eq!((t, out.truncated), (50, true));
}

#[test]
fn stepping_after_the_end_or_with_bad_actions_is_an_error() {
    let mut env = d7(|p| p.horizon = 1);
    let mut rng = EnvRng::seed_from_u64(0);
    assert_eq!(
        env.step(&[0, 0], &mut rng),
        Err(EnvError::WrongActionCount {
            expected: 3,
            got: 2
        })
    );
    assert!(matches!(
        env.step(&[0, 4, 0], &mut rng),
        Err(EnvError::ActionOutOfRange { agent: 1, .. })
    ));
    assert_eq!(env.t(), 0, "a refused step changes nothing");
    assert!(env.step(&[0, 0, 0], &mut rng).unwrap().done);
    assert_eq!(env.step(&[0, 0, 0], &mut rng), Err(EnvError::EpisodeOver));
    env.reset(&mut rng);
    assert_eq!(env.t(), 0);
    assert!(env.step(&[0, 0, 0], &mut rng).is_ok());
}

/// A scripted team (closed loop, reading the state): the Fetch stages the tools the humans
/// still need, lowest first, and passes to any Turtlebot waiting at its table; a Turtlebot
/// carrying a tool some human needs now drives to that human, otherwise it fetches one.
pub(super) fn scripted<const V: usize>(env: &Osd<V>) -> Vec<usize> {
    let layout = Osd::<V>::layout();
    let (n_h, n_tb) = (layout.n_humans(), layout.n_turtlebots());
    let humans = env.humans();
    let mut actions = Vec::new();
    for tb in env.turtlebots() {
        let wanted = (0..n_h).find(|&h| {
            let hu = &humans[h];
            !hu.obtained && !hu.finished && tb.basket[hu.need] > 0.0
        });
        actions.push(wanted.unwrap_or(layout.get_tool()));
    }
    let fetch = env.fetch();
    let waiting = (0..n_tb).find(|&k| env.turtlebots()[k].waiting_at_table(layout));
    let action = match waiting {
        Some(k) if !fetch.staged().is_empty() => 1 + k,
        _ if fetch.staged().len() < 2 => {
            // Tools still to hand out, per type, beyond those staged or carried.
            let mut missing = [0.0; layout::N_OBJS];
            for h in humans {
                for (j, m) in missing.iter_mut().enumerate() {
                    if j > h.need || (j == h.need && !h.obtained) {
                        *m += 1.0;
                    }
                }
            }
            for &j in fetch.staged() {
                missing[j] -= 1.0;
            }
            for tb in env.turtlebots() {
                for (m, held) in missing.iter_mut().zip(&tb.basket) {
                    *m -= held;
                }
            }
            (0..layout::N_OBJS)
                .find(|&j| missing[j] > 0.0 && fetch.count_found[j] < layout.n_each_obj)
                .map_or(0, |j| 1 + n_tb + j)
        }
        _ => 0,
    };
    actions.push(action);
    actions
}

/// Run the scripted team to the end; returns (steps, undiscounted return, last outcome).
fn run_scripted<const V: usize>(env: &mut Osd<V>) -> (usize, f64, StepOutcome) {
    let mut ret = 0.0;
    loop {
        let actions = scripted(env);
        let out = step(env, &actions);
        ret += out.reward;
        if out.done {
            return (env.t(), ret, out);
        }
    }
}

#[test]
fn the_scripted_team_serves_every_human_and_ends_terminal() {
    fn check<const V: usize>(mut env: Osd<V>) -> (usize, f64) {
        let (t, ret, out) = run_scripted(&mut env);
        assert!(out.terminal(), "{}: cut at {t}", Osd::<V>::layout().gym_id);
        assert!(env.humans().iter().all(|h| h.cur_step >= 2 && h.obtained));
        // The upper bound of `docs/MACROMARL.md` §3.2: 300 per human minus one per step.
        assert!(ret <= 300.0 * env.humans().len() as f64 - t as f64);
        (t, ret)
    }
    let results = [
        check(OsdD7::published(200).unwrap()),
        check(OsdT0::published(250).unwrap()),
        check(OsdT1::published(250).unwrap()),
        check(OsdF0::published(300).unwrap()),
    ];
    // Lower bounds on the optimum (the shipped learned policies reach C 801 in 99 steps, D 781
    // in 99, E 1050 in 130; `docs/MACROMARL.md` §4). A and C meet the upper bound 300 N - steps.
    assert_eq!(
        results,
        [(67, 533.0), (103, 797.0), (100, 760.0), (129, 1051.0)]
    );
}

/// Properties of random episodes in every domain: observations change only when the agent's
/// macro-action ended, rewards come from the reference's reward set, and executed actions of
/// busy agents are the running ones.
#[test]
fn random_episodes_keep_the_step_contract() {
    fn check<const V: usize>(mut env: Osd<V>, seed: u64) {
        let mut rng = EnvRng::seed_from_u64(seed);
        for _ in 0..20 {
            env.reset(&mut rng);
            loop {
                let before: Vec<Vec<f32>> =
                    (0..env.n_agents()).map(|i| env.obs(i).to_vec()).collect();
                let free: Vec<bool> = (0..env.n_agents()).map(|i| env.is_free(i)).collect();
                let running = env.executed().to_vec();
                let actions: Vec<usize> = env
                    .n_actions()
                    .iter()
                    .map(|&n| rng.gen_range(0..n))
                    .collect();
                let out = env.step(&actions, &mut rng).unwrap();
                for i in 0..env.n_agents() {
                    if !env.mac_done()[i] {
                        assert_eq!(env.obs(i), &before[i][..], "held observation");
                    }
                    let expected = if free[i] { actions[i] } else { running[i] };
                    assert_eq!(env.executed()[i], expected);
                }
                // -1, plus per Turtlebot 0, 100 or 80, plus 0 or -10 from the Fetch.
                let gained = out.reward + 1.0;
                let tens = gained / 10.0;
                assert!(tens.fract() == 0.0 && gained <= 300.0, "{}", out.reward);
                if out.done {
                    break;
                }
            }
        }
    }
    check(OsdD7::published(200).unwrap(), 1);
    check(OsdT0::published(250).unwrap(), 2);
    check(OsdT1::published(250).unwrap(), 3);
    check(OsdF0::published(300).unwrap(), 4);
}

#[test]
fn movement_noise_draws_from_the_caller_stream_only() {
    let noisy = d7(|p| p.tb_move_noisy = 0.1);
    assert!(!noisy.deterministic());
    assert!(d7(|_| {}).deterministic());
    let run = |seed: u64| {
        let mut env = noisy.clone();
        let mut rng = EnvRng::seed_from_u64(seed);
        for _ in 0..3 {
            env.step(&[GO_WA0, 1, WAIT], &mut rng).unwrap();
        }
        env.turtlebots()[0].pos
    };
    assert_eq!(run(5), run(5));
    assert_ne!(run(5), run(6));
}

/// The scripted team's action logs for the reference fixtures `osd_*_scripted`: run with
/// `OSD_STEPS_DIR=DIR cargo test --release --lib write_scripted_steps -- --ignored`, then feed
/// each `DIR/NAME.steps.json` to `scripts/macromarl_traces.py --steps` with the same params
/// (`scripts/macromarl_fixtures.sh`).
#[test]
#[ignore]
fn write_scripted_steps() {
    use crate::envs::domain::{json_to_toml, Domain};
    fn log<const V: usize>(domain: OsdDomain<V>, params: &str) -> String {
        let Some(toml::Value::Table(given)) = json_to_toml(&serde_json::from_str(params).unwrap())
        else {
            panic!("params are an object")
        };
        let mut env = domain
            .build(&Domain::keys(&domain, &given).unwrap())
            .unwrap();
        let mut rows = Vec::new();
        loop {
            let actions = scripted(&env);
            let row: Vec<i64> = (0..env.n_agents())
                .map(|i| {
                    if env.is_free(i) {
                        actions[i] as i64
                    } else {
                        -1
                    }
                })
                .collect();
            rows.push(row);
            if step(&mut env, &actions).done {
                return serde_json::to_string(&rows).unwrap();
            }
        }
    }
    let dir = std::path::PathBuf::from(std::env::var("OSD_STEPS_DIR").expect("OSD_STEPS_DIR"));
    for (name, text) in [
        ("osd_d_v7_a_scripted", log(OSD_D_V7, SCRIPTED_PARAMS[0])),
        ("osd_d_v7_b_scripted", log(OSD_D_V7, SCRIPTED_PARAMS[1])),
        ("osd_t_v0_c_scripted", log(OSD_T_V0, SCRIPTED_PARAMS[2])),
        ("osd_t_v1_d_scripted", log(OSD_T_V1, SCRIPTED_PARAMS[3])),
        ("osd_f_v0_e_scripted", log(OSD_F_V0, SCRIPTED_PARAMS[4])),
    ] {
        std::fs::write(dir.join(format!("{name}.steps.json")), text).unwrap();
    }
}

/// The params of the scripted fixtures (as `scripts/macromarl_fixtures.sh` passes them): the
/// published settings (B with `obs_human_wait`, C and E too, to cover those bits).
const SCRIPTED_PARAMS: [&str; 5] = [
    r#"{"TB_move_speed": 0.8, "delay_delivery_penalty": -20.0, "human_speed_per_step": [[27,20,20,20],[27,20,20,20]]}"#,
    r#"{"TB_move_speed": 0.8, "delay_delivery_penalty": -20.0, "obs_human_wait": true, "human_speed_per_step": [[18,15,15,15],[48,18,15,15]]}"#,
    r#"{"TB_move_speed": 0.8, "delay_delivery_penalty": -20.0, "obs_human_wait": true, "human_speed_per_step": [[40,40,40,40],[40,40,40,40],[40,40,40,40]]}"#,
    r#"{"TB_move_speed": 0.8, "delay_delivery_penalty": -20.0, "human_speed_per_step": [[38,38,38,38],[38,38,38,38],[27,27,27,27]]}"#,
    r#"{"TB_move_speed": 0.8, "delay_delivery_penalty": -20.0, "obs_human_wait": true, "terminate_step": 300, "human_speed_per_step": [[40,40,40,40],[40,40,40,40],[40,40,40,40],[40,40,40,40]]}"#,
];

#[test]
fn observation_names_match_the_observation_sizes() {
    fn check<const V: usize>() {
        for wait in [false, true] {
            let p = OsdParams {
                obs_human_wait: wait,
                ..OsdParams::published(Osd::<V>::layout())
            };
            let env = Osd::<V>::new(p).unwrap();
            for agent in 0..env.n_agents() {
                assert_eq!(env.obs_names(agent).len(), env.obs_sizes()[agent]);
                assert_eq!(env.obs(agent).len(), env.obs_sizes()[agent]);
                assert_eq!(env.action_names(agent).len(), env.n_actions()[agent]);
            }
        }
    }
    check::<D7>();
    check::<T0>();
    check::<T1>();
    check::<F0>();
}
