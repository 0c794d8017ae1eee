//! What agents perceive. Two views, both laid out as the reference's `itemList` (the foods:
//! x, y, chop progress; the plates, the knives, the delivery, the agents: x, y), then under
//! `Overcooked_V1` the task's one-hot over `TASKLIST` (ACAC's `Overcooked_V0` has none):
//!
//! - the **belief** (`agent.obs` and `agent.pomap`, `Overcooked_V1._get_vector_obs`), updated
//!   after every primitive step: items within `obs_radius` (Chebyshev) at their true places,
//!   others where last seen (back at their start when that place is in view and they are not
//!   there). Macro-actions read their targets from it and navigate on its map. A remembered
//!   chop progress is divided by 3 again at each step out of view (the reference's quirk:
//!   it divides the stored fraction, not the count).
//! - the **macro-observation** (`_get_macro_vector_obs`), what a policy sees: refreshed only
//!   when the agent's macro-action ends, true values in view and zeros elsewhere.
//!
//! Both are computed in f64 as the reference computes them (the belief's round trips through
//! `x * xlen` decide map cells, so they must be bit-exact).

use serde::{Deserialize, Serialize};

use super::layout::{Cells, Tile};
use super::world::{Cell, Kit, World, REQUIRED_CHOPS};

/// The reference's `TASKLIST`, in one-hot order.
pub const TASKS: [&str; 7] = [
    "tomato salad",
    "lettuce salad",
    "onion salad",
    "lettuce-tomato salad",
    "onion-tomato salad",
    "lettuce-onion salad",
    "lettuce-onion-tomato salad",
];

/// Length of an observation with `n_agent` agents in a kitchen holding `kit`: foods x 3,
/// plates, knives, the delivery and agents x 2, and under V1 the 7 task flags (V1: 32 for 3
/// agents, 30 for 2; ACAC's Large kitchen: 48).
pub fn obs_len(n_agent: usize, kit: &Kit) -> usize {
    3 * kit.n_foods + 2 * (kit.n_plates + kit.n_knives + 1 + n_agent) + task_len(kit)
}

/// Length of the task one-hot: 7 under V1, none under V0.
pub fn task_len(kit: &Kit) -> usize {
    match kit.rules {
        super::layout::Rules::V1 => TASKS.len(),
        super::layout::Rules::V0 => 0,
    }
}

/// One agent's belief: its last vector observation and the map it navigates on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Belief {
    /// The last vector observation, as the reference's `_get_vector_obs` builds it.
    pub obs: Vec<f64>,
    /// The map as the agent last saw it, which it navigates on.
    pub pomap: Cells,
}

/// Whether `c` is within `radius` of `a` in both coordinates (radius 0: everything).
pub fn in_view(a: Cell, c: Cell, radius: i32) -> bool {
    radius == 0 || ((c.x - a.x).abs() <= radius && (c.y - a.y).abs() <= radius)
}

/// Write the task one-hot at the end of `out` (`oneHotTask`; all zero for a task not listed;
/// nothing under V0).
fn write_task<T: From<u8>>(out: &mut [T], task: &str, kit: &Kit) {
    if task_len(kit) == 0 {
        return;
    }
    let start = out.len() - TASKS.len();
    for (k, t) in TASKS.iter().enumerate() {
        out[start + k] = T::from(u8::from(*t == task));
    }
}

/// The full observation `_initObs` gives every agent at reset: every item's true place.
pub fn reset_belief(w: &World, task: &str, b: &mut Belief) {
    let (xl, yl) = (w.side as f64, w.side as f64);
    let mut idx = 0;
    for k in 0..w.n_items() {
        let (at, _) = w.item(k);
        b.obs[idx] = f64::from(at.x) / xl;
        b.obs[idx + 1] = f64::from(at.y) / yl;
        idx += 2;
        if let Some(f) = w.item_food(k) {
            b.obs[idx] = f64::from(w.foods[f].chops) / f64::from(REQUIRED_CHOPS);
            idx += 1;
        }
    }
    write_task(&mut b.obs, task, &w.kit);
}

/// Agent `agent`'s belief after a step (`_get_vector_obs`), from its previous one, in place.
pub fn update_belief(w: &World, agent: usize, base: &Cells, radius: i32, b: &mut Belief) {
    let (xl, yl) = (w.side as f64, w.side as f64);
    let me = w.cooks[agent].at;
    let (lo_x, hi_x) = (f64::from(me.x - radius), f64::from(me.x + radius));
    let (lo_y, hi_y) = (f64::from(me.y - radius), f64::from(me.y + radius));
    b.pomap = *base;
    let mut idx = 0;
    for k in 0..w.n_items() {
        let (at, start) = w.item(k);
        let food = w.item_food(k);
        let (x, y);
        if in_view(me, at, radius) {
            x = f64::from(at.x) / xl;
            y = f64::from(at.y) / yl;
            if let Some(f) = food {
                b.obs[idx + 2] = f64::from(w.foods[f].chops) / f64::from(REQUIRED_CHOPS);
            }
        } else {
            let (mut px, mut py) = (b.obs[idx] * xl, b.obs[idx + 1] * yl);
            if px >= lo_x && px <= hi_x && py >= lo_y && py <= hi_y {
                px = f64::from(start.x);
                py = f64::from(start.y);
            }
            x = px / xl;
            y = py / yl;
            if food.is_some() {
                b.obs[idx + 2] /= f64::from(REQUIRED_CHOPS);
            }
        }
        b.obs[idx] = x;
        b.obs[idx + 1] = y;
        idx += if food.is_some() { 3 } else { 2 };
        paint(
            &mut b.pomap,
            w.side,
            (x * xl) as i64,
            (y * yl) as i64,
            w.item_tile(k),
        );
    }
    paint(
        &mut b.pomap,
        w.side,
        i64::from(me.x),
        i64::from(me.y),
        Tile::Agent,
    );
}

/// `pomap[x][y] = tile` (Python's `int()` truncates as `as` does; off-grid is ignored).
fn paint(map: &mut Cells, side: usize, x: i64, y: i64, tile: Tile) {
    if x >= 0 && y >= 0 && (x as usize) < side && (y as usize) < side {
        map[x as usize][y as usize] = tile;
    }
}

/// Agent `agent`'s macro-observation (`_get_macro_vector_obs`) into `out`.
pub fn macro_obs(w: &World, agent: usize, radius: i32, task: &str, out: &mut [f32]) {
    let (xl, yl) = (w.side as f64, w.side as f64);
    let me = w.cooks[agent].at;
    let mut idx = 0;
    for k in 0..w.n_items() {
        let (at, _) = w.item(k);
        let seen = in_view(me, at, radius);
        out[idx] = if seen {
            (f64::from(at.x) / xl) as f32
        } else {
            0.0
        };
        out[idx + 1] = if seen {
            (f64::from(at.y) / yl) as f32
        } else {
            0.0
        };
        idx += 2;
        if let Some(f) = w.item_food(k) {
            out[idx] = if seen {
                (f64::from(w.foods[f].chops) / f64::from(REQUIRED_CHOPS)) as f32
            } else {
                0.0
            };
            idx += 1;
        }
    }
    write_task(out, task, &w.kit);
}

/// ACAC's `get_vector_state()` into `out`: every item at its true place (x / side, y / side, and
/// chop progress for the foods), in the observation's layout without the task one-hot.
pub fn vector_state(w: &World, out: &mut [f32]) {
    let (xl, yl) = (w.side as f64, w.side as f64);
    let mut idx = 0;
    for k in 0..w.n_items() {
        let (at, _) = w.item(k);
        out[idx] = (f64::from(at.x) / xl) as f32;
        out[idx + 1] = (f64::from(at.y) / yl) as f32;
        idx += 2;
        if let Some(f) = w.item_food(k) {
            out[idx] = (f64::from(w.foods[f].chops) / f64::from(REQUIRED_CHOPS)) as f32;
            idx += 1;
        }
    }
}

/// Names of the observation's entries, in layout order, for `foods` (their names) in a kitchen
/// holding `kit`.
pub fn obs_names(n_agent: usize, foods: &[&str], kit: &Kit) -> Vec<String> {
    let mut names = vec![];
    for f in foods {
        names.extend([format!("{f}_x"), format!("{f}_y"), format!("{f}_chopped")]);
    }
    let fixed = (1..=kit.n_plates)
        .map(|k| format!("plate{k}"))
        .chain((1..=kit.n_knives).map(|k| format!("knife{k}")))
        .chain(["delivery".to_string()]);
    for item in fixed.chain((0..n_agent).map(|i| format!("agent{i}"))) {
        names.extend([format!("{item}_x"), format!("{item}_y")]);
    }
    if task_len(kit) > 0 {
        names.extend(
            TASKS
                .iter()
                .map(|t| format!("task_{}", t.replace(' ', "_"))),
        );
    }
    names
}

#[cfg(test)]
mod tests {
    use super::super::layout::Rules;
    use super::super::world::FOOD_NAMES;
    use super::*;

    #[test]
    fn sizes_are_32_for_three_agents_and_30_for_two() {
        assert_eq!(obs_len(3, &Kit::V1), 32);
        assert_eq!(obs_len(2, &Kit::V1), 30);
        assert_eq!(obs_names(3, &FOOD_NAMES, &Kit::V1).len(), 32);
        assert_eq!(
            obs_names(2, &FOOD_NAMES, &Kit::V1)[29],
            "task_lettuce-onion-tomato_salad"
        );
    }

    /// spec acac_envs.md §Overcooked-MA-v0: 48 values, no task one-hot.
    #[test]
    fn the_large_kitchen_observes_48_values() {
        let kit = Kit {
            rules: Rules::V0,
            n_foods: 6,
            n_plates: 4,
            n_knives: 4,
        };
        assert_eq!(obs_len(6, &kit), 48);
        let names = obs_names(6, &["A", "B", "C", "D", "E", "F"], &kit);
        assert_eq!(names.len(), 48);
        assert_eq!(names[18], "plate1_x");
        assert_eq!(names[34], "delivery_x");
        assert_eq!(names[47], "agent5_y");
    }
}
