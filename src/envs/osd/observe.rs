//! The agents' macro-observations (`_getobs`) and the global state (`get_state`), written into
//! buffers the environment owns.
//!
//! Turtlebot k: `[location one-hot (waypoints + "none") | each human's work-step one-hot, set
//! only for the human whose area k is at | basket counts | the Fetch's ready bits, seen only at
//! the tool-room waypoints or before the first arrival | (obs_human_wait) waiting humans]`.
//! Fetch: `[staged tool counts | which Turtlebots stand exactly on their table spot |
//! (OSD-D-v7 with obs_human_wait) waiting humans]`.

use super::fetch::Fetch;
use super::human::Human;
use super::layout::{HumanWaitObs, Layout, FETCH_POS, N_OBJS, N_WORK_STEPS};
use super::params::OsdParams;
use super::turtlebot::Turtlebot;

/// The observation a Turtlebot gets at reset: location "none", nothing else.
pub fn write_tb_reset_obs(layout: &Layout, out: &mut [f32]) {
    out.fill(0.0);
    out[layout.n_humans() + 2] = 1.0;
}

/// Turtlebot `tb`'s observation after the macro-action it just finished.
pub fn write_tb_obs(
    layout: &Layout,
    p: &OsdParams,
    tb: &Turtlebot,
    fetch: &Fetch,
    humans: &[Human],
    out: &mut [f32],
) {
    out.fill(0.0);
    let n_h = layout.n_humans();
    let n_loc = n_h + 3;
    out[tb.cur_bwp.unwrap_or(n_loc - 1)] = 1.0;
    let here = tb.cur_bwp.filter(|&b| b < n_h);
    if let Some(h) = here {
        out[n_loc + h * N_WORK_STEPS + humans[h].cur_step] = 1.0;
    }
    let basket_at = n_loc + n_h * N_WORK_STEPS;
    for (o, &count) in out[basket_at..basket_at + N_OBJS]
        .iter_mut()
        .zip(&tb.basket)
    {
        *o = count as f32;
    }
    let ready_at = basket_at + N_OBJS;
    // Visible at ToolRoomWait and the table (`BWP.idx >= len(BWPs) - 2`) or before any arrival.
    if tb.cur_bwp.is_none_or(|b| b >= n_h) {
        out[ready_at] = fetch.ready[0] as f32;
        out[ready_at + 1] = fetch.ready[1] as f32;
    }
    if p.obs_human_wait {
        let wait = &mut out[ready_at + 2..ready_at + 2 + n_h];
        match layout.human_wait_obs {
            HumanWaitObs::EveryHuman => write_waiting(humans, wait),
            HumanWaitObs::HumanHere => {
                if let Some(h) = here.filter(|&h| humans[h].time_left < 0.0) {
                    wait[h] = 1.0;
                }
            }
        }
    }
}

/// 1 for each human whose step time ran out (`cur_step_time_left < 0`).
fn write_waiting(humans: &[Human], out: &mut [f32]) {
    for (o, h) in out.iter_mut().zip(humans) {
        *o = if h.time_left < 0.0 { 1.0 } else { 0.0 };
    }
}

/// The staged tools counted per type.
fn staged_counts(fetch: &Fetch) -> [f32; N_OBJS] {
    let mut counts = [0.0; N_OBJS];
    for &tool in fetch.staged() {
        counts[tool] += 1.0;
    }
    counts
}

/// The Fetch's observation after the macro-action it just finished.
pub fn write_fetch_obs(
    layout: &Layout,
    p: &OsdParams,
    fetch: &Fetch,
    tbs: &[Turtlebot],
    humans: &[Human],
    out: &mut [f32],
) {
    out[..N_OBJS].copy_from_slice(&staged_counts(fetch));
    for (k, tb) in tbs.iter().enumerate() {
        // Exact coordinate equality, as the reference compares.
        out[N_OBJS + k] = if tb.pos == layout.tables[k] { 1.0 } else { 0.0 };
    }
    if p.obs_human_wait && layout.human_wait_obs == HumanWaitObs::EveryHuman {
        write_waiting(humans, &mut out[N_OBJS + tbs.len()..]);
    }
}

/// `get_state()` (OSD-D-v7 and OSD-T-v0): positions of the Turtlebots and the Fetch over
/// (7, 5), the baskets, the staged tool counts, the tool in the Fetch's hand during a pass,
/// the Fetch's `time_left / t_cost`, then for each human its work-step one-hot and its
/// progress `1 - time_left / step time` (-1 while waiting).
pub fn write_state(
    layout: &Layout,
    p: &OsdParams,
    tbs: &[Turtlebot],
    fetch: &Fetch,
    humans: &[Human],
    out: &mut [f32],
) {
    let mut s = StateWriter { out, at: 0 };
    for tb in tbs {
        s.push(tb.pos[0] / 7.0);
        s.push(tb.pos[1] / 5.0);
    }
    s.push(FETCH_POS[0] / 7.0);
    s.push(FETCH_POS[1] / 5.0);
    for tb in tbs {
        for &count in &tb.basket {
            s.push(count);
        }
    }
    for count in staged_counts(fetch) {
        s.push(count as f64);
    }
    let passing = fetch
        .cur_action
        .is_some_and(|a| (1..=tbs.len()).contains(&a))
        && !fetch.done;
    let mut in_hand = [0.0; N_OBJS];
    if let (true, Some(&tool)) = (passing, fetch.staged().first()) {
        in_hand[tool] = 1.0;
    }
    for v in in_hand {
        s.push(v);
    }
    s.push(match fetch.cur_t_cost(layout, p) {
        Some(t_cost) => fetch.time_left / t_cost,
        None => 0.0,
    });
    for h in humans {
        for k in 0..N_WORK_STEPS {
            s.push(if k == h.cur_step { 1.0 } else { 0.0 });
        }
        s.push(if h.time_left >= 0.0 {
            1.0 - h.time_left / h.speeds[h.cur_step]
        } else {
            -1.0
        });
    }
    debug_assert_eq!(s.at, s.out.len());
}

struct StateWriter<'a> {
    out: &'a mut [f32],
    at: usize,
}

impl StateWriter<'_> {
    fn push(&mut self, v: f64) {
        self.out[self.at] = v as f32;
        self.at += 1;
    }
}
