//! The kitchen as text, for `--verbose` replays and debugging: one character per cell of the
//! map (`#` counter, `.` floor, `K` knife, `D` delivery, `t`/`l`/`o` food, `p` plate, agents by
//! index), then what agents, knives and plates hold and how far each food is chopped.

use std::fmt::Write;

use super::layout::Tile;
use super::world::{Cell, Held, World, FOOD_NAMES};

fn held(h: Option<Held>) -> String {
    match h {
        None => "-".into(),
        Some(Held::Food(k)) => FOOD_NAMES[k].into(),
        Some(Held::Plate(p)) => format!("plate {}", p + 1),
    }
}

/// The picture of `w`.
pub fn render(w: &World) -> String {
    let mut s = String::new();
    for x in 0..w.side {
        for y in 0..w.side {
            let c = Cell::new(x as i32, y as i32);
            let ch = match w.cook_at(c) {
                Some(i) => char::from_digit(i as u32, 10).unwrap_or('A'),
                None => match w.tile(c) {
                    Tile::Space => '.',
                    Tile::Counter => '#',
                    Tile::Agent => 'a',
                    Tile::Tomato => 't',
                    Tile::Lettuce => 'l',
                    Tile::Onion => 'o',
                    Tile::Plate => 'p',
                    Tile::Knife => 'K',
                    Tile::Delivery => 'D',
                },
            };
            s.push(ch);
        }
        s.push('\n');
    }
    for (i, c) in w.cooks.iter().enumerate() {
        let _ = writeln!(
            s,
            "agent {i} at ({}, {}) holds {}",
            c.at.x,
            c.at.y,
            held(c.holding)
        );
    }
    for (k, kn) in w.knives.iter().enumerate() {
        let _ = writeln!(s, "knife {} holds {}", k + 1, held(kn.holding));
    }
    for (k, f) in w.foods.iter().enumerate() {
        let _ = writeln!(
            s,
            "{} at ({}, {}) chopped {}/3",
            FOOD_NAMES[k], f.at.x, f.at.y, f.chops
        );
    }
    s
}
