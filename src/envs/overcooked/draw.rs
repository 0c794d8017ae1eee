//! One Overcooked frame for `macdec render`: the kitchen as the reference's figures show it,
//! rows of the map from the top (`x`) and columns from the left (`y`). Counters are wood,
//! cutting boards grey with a knife, the delivery counter yellow; tomatoes red, lettuces green,
//! onions purple (three slices once chopped, ticks for the chops so far); plates white with
//! what is on them; agents in their colours with what they carry drawn on them.

use super::layout::Tile;
use super::world::{Cell, Held, World};
use super::Overcooked;
use crate::draw::{Canvas, Colour, Picture};

/// Status-bar labels of the agents.
pub static LABELS: [&str; 6] = ["A0", "A1", "A2", "A3", "A4", "A5"];

/// Colours of the foods, in item order (tomato, lettuce, onion; the Large kitchen's objects
/// "A".."F" take these, then the tools' colours).
const FOOD_COLOURS: [Colour; 6] = [
    Colour::Red,
    Colour::Working,
    Colour::Human,
    Colour::Tool0,
    Colour::Tool1,
    Colour::Tool2,
];

/// Pixels per cell side: 48 on the 7 x 7 kitchens, 40 on 9 x 9, 32 on 11 x 11.
pub fn cell_px(side: usize) -> i64 {
    match side {
        0..=7 => 48,
        8..=9 => 40,
        _ => 32,
    }
}

/// Pixel geometry of a kitchen.
#[derive(Debug, Clone, Copy)]
struct Grid {
    cell: i64,
}

impl Grid {
    /// Top-left pixel of `c`.
    fn origin(&self, c: Cell) -> (i64, i64) {
        (i64::from(c.y) * self.cell, i64::from(c.x) * self.cell)
    }

    /// Centre of `c`.
    fn centre(&self, c: Cell) -> (f64, f64) {
        let (x, y) = self.origin(c);
        let half = self.cell as f64 / 2.0 + 0.5;
        (x as f64 + half, y as f64 + half)
    }
}

/// A food at (cx, cy): a whole disc, or three slices once chopped.
fn draw_food(canvas: &mut Canvas, cx: f64, cy: f64, r: f64, k: usize, chopped: bool) {
    let c = FOOD_COLOURS[k];
    if chopped {
        let s = r * 0.45;
        for (dx, dy) in [(-0.5, 0.3), (0.5, 0.3), (0.0, -0.45)] {
            canvas.ringed_circle(cx + dx * r, cy + dy * r, s, 1.0, Colour::Dark, c);
        }
    } else {
        canvas.ringed_circle(cx, cy, r, 1.0, Colour::Dark, c);
    }
}

/// A plate at (cx, cy) with the foods it holds as small slices.
fn draw_plate(canvas: &mut Canvas, w: &World, cx: f64, cy: f64, r: f64, p: usize) {
    canvas.ringed_circle(cx, cy, r, 1.0, Colour::Dark, Colour::White);
    let spots = [
        (-0.4, 0.25),
        (0.4, 0.25),
        (0.0, -0.4),
        (-0.4, -0.2),
        (0.4, -0.2),
        (0.0, 0.45),
    ];
    for (k, &(dx, dy)) in spots.iter().enumerate().take(w.kit.n_foods) {
        if w.plates[p].holds[k] {
            canvas.fill_circle(cx + dx * r, cy + dy * r, r * 0.3, FOOD_COLOURS[k]);
        }
    }
}

/// What an agent, a knife or a counter shows of `h` at (cx, cy).
fn draw_thing(canvas: &mut Canvas, w: &World, cx: f64, cy: f64, r: f64, h: Held) {
    match h {
        Held::Food(k) => draw_food(canvas, cx, cy, r, k, w.foods[k].chopped),
        Held::Plate(p) => draw_plate(canvas, w, cx, cy, r, p),
    }
}

/// The fixed cells: floor, counters, cutting boards and the delivery counter.
fn draw_cells(canvas: &mut Canvas, w: &World, g: Grid) {
    let fixed = |c: Cell| {
        if w.knife_at(c).is_some() {
            Tile::Knife
        } else if w.delivery.at == c {
            Tile::Delivery
        } else {
            match w.tile(c) {
                Tile::Space | Tile::Agent => Tile::Space,
                _ => Tile::Counter,
            }
        }
    };
    for x in 0..w.side as i32 {
        for y in 0..w.side as i32 {
            let c = Cell::new(x, y);
            let (px, py) = g.origin(c);
            let inner = g.cell - 1;
            match fixed(c) {
                Tile::Space => {}
                Tile::Knife => {
                    canvas.fill_rect(px, py, g.cell, g.cell, Colour::Table);
                    let inset = g.cell / 8;
                    canvas.fill_rect(
                        px + inset,
                        py + inset,
                        g.cell - 2 * inset,
                        g.cell - 2 * inset,
                        Colour::GridLine,
                    );
                    let (cx, cy) = g.centre(c);
                    let l = g.cell as f64 * 0.35;
                    canvas.line(
                        cx - l,
                        cy + l,
                        cx - l * 0.2,
                        cy + l * 0.2,
                        2.0,
                        Colour::Dark,
                    );
                }
                Tile::Delivery => {
                    canvas.fill_rect(px, py, g.cell, g.cell, Colour::Goal);
                    canvas.outline_rect(px + 3, py + 3, inner - 5, inner - 5, 2, Colour::Dark);
                }
                _ => canvas.fill_rect(px, py, g.cell, g.cell, Colour::Table),
            }
        }
    }
    let side = w.side as i64 * g.cell + 1;
    for k in 0..=w.side as i64 {
        canvas.fill_rect(k * g.cell, 0, 1, side, Colour::GridLine);
        canvas.fill_rect(0, k * g.cell, side, 1, Colour::GridLine);
    }
    canvas.outline_rect(0, 0, side, side, 1, Colour::Dark);
}

/// The picture of `env`'s current state.
pub fn draw(env: &Overcooked) -> Picture {
    let w = env.world();
    let g = Grid {
        cell: cell_px(w.side),
    };
    let side = (w.side as i64 * g.cell + 1) as usize;
    let mut canvas = Canvas::new(side, side, Colour::Background);
    draw_cells(&mut canvas, w, g);
    let r = g.cell as f64 * 0.3;
    let carried = |h: Held| w.cooks.iter().any(|c| c.holding == Some(h));
    let on_plate = |k: usize| w.plates.iter().any(|p| p.holds[k]);
    for p in 0..w.kit.n_plates {
        if !carried(Held::Plate(p)) {
            let (cx, cy) = g.centre(w.plates[p].at);
            draw_plate(&mut canvas, w, cx, cy, r, p);
        }
    }
    for (k, f) in w.foods.iter().enumerate().take(w.kit.n_foods) {
        if carried(Held::Food(k)) || on_plate(k) {
            continue;
        }
        let (cx, cy) = g.centre(f.at);
        draw_food(&mut canvas, cx, cy, r * 0.8, k, f.chopped);
        // One tick per chop so far, along the cell's bottom.
        let (px, py) = g.origin(f.at);
        for n in 0..i64::from(f.chops.min(3)) {
            canvas.fill_rect(px + 4 + n * 6, py + g.cell - 6, 4, 3, Colour::Dark);
        }
    }
    for (i, c) in w.cooks.iter().enumerate() {
        let (cx, cy) = g.centre(c.at);
        canvas.ringed_circle(
            cx,
            cy,
            g.cell as f64 * 0.42,
            2.0,
            Colour::Dark,
            Colour::robot(i),
        );
        if let Some(h) = c.holding {
            draw_thing(&mut canvas, w, cx, cy, r * 0.8, h);
        }
    }
    Picture {
        world: canvas,
        agent_labels: &LABELS[..w.cooks.len()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::overcooked::OvercookedParams;

    #[test]
    fn agents_counters_and_the_delivery_are_where_the_map_puts_them() {
        let env = Overcooked::new(OvercookedParams::default()).unwrap();
        let pic = draw(&env);
        assert_eq!(pic.world.width(), 7 * 48 + 1);
        assert_eq!(pic.agent_labels, ["A0", "A1", "A2"]);
        let at = |c: Cell| {
            let (x, y) = Grid { cell: 48 }.centre(c);
            pic.world.pixel(x as usize, y as usize)
        };
        // Agents (1,2), (1,4), (5,2) in their colours; the delivery counter (3,0); a counter
        // (6,0); floor (3,3); the tomato (0,5) red.
        assert_eq!(at(Cell::new(1, 2)), Some(Colour::Agent0));
        assert_eq!(at(Cell::new(1, 4)), Some(Colour::Agent1));
        assert_eq!(at(Cell::new(5, 2)), Some(Colour::Agent2));
        assert_eq!(at(Cell::new(3, 0)), Some(Colour::Goal));
        assert_eq!(at(Cell::new(6, 0)), Some(Colour::Table));
        assert_eq!(at(Cell::new(3, 3)), Some(Colour::Background));
        assert_eq!(at(Cell::new(0, 5)), Some(Colour::Red));
        assert_eq!(at(Cell::new(5, 6)), Some(Colour::White));
    }

    #[test]
    fn the_large_kitchen_draws_its_six_agents_and_objects() {
        let params = OvercookedParams {
            side: 11,
            n_agent: 6,
            large: Some(crate::envs::overcooked::LargeKitchen::default()),
            ..OvercookedParams::default()
        };
        let env = Overcooked::new(params).unwrap();
        let pic = draw(&env);
        assert_eq!(pic.world.width(), 11 * 32 + 1);
        assert_eq!(pic.agent_labels.len(), 6);
        let at = |c: Cell| {
            let (x, y) = Grid { cell: 32 }.centre(c);
            pic.world.pixel(x as usize, y as usize)
        };
        // The delivery (5,0), floor (5,5); object A (1,10) in the first food colour (as slices:
        // fresh objects count as chopped), object F (0,7) in the sixth.
        assert_eq!(at(Cell::new(5, 0)), Some(Colour::Goal));
        assert_eq!(at(Cell::new(5, 5)), Some(Colour::Background));
        let shows = |c: Cell, colour: Colour| {
            let (px, py) = Grid { cell: 32 }.origin(c);
            (0..32).any(|dx| {
                (0..32).any(|dy| {
                    pic.world.pixel((px + dx) as usize, (py + dy) as usize) == Some(colour)
                })
            })
        };
        assert!(shows(Cell::new(1, 10), Colour::Red));
        assert!(shows(Cell::new(0, 7), Colour::Tool2));
        assert!(!shows(Cell::new(0, 7), Colour::Red));
    }
}
