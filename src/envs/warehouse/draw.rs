//! One Warehouse Tool Delivery frame, laid out as the reference's renderer draws the world (spec
//! `warehouse.md` section 1): the 7 m x 5 m floor, the tool room left of the dashed wall at
//! x = 3.5, the workshop box x in [5, 7], y in [3, 5], the table centred at (1.75, 1.8)
//! (0.6 m x 1.8 m) with the Fetch's two-slot staging area on it, the red waypoints, the Fetch
//! (gray), the Turtlebots (green T0, blue T1) with the tools in their baskets, and the human with
//! a bar of its work steps and the tool it needs next. Tools are coloured by index everywhere.

use super::{FetchAction, Warehouse, FETCH_POS, WAYPOINTS};
use crate::draw::font::draw_text_centred;
use crate::draw::{Canvas, Colour, Picture};

/// Status-bar labels: Turtlebot 0, Turtlebot 1, Fetch.
pub const LABELS: [&str; 3] = ["T0", "T1", "F"];

/// Pixels per metre: the world is 420 x 300 pixels.
pub const PX_PER_M: f64 = 60.0;
const WORLD_W_M: f64 = 7.0;
pub(crate) const WORLD_H_M: f64 = 5.0;

/// Where the human stands in the workshop (the dynamics have no human position; `docs/WAREHOUSE.md` §1).
const HUMAN_POS: [f64; 2] = [6.5, 3.9];
/// Centres of the two staging slots on the table, first-to-pass first.
const STAGING: [[f64; 2]; 2] = [[1.75, 2.4], [1.75, 2.05]];

pub(crate) const TB_RADIUS_M: f64 = 0.17;
const FETCH_RADIUS_M: f64 = 0.25;

/// World point (m, y up) to continuous pixel coordinates (y down).
pub fn to_px(p: [f64; 2]) -> (f64, f64) {
    (p[0] * PX_PER_M, (WORLD_H_M - p[1]) * PX_PER_M)
}

fn world_px() -> (usize, usize) {
    (
        (WORLD_W_M * PX_PER_M).round() as usize,
        (WORLD_H_M * PX_PER_M).round() as usize,
    )
}

/// Fill (and rim) the axis-aligned world box from corner `lo` to corner `hi` (m). MacroMARL's
/// Warehouse pictures (`envs::osd::draw`) use the same world scale and draw with it too.
pub(crate) fn world_rect(
    c: &mut Canvas,
    lo: [f64; 2],
    hi: [f64; 2],
    fill: Colour,
    rim: Option<Colour>,
) {
    let (px0, py0) = to_px([lo[0], hi[1]]);
    let (px1, py1) = to_px([hi[0], lo[1]]);
    let (x, y) = (px0.round() as i64, py0.round() as i64);
    let (w, h) = (px1.round() as i64 - x, py1.round() as i64 - y);
    c.fill_rect(x, y, w, h, fill);
    if let Some(rim) = rim {
        c.outline_rect(x, y, w, h, 1, rim);
    }
}

fn draw_rooms(c: &mut Canvas) {
    let (w, h) = world_px();
    world_rect(c, [5.0, 3.0], [7.0, 5.0], Colour::Workshop, None);
    let (wall_x, _) = to_px([3.5, 0.0]);
    c.dashed_line(wall_x, 0.0, wall_x, h as f64, 2.0, 6.0, 5.0, Colour::Dark);
    let (ws_x, ws_y) = to_px([5.0, 3.0]);
    c.dashed_line(ws_x, 0.0, ws_x, ws_y, 2.0, 6.0, 5.0, Colour::Dark);
    c.dashed_line(ws_x, ws_y, w as f64, ws_y, 2.0, 6.0, 5.0, Colour::Dark);
    c.outline_rect(0, 0, w as i64, h as i64, 3, Colour::Dark);
    // Table centred at (1.75, 1.8), 0.6 m x 1.8 m.
    world_rect(
        c,
        [1.45, 0.9],
        [2.05, 2.7],
        Colour::Table,
        Some(Colour::Dark),
    );
    for robot in WAYPOINTS {
        for wp in robot {
            let (x, y) = to_px(wp);
            c.fill_circle(x, y, 4.0, Colour::Red);
        }
    }
}

fn draw_fetch(c: &mut Canvas, env: &Warehouse) {
    let fetch = env.fetch();
    let (fx, fy) = to_px(FETCH_POS);
    let r = FETCH_RADIUS_M * PX_PER_M;
    match fetch.cur {
        // Searching: a ring in the colour of the tool being looked for.
        Some(FetchAction::Search(k)) if !fetch.done => {
            c.fill_circle(fx, fy, r + 5.0, Colour::tool(k));
        }
        // Passing: an arm toward Turtlebot j's table spot.
        Some(FetchAction::Pass(j)) => {
            let (tx, ty) = to_px(env.turtlebot(j).targets[2]);
            let (ax, ay) = (fx + 0.75 * (tx - fx), fy + 0.75 * (ty - fy));
            c.line(fx, fy, ax, ay, 6.0, Colour::Dark);
            c.line(fx, fy, ax, ay, 3.0, Colour::Fetch);
        }
        _ => {}
    }
    c.ringed_circle(fx, fy, r, 2.0, Colour::Dark, Colour::Fetch);
    draw_text_centred(c, fx, fy, "F", 2, Colour::White);
    for (slot, centre) in STAGING.iter().enumerate() {
        let (x, y) = to_px(*centre);
        match fetch.staged().get(slot) {
            Some(&k) => c.centred_square(x, y, 14, Colour::tool(k), Colour::Dark),
            None => c.centred_square(x, y, 14, Colour::Table, Colour::White),
        }
    }
}

fn draw_human(c: &mut Canvas, env: &Warehouse) {
    let human = env.human();
    let (hx, hy) = to_px(HUMAN_POS);
    c.fill_circle(hx, hy - 16.0, 6.5, Colour::Human);
    c.fill_rect(hx as i64 - 6, hy as i64 - 9, 13, 22, Colour::Human);
    // Work steps: done dark, current green while its time runs, red while waiting for a tool.
    let n_steps = env.params().n_objs + 1;
    let (bar_x, _) = to_px([5.15, 0.0]);
    for k in 0..n_steps {
        let colour = if human.finished || k < human.step_k {
            Colour::Dark
        } else if k > human.step_k {
            Colour::GridLine
        } else if human.htl <= 0.0 && !human.obtained {
            Colour::Red
        } else {
            Colour::Working
        };
        c.centred_square(
            bar_x + 7.0 + 20.0 * k as f64,
            13.0,
            14,
            colour,
            Colour::Dark,
        );
    }
    // The tool the human needs to leave this step: a hollow square until delivered.
    if !human.finished && human.step_k < env.params().n_objs {
        let tool = Colour::tool(human.need);
        let (x, y) = ((hx - 37.0) as i64, (hy - 7.0) as i64);
        c.fill_rect(x, y, 14, 14, tool);
        if !human.obtained {
            c.fill_rect(x + 3, y + 3, 8, 8, Colour::Workshop);
        }
    }
}

fn draw_turtlebots(c: &mut Canvas, env: &Warehouse) {
    let r = TB_RADIUS_M * PX_PER_M;
    let pos = [0, 1].map(|i| to_px(env.turtlebot(i).pos));
    // Turtlebots may share a point (`docs/WAREHOUSE.md` §1): draw them side by side.
    let close = (pos[0].0 - pos[1].0).hypot(pos[0].1 - pos[1].1) < r;
    for (i, &(mut x, y)) in pos.iter().enumerate() {
        if close {
            x += if i == 0 { -0.7 * r } else { 0.7 * r };
        }
        c.ringed_circle(x, y, r, 1.5, Colour::Dark, Colour::agent(i));
        draw_text_centred(c, x, y, if i == 0 { "0" } else { "1" }, 2, Colour::White);
        let mut slot = 0.0;
        for (k, &count) in env.turtlebot(i).basket.iter().enumerate() {
            if count > 0.0 {
                let sx = if i == 0 { x - r - 5.0 } else { x + r + 5.0 };
                c.centred_square(
                    sx,
                    y - r + 4.0 + 9.0 * slot,
                    8,
                    Colour::tool(k),
                    Colour::Dark,
                );
                slot += 1.0;
            }
        }
    }
}

/// The picture of `env`'s current state.
pub fn draw(env: &Warehouse) -> Picture {
    let (w, h) = world_px();
    let mut c = Canvas::new(w, h, Colour::Background);
    draw_rooms(&mut c);
    draw_fetch(&mut c, env);
    draw_human(&mut c, env);
    draw_turtlebots(&mut c, env);
    Picture {
        world: c,
        agent_labels: &LABELS,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::warehouse::TURTLEBOT_STARTS;
    use crate::envs::{EnvRng, MacroEnv};
    use rand::SeedableRng;

    fn at(c: &Canvas, p: (f64, f64)) -> Option<Colour> {
        c.pixel(p.0 as usize, p.1 as usize)
    }

    #[test]
    fn reset_frame_shows_robots_table_and_rooms_where_the_spec_puts_them() {
        let env = Warehouse::paper(150).unwrap();
        let c = draw(&env).world;
        assert_eq!((c.width(), c.height() >= 300), (420, true));
        // Turtlebots: the "0"/"1" label sits on the centre, so look left of it.
        for (i, colour) in [(0, Colour::Agent0), (1, Colour::Agent1)] {
            let (x, y) = to_px(TURTLEBOT_STARTS[i]);
            assert_eq!(at(&c, (x - 7.0, y)), Some(colour), "T{i}");
        }
        let (fx, fy) = to_px(FETCH_POS);
        assert_eq!(at(&c, (fx - 9.0, fy)), Some(Colour::Fetch));
        assert_eq!(at(&c, to_px([1.75, 1.2])), Some(Colour::Table));
        assert_eq!(at(&c, to_px([6.8, 3.3])), Some(Colour::Workshop));
        assert_eq!(at(&c, to_px([4.5, 1.0])), Some(Colour::Background));
        assert_eq!(
            at(&c, to_px([2.5, 3.5])),
            Some(Colour::Red),
            "tool-room waypoint"
        );
        // Human on work step 0 with time left: first bar square green, tool 0 still missing.
        let (bar_x, _) = to_px([5.15, 0.0]);
        assert_eq!(at(&c, (bar_x + 7.0, 13.0)), Some(Colour::Working));
        assert_eq!(at(&c, (bar_x + 27.0, 13.0)), Some(Colour::GridLine));
    }

    #[test]
    fn staged_tools_fill_the_slots_in_their_colours() {
        // The Fetch searches tool 1 (6 steps) while the Turtlebots drive to the tool room.
        let mut env = Warehouse::paper(150).unwrap();
        let mut rng = EnvRng::seed_from_u64(0);
        env.reset(&mut rng);
        let c = draw(&env).world;
        assert_eq!(at(&c, to_px(STAGING[0])), Some(Colour::Table), "empty slot");
        for _ in 0..6 {
            env.step(&[1, 1, 4], &mut rng).unwrap();
        }
        assert_eq!(env.fetch().staged(), &[1]);
        let c = draw(&env).world;
        assert_eq!(at(&c, to_px(STAGING[0])), Some(Colour::Tool1));
        assert_eq!(at(&c, to_px(STAGING[1])), Some(Colour::Table));
    }
}
