//! Text views of a Warehouse state: the observation elements' names (exported policies,
//! replays) and an ASCII picture for debugging and `--verbose` replays: a map at 0.25 m per
//! character (north up; `0`..`2` Turtlebots, `F` Fetch, `+` waypoints, `H0`.. humans' areas)
//! and one status line per robot and per human.

use std::fmt::Write;

use super::layout::{HumanWaitObs, Layout, FETCH_POS, N_OBJS, N_WORK_STEPS};
use super::{MacroEnv, Osd};

/// Names of agent `agent`'s observation elements, in layout order.
pub fn obs_names(layout: &Layout, obs_human_wait: bool, agent: usize) -> Vec<String> {
    let n_h = layout.n_humans();
    let n_tb = layout.n_turtlebots();
    assert!(agent <= n_tb, "agent {agent} out of range");
    let mut names = Vec::new();
    if agent < n_tb {
        names.extend((0..n_h).map(|h| format!("at_WorkArea{h}")));
        names.extend(["at_ToolRoomWait", "at_ToolRoomTable", "at_none"].map(String::from));
        for h in 0..n_h {
            names.extend((0..N_WORK_STEPS).map(|k| format!("human{h}_step{k}")));
        }
        names.extend((0..N_OBJS).map(|j| format!("basket_obj{j}")));
        names.extend(["ready_one", "ready_two"].map(String::from));
        if obs_human_wait {
            names.extend((0..n_h).map(|h| format!("human{h}_waiting")));
        }
    } else {
        names.extend((0..N_OBJS).map(|j| format!("staged_obj{j}")));
        names.extend((0..n_tb).map(|k| format!("T{k}_beside_table")));
        if obs_human_wait && layout.human_wait_obs == HumanWaitObs::EveryHuman {
            names.extend((0..n_h).map(|h| format!("human{h}_waiting")));
        }
    }
    names
}

const CELL_M: f64 = 0.25;
const ROWS: usize = 20; // 5 m

/// The ASCII picture of `env`.
pub fn ascii<const V: usize>(env: &Osd<V>) -> String {
    let layout = Osd::<V>::layout();
    let cols = (layout.world_width_m() / CELL_M) as usize;
    let mut grid = vec![vec![b'.'; cols]; ROWS];
    let mut put = |p: [f64; 2], ch: u8| {
        let c = (p[0] / CELL_M).floor().clamp(0.0, (cols - 1) as f64) as usize;
        let r = ((5.0 - p[1]) / CELL_M)
            .floor()
            .clamp(0.0, (ROWS - 1) as f64) as usize;
        grid[r][c] = ch;
    };
    for (h, wa) in layout.work_areas.iter().enumerate() {
        put(*wa, b'H');
        put([wa[0] + CELL_M, wa[1]], b'0' + h as u8);
    }
    put(layout.tool_room_wait, b'+');
    for t in layout.tables {
        put(*t, b'+');
    }
    put(FETCH_POS, b'F');
    for (i, tb) in env.turtlebots().iter().enumerate() {
        put(tb.pos, b'0' + i as u8);
    }
    let mut s = String::new();
    for row in grid {
        s.push_str(&String::from_utf8_lossy(&row));
        s.push('\n');
    }
    let names = |agent: usize, a: Option<usize>| a.map_or("-", |a| env.action_names(agent)[a]);
    for (i, tb) in env.turtlebots().iter().enumerate() {
        let _ = writeln!(
            s,
            "T{i} ({:.2}, {:.2}) {} left {:.2} done {} basket {:?}",
            tb.pos[0],
            tb.pos[1],
            names(i, tb.cur_action),
            tb.time_left,
            tb.done,
            tb.basket
        );
    }
    let f = env.fetch();
    let _ = writeln!(
        s,
        "F {} left {} done {} staged {:?} ready {:?}",
        names(layout.n_turtlebots(), f.cur_action),
        f.time_left,
        f.done,
        f.staged(),
        f.ready
    );
    for (k, h) in env.humans().iter().enumerate() {
        let _ = writeln!(
            s,
            "H{k} step {} left {} needs {} obtained {} finished {}",
            h.cur_step, h.time_left, h.need, h.obtained, h.finished
        );
    }
    let _ = write!(s, "t = {}  reward {}", env.t(), env.last_reward());
    s
}
