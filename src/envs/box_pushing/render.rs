//! ASCII picture of a Box Pushing state, for debugging and `macdec replay --verbose`.

use std::fmt::Write;

use super::actions::ACTION_NAMES;
use super::geometry::Cell;
use super::observe::OBS_SIZE;
use super::BoxPushing;

/// Three characters for one cell: robots first (`0>` is robot 0 facing east, `01` both robots),
/// then boxes (`s0`, `s1`, `BB`), then waypoints (`w0`..`w3`), else `.`.
fn cell_text(env: &BoxPushing, cell: Cell) -> String {
    let on: Vec<usize> = (0..2).filter(|&i| env.robots[i].cell == cell).collect();
    match on.as_slice() {
        [i] => return format!("{i}{} ", env.robots[*i].heading.arrow()),
        [_, _] => return "01 ".to_string(),
        _ => {}
    }
    for k in 0..2 {
        if env.boxes.small[k] == cell {
            return format!("s{k} ");
        }
    }
    if env.boxes.big_covers(cell) {
        return "BB ".to_string();
    }
    if let Some(k) = env.layout.waypoints.iter().position(|&w| w == cell) {
        return format!("w{k} ");
    }
    ".  ".to_string()
}

fn bits(obs: &[f32; OBS_SIZE]) -> String {
    obs.iter()
        .map(|&v| if v > 0.5 { '1' } else { '0' })
        .collect()
}

/// The grid with the top (goal) row first, then one status line per robot: cell, heading, current
/// macro-action, finished flag, remembered waypoint and held observation (bits in the order small,
/// big, empty, wall, teammate).
pub fn render(env: &BoxPushing) -> String {
    let n = env.layout.n;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "t={} done={} joint_push={}",
        env.t, env.done, env.joint_push
    );
    for row in (0..n).rev() {
        let _ = write!(s, "{row:>3} ");
        for col in 0..n {
            s.push_str(&cell_text(env, Cell::new(col, row)));
        }
        if row == n - 1 {
            s.push_str(" <- goal");
        }
        s.push('\n');
    }
    for (i, r) in env.robots.iter().enumerate() {
        let current = r.current.map_or("-", |m| ACTION_NAMES[m.index()]);
        let waypoint = r.waypoint.map_or("-".to_string(), |k| format!("W{k}"));
        let outside = if r.cell.is_outside(n) {
            " (outside the grid)"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "robot {i}: ({},{}) {} {current} finished={} waypoint={waypoint} obs={}{outside}",
            r.cell.col,
            r.cell.row,
            r.heading.arrow(),
            r.finished,
            bits(&env.obs[i]),
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::super::BoxPushing;
    use crate::envs::MacroEnv;

    #[test]
    fn start_picture_shows_robots_boxes_and_waypoints() {
        let env = BoxPushing::new(10, 100).unwrap();
        let text = env.render_ascii();
        let lines: Vec<&str> = text.lines().collect();
        // Header, rows 9..0, two robot lines.
        assert_eq!(lines.len(), 1 + 10 + 2);
        assert!(lines[1].starts_with("  9 ") && lines[1].ends_with("<- goal"));
        assert_eq!(lines[5], "  5 .  s0 .  .  BB BB .  .  s1 .  ");
        assert_eq!(lines[6], "  4 .  w0 .  .  w2 w3 .  .  w1 .  ");
        assert_eq!(lines[9], "  1 .  0> .  .  .  .  .  .  1< .  ");
        assert!(lines[11].starts_with("robot 0: (1,1) > - finished=true waypoint=- obs=00100"));
    }
}
