//! ASCII picture of a Warehouse state (debugging, `--verbose` replays): a 7 m x 5 m map at
//! 0.25 m per character (north up) and one status line per robot and for the human.
//!
//! Map legend: `0`/`1` Turtlebots (`&` both in one cell), `F` Fetch, `=` table, `+` waypoints,
//! `:` tool-room wall (x = 3.5), `|`/`-` workshop walls, `H` the human.

use std::fmt::Write;

use super::params::{FETCH_POS, WAYPOINTS};
use super::{MacroEnv, Warehouse, FETCH_ACTION_NAMES, TB_ACTION_NAMES};

const CELL_M: f64 = 0.25;
const COLS: usize = 28; // 7 m
const ROWS: usize = 20; // 5 m

fn cell(p: [f64; 2]) -> (usize, usize) {
    let c = (p[0] / CELL_M).floor().clamp(0.0, (COLS - 1) as f64) as usize;
    let r = ((5.0 - p[1]) / CELL_M)
        .floor()
        .clamp(0.0, (ROWS - 1) as f64) as usize;
    (r, c)
}

fn put(grid: &mut [[u8; COLS]; ROWS], p: [f64; 2], ch: u8) {
    let (r, c) = cell(p);
    grid[r][c] = ch;
}

fn location_name(loc: Option<usize>) -> &'static str {
    match loc {
        Some(0) => "workshop",
        Some(1) => "tool-room",
        Some(2) => "table",
        _ => "none",
    }
}

pub(super) fn render(env: &Warehouse) -> String {
    let mut grid = [[b'.'; COLS]; ROWS];
    for row in grid.iter_mut() {
        row[14] = b':';
    }
    for row in grid.iter_mut().take(8) {
        row[20] = b'|';
    }
    for ch in grid[8][20..].iter_mut() {
        *ch = b'-';
    }
    // Table centred at (1.75, 1.8), 0.6 x 1.8 m.
    let mut y = 0.95;
    while y < 2.7 {
        put(&mut grid, [1.5, y], b'=');
        put(&mut grid, [1.8, y], b'=');
        y += CELL_M;
    }
    for wps in WAYPOINTS {
        for wp in wps {
            put(&mut grid, wp, b'+');
        }
    }
    put(&mut grid, FETCH_POS, b'F');
    put(&mut grid, [6.5, 4.5], b'H');
    let (p0, p1) = (env.turtlebot(0).pos, env.turtlebot(1).pos);
    put(&mut grid, p0, b'0');
    put(&mut grid, p1, b'1');
    if cell(p0) == cell(p1) {
        put(&mut grid, p0, b'&');
    }

    let mut s = String::with_capacity((COLS + 1) * ROWS + 512);
    for row in &grid {
        s.push_str(std::str::from_utf8(row).expect("ASCII grid"));
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "t={}/{}  last reward {}  mac_done {:?}",
        env.t(),
        env.horizon(),
        env.last_reward,
        env.mac_done()
            .iter()
            .map(|&d| u8::from(d))
            .collect::<Vec<_>>()
    );
    for i in 0..2 {
        let tb = env.turtlebot(i);
        let _ = writeln!(
            s,
            "T{i} at ({:.2}, {:.2}) loc={} action={} tl={} done={} basket={:?}",
            tb.pos[0],
            tb.pos[1],
            location_name(tb.loc),
            tb.cur.map_or("-", |a| TB_ACTION_NAMES[a as usize]),
            tb.tl,
            u8::from(tb.done),
            tb.basket
        );
    }
    let f = env.fetch();
    let _ = writeln!(
        s,
        "Fetch action={} tl={} done={} staging={:?} ready={:?} found={:?} serving_failed={}",
        f.cur.map_or("-", |a| FETCH_ACTION_NAMES[a.index()]),
        f.tl,
        u8::from(f.done),
        f.staged(),
        f.ready,
        f.found_count,
        f.serving_failed
    );
    let h = env.human();
    let _ = writeln!(
        s,
        "Human step {} htl={} needs tool {} obtained={} finished={}",
        h.step_k, h.htl, h.need, h.obtained, h.finished
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reset_picture_shows_robots_and_status() {
        let env = Warehouse::paper(150).unwrap();
        let s = env.render_ascii();
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(lines.len(), ROWS + 5);
        // T0 at (3.0, 1.5): row floor(3.5/0.25) = 14, col 12; T1 at (3.0, 2.5): row 10, col 12.
        assert_eq!(lines[14].as_bytes()[12], b'0');
        assert_eq!(lines[10].as_bytes()[12], b'1');
        assert!(s.contains("t=0/150"));
        assert!(s.contains("T0 at (3.00, 1.50) loc=none action=-"));
        assert!(s.contains("Fetch action=- tl=0 done=1 staging=[]"));
        assert!(s.contains("Human step 0 htl=18 needs tool 0"));
    }
}
