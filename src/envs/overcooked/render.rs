//! The kitchen as text, for `--verbose` replays and debugging: one character per cell of the
//! map (`#` counter, `.` floor, `K` knife, `D` delivery, `t`/`l`/`o` food (the Large kitchen:
//! its objects' names, lower case), `p` plate, agents by index), then what agents, knives and plates hold and how far each food is chopped.

use std::fmt::Write;

use super::layout::Rules;
use super::layout::Tile;
use super::world::{Cell, Held, World, FOOD_NAMES};

/// The name of food `k`: V1's, or under V0 the letter of `obj` order ("A".."F" as ACAC's
/// settings name them; the kitchen keeps no names).
fn food_name(w: &World, k: usize) -> String {
    match w.kit.rules {
        Rules::V1 => FOOD_NAMES[k].into(),
        Rules::V0 => format!("object {}", k + 1),
    }
}

fn held(w: &World, h: Option<Held>) -> String {
    match h {
        None => "-".into(),
        Some(Held::Food(k)) => food_name(w, k),
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
                    Tile::Food(k) => match w.kit.rules {
                        Rules::V1 => ['t', 'l', 'o'][usize::from(k).min(2)],
                        Rules::V0 => char::from(b'a' + k),
                    },
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
            held(w, c.holding)
        );
    }
    for (k, kn) in w.knives.iter().enumerate().take(w.kit.n_knives) {
        let _ = writeln!(s, "knife {} holds {}", k + 1, held(w, kn.holding));
    }
    for (k, f) in w.foods.iter().enumerate().take(w.kit.n_foods) {
        // A Large kitchen's fresh object counts as chopped (spec acac_envs.md §Overcooked-MA-v0).
        let fresh_chopped = if f.chopped && f.chops < 3 {
            " (fresh, counts as chopped)"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "{} at ({}, {}) chopped {}/3{fresh_chopped}",
            food_name(w, k),
            f.at.x,
            f.at.y,
            f.chops
        );
    }
    s
}
