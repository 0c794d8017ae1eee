//! One Warehouse frame in the style of the reference's renderer: the floor (7 m x 5 m with two
//! rooms, 9 m wide with three or four), the tool room left of the dashed wall at x = 3.5 with
//! the table and the Fetch's two staging slots, each human's room (the box around its work
//! area) with its work-step bar and the tool it needs next, the red waypoints, the Fetch (gray;
//! a ring in the colour of the tool it looks for, an arm toward the Turtlebot it passes to) and
//! the Turtlebots with the tools in their baskets. Tools are coloured by index everywhere.

use super::layout::{Layout, FETCH_POS, N_WORK_STEPS};
use super::{FetchAction, Osd};
use crate::draw::font::draw_text_centred;
use crate::draw::{Canvas, Colour, Picture};
use crate::envs::warehouse::draw::{to_px, world_rect, PX_PER_M, WORLD_H_M};

const TB_RADIUS_M: f64 = 0.17;
const FETCH_RADIUS_M: f64 = 0.25;
/// Centres of the two staging slots on the table, first-to-pass first.
const STAGING: [[f64; 2]; 2] = [[1.75, 2.75], [1.75, 2.25]];

const LABELS_2: [&str; 3] = ["T0", "T1", "F"];
const LABELS_3: [&str; 4] = ["T0", "T1", "T2", "F"];

/// The room of the human working at `area`: 2 m wide around it, along the top or bottom wall.
pub fn room_of(area: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    if area[1] >= 2.5 {
        ([area[0] - 1.0, 3.0], [area[0] + 1.0, 5.0])
    } else {
        ([area[0] - 1.0, 0.0], [area[0] + 1.0, 2.0])
    }
}

fn draw_rooms(c: &mut Canvas, layout: &Layout) {
    let (w, h) = (c.width() as f64, c.height() as f64);
    for &area in layout.work_areas {
        let (lo, hi) = room_of(area);
        world_rect(c, lo, hi, Colour::Workshop, Some(Colour::Dark));
    }
    let (wall_x, _) = to_px([3.5, 0.0]);
    c.dashed_line(wall_x, 0.0, wall_x, h, 2.0, 6.0, 5.0, Colour::Dark);
    c.outline_rect(0, 0, w as i64, h as i64, 3, Colour::Dark);
    world_rect(
        c,
        [1.45, 1.6],
        [2.05, 3.4],
        Colour::Table,
        Some(Colour::Dark),
    );
    let mut dot = |p: [f64; 2]| {
        let (x, y) = to_px(p);
        c.fill_circle(x, y, 4.0, Colour::Red);
    };
    layout.work_areas.iter().for_each(|&p| dot(p));
    dot(layout.tool_room_wait);
    layout.tables.iter().for_each(|&p| dot(p));
}

fn draw_fetch<const V: usize>(c: &mut Canvas, env: &Osd<V>) {
    let layout = Osd::<V>::layout();
    let fetch = env.fetch();
    let (fx, fy) = to_px(FETCH_POS);
    let r = FETCH_RADIUS_M * PX_PER_M;
    if let (Some(a), false) = (fetch.cur_action, fetch.done) {
        match FetchAction::of(a, layout.n_turtlebots()) {
            FetchAction::Look(j) => c.fill_circle(fx, fy, r + 5.0, Colour::tool(j)),
            FetchAction::Pass(k) => {
                let (tx, ty) = to_px(layout.tables[k]);
                let (ax, ay) = (fx + 0.75 * (tx - fx), fy + 0.75 * (ty - fy));
                c.line(fx, fy, ax, ay, 6.0, Colour::Dark);
                c.line(fx, fy, ax, ay, 3.0, Colour::Fetch);
            }
            FetchAction::Wait => {}
        }
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

fn draw_humans<const V: usize>(c: &mut Canvas, env: &Osd<V>) {
    let layout = Osd::<V>::layout();
    for (human, &area) in env.humans().iter().zip(layout.work_areas) {
        let (lo, hi) = room_of(area);
        let top = area[1] >= 2.5;
        let (hx, hy) = to_px([area[0] + 0.35, if top { 3.9 } else { 1.1 }]);
        c.fill_circle(hx, hy - 16.0, 6.5, Colour::Human);
        c.fill_rect(hx as i64 - 6, hy as i64 - 9, 13, 22, Colour::Human);
        // Work steps: done dark, current green while its time runs, red while waiting.
        let (bar_x, bar_y) = to_px([lo[0] + 0.15, if top { hi[1] - 0.2 } else { lo[1] + 0.2 }]);
        for k in 0..N_WORK_STEPS {
            let colour = if human.finished || k < human.cur_step {
                Colour::Dark
            } else if k > human.cur_step {
                Colour::GridLine
            } else if human.time_left <= 0.0 && !human.obtained {
                Colour::Red
            } else {
                Colour::Working
            };
            c.centred_square(
                bar_x + 7.0 + 20.0 * k as f64,
                bar_y,
                14,
                colour,
                Colour::Dark,
            );
        }
        // The tool needed to leave this step: hollow until delivered.
        if !human.finished && human.cur_step + 1 < N_WORK_STEPS {
            let (x, y) = ((hx + 16.0) as i64, (hy - 7.0) as i64);
            c.fill_rect(x, y, 14, 14, Colour::tool(human.need));
            if !human.obtained {
                c.fill_rect(x + 3, y + 3, 8, 8, Colour::Workshop);
            }
        }
    }
}

fn draw_turtlebots<const V: usize>(c: &mut Canvas, env: &Osd<V>) {
    let r = TB_RADIUS_M * PX_PER_M;
    for (i, tb) in env.turtlebots().iter().enumerate() {
        let (x, y) = to_px(tb.pos);
        c.ringed_circle(x, y, r, 1.5, Colour::Dark, Colour::robot(i));
        let text = if i < 2 { Colour::White } else { Colour::Dark };
        draw_text_centred(c, x, y, &i.to_string(), 2, text);
        let mut slot = 0.0;
        for (k, &count) in tb.basket.iter().enumerate() {
            if count > 0.0 {
                c.centred_square(
                    x + r + 5.0,
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
pub fn draw<const V: usize>(env: &Osd<V>) -> Picture {
    let layout = Osd::<V>::layout();
    let w = (layout.world_width_m() * PX_PER_M).round() as usize;
    let h = (WORLD_H_M * PX_PER_M).round() as usize;
    let mut c = Canvas::new(w, h, Colour::Background);
    draw_rooms(&mut c, layout);
    draw_fetch(&mut c, env);
    draw_humans(&mut c, env);
    draw_turtlebots(&mut c, env);
    Picture {
        world: c,
        agent_labels: if layout.n_turtlebots() == 2 {
            &LABELS_2
        } else {
            &LABELS_3
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::osd::{OsdD7, OsdF0};
    use crate::envs::{EnvRng, MacroEnv};
    use rand::SeedableRng;

    fn at(c: &Canvas, p: (f64, f64)) -> Option<Colour> {
        c.pixel(p.0 as usize, p.1 as usize)
    }

    #[test]
    fn reset_frame_shows_robots_rooms_and_table() {
        let env = OsdD7::published(200).unwrap();
        let c = draw(&env).world;
        assert_eq!((c.width(), c.height()), (420, 300));
        for (i, colour) in [(0, Colour::Agent0), (1, Colour::Agent1)] {
            let (x, y) = to_px(OsdD7::layout().tb_starts[i]);
            assert_eq!(at(&c, (x - 7.0, y)), Some(colour), "T{i}");
        }
        let (fx, fy) = to_px(FETCH_POS);
        assert_eq!(at(&c, (fx - 9.0, fy)), Some(Colour::Fetch));
        assert_eq!(at(&c, to_px([1.75, 1.9])), Some(Colour::Table));
        assert_eq!(at(&c, to_px([6.8, 4.3])), Some(Colour::Workshop), "room 0");
        assert_eq!(at(&c, to_px([6.8, 0.7])), Some(Colour::Workshop), "room 1");
        assert_eq!(at(&c, to_px([4.5, 2.5])), Some(Colour::Background));
        let f = OsdF0::published(300).unwrap();
        let c = draw(&f).world;
        assert_eq!(c.width(), 540);
        assert_eq!(draw(&f).agent_labels.len(), 4);
    }

    #[test]
    fn staged_tools_fill_the_slots_in_their_colours() {
        let mut env = OsdD7::published(200).unwrap();
        let mut rng = EnvRng::seed_from_u64(0);
        env.reset(&mut rng);
        for _ in 0..6 {
            env.step(&[2, 2, 4], &mut rng).unwrap();
        }
        assert_eq!(env.fetch().staged(), &[1]);
        let c = draw(&env).world;
        assert_eq!(at(&c, to_px(STAGING[0])), Some(Colour::Tool1));
        assert_eq!(at(&c, to_px(STAGING[1])), Some(Colour::Table));
    }
}
