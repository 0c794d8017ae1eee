//! The primitive step (`Overcooked_V1.step`, ACAC's `Overcooked_V0.step`): agents act in index
//! order, each once; an agent walking into another that has not acted yet waits for it (a swap
//! when the other walks into it; under V0 also a closed chain of agents each walking into the
//! next one's cell, which all move at once), and walking into a non-floor cell picks up, puts
//! down, chops or delivers.

use serde::{Deserialize, Serialize};

use super::layout::{Rules, Tile, MAX_AGENTS, MAX_FOODS};
use super::world::{Cell, Held, World, DIRECTION, FOOD_NAMES};

/// The reference's `rewardList`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rewards {
    /// "subtask finished": a food of the task chopped through.
    pub subtask_finished: f64,
    /// "correct delivery": the task's dish delivered (terminal).
    pub correct_delivery: f64,
    /// "wrong delivery": anything else handed to the delivery counter.
    pub wrong_delivery: f64,
    /// "step penalty": every primitive step.
    pub step_penalty: f64,
}

impl Default for Rewards {
    /// MacroMARL's values (`pg_based_main.py`, with its default `--step_penalty`).
    fn default() -> Self {
        Rewards {
            subtask_finished: 10.0,
            correct_delivery: 200.0,
            wrong_delivery: -5.0,
            step_penalty: -0.1,
        }
    }
}

/// Whether a plate holding `holds` (flags in food order) is `Overcooked_V1`'s dish `task`: the reference
/// names the dish by its foods' names in the order lettuce, onion, tomato, joined by `-`, then
/// " salad" (the delivery branch of `step`), and compares the name with the task. Compared
/// piece by piece here, so a delivery allocates nothing.
pub fn is_dish(holds: &[bool], task: &str) -> bool {
    let Some(mut rest) = task.strip_suffix(" salad") else {
        return false;
    };
    let mut first = true;
    for k in [1, 2, 0] {
        if !holds[k] {
            continue;
        }
        if !first {
            let Some(r) = rest.strip_prefix('-') else {
                return false;
            };
            rest = r;
        }
        first = false;
        let Some(r) = rest.strip_prefix(FOOD_NAMES[k]) else {
            return false;
        };
        rest = r;
    }
    rest.is_empty()
}

/// One primitive step of all agents (`actions[i]`: 0..4 a move as [`DIRECTION`], 4 stay).
/// Returns the team reward and whether the task's dish was delivered.
///
/// The reference loops until every agent has acted; an agent waiting for another is retried
/// in the next pass. On a grid no three agents can wait on each other in a cycle, and V0 moves
/// the cycles of four or six, so passes are bounded; the cap only guards against a state the
/// reference would loop in forever (a V1 kitchen of more than three agents cannot be built).
pub fn primitive_step(w: &mut World, actions: &[u8], task: &str, r: &Rewards) -> (f64, bool) {
    let mut reward = r.step_penalty;
    let mut delivered = false;
    for c in w.cooks.iter_mut() {
        c.moved = false;
    }
    for _pass in 0..=w.cooks.len() * 4 {
        for i in 0..w.cooks.len() {
            if w.cooks[i].moved {
                continue;
            }
            w.cooks[i].moved = true;
            let a = actions[i];
            if a >= 4 {
                continue;
            }
            let target = w.cooks[i].at.plus(DIRECTION[a as usize]);
            match w.tile(target) {
                Tile::Agent => walk_into_agent(w, i, target, actions),
                Tile::Space => {
                    let at = w.cooks[i].at;
                    w.set_tile(at, Tile::Space);
                    w.move_cook(i, target);
                    w.set_tile(target, Tile::Agent);
                }
                tile if w.cooks[i].holding.is_none() => {
                    reward += take_or_chop(w, i, target, tile, task, r);
                }
                tile => {
                    let (dr, done) = put(w, i, target, tile, task, r);
                    reward += dr;
                    delivered |= done;
                }
            }
        }
        if w.cooks.iter().all(|c| c.moved) {
            break;
        }
    }
    (reward, delivered)
}

/// Agent `i` walks into agent `j`'s cell: if `j` has not acted, `i` waits, or swaps with `j`
/// when `j` walks into `i`'s cell; if `j` has acted, `i` stays. Under V0, when `j` walks
/// elsewhere, [`move_cycle`] may move a whole cycle.
fn walk_into_agent(w: &mut World, i: usize, target: Cell, actions: &[u8]) {
    let Some(j) = w.cook_at(target) else { return };
    if w.cooks[j].moved {
        return;
    }
    w.cooks[i].moved = false;
    let b = actions[j];
    if b < 4 {
        let back = w.cooks[j].at.plus(DIRECTION[b as usize]);
        if back == w.cooks[i].at {
            w.move_cook(j, back);
            w.move_cook(i, target);
        } else if w.kit.rules == Rules::V0 {
            move_cycle(w, i, actions);
        }
    }
}

/// ACAC's `four_chain_case`: follow the agents from `i`, each walking into the cell (the map
/// shows an agent there) of the first agent standing in it, for at most `n_agent` links; if
/// the chain comes back to `i`, every agent on it moves one step, in chain order. Agents that
/// already acted this step are followed too, as in the reference.
fn move_cycle(w: &mut World, i: usize, actions: &[u8]) {
    let n = w.cooks.len();
    let mut chain = [0usize; MAX_AGENTS];
    let mut len = 0;
    let mut cur = i;
    let mut closed = false;
    for _ in 0..n {
        chain[len] = cur;
        len += 1;
        let a = actions[cur];
        if a >= 4 {
            break;
        }
        let next = w.cooks[cur].at.plus(DIRECTION[a as usize]);
        if w.tile(next) != Tile::Agent {
            break;
        }
        // The reference would raise on a map showing an agent where none stands.
        let Some(j) = w.cook_at(next) else { return };
        cur = j;
        if cur == i {
            closed = true;
            break;
        }
    }
    if closed {
        for &k in &chain[..len] {
            let to = w.cooks[k].at.plus(DIRECTION[actions[k] as usize]);
            w.move_cook(k, to);
        }
    }
}

/// Empty-handed agent `i` walks into `target` showing `tile`: takes a food or plate from a
/// counter, a plate or chopped food from a knife, or chops the food on a knife. Returns the
/// reward earned ("subtask finished" when a food of the task is chopped through).
fn take_or_chop(w: &mut World, i: usize, target: Cell, tile: Tile, task: &str, r: &Rewards) -> f64 {
    match tile {
        Tile::Food(_) | Tile::Plate => {
            let item = match tile {
                Tile::Food(k) => w.food_at(target, k as usize).map(Held::Food),
                _ => w.plate_at(target).map(Held::Plate),
            };
            // The reference raises here when the map shows an object that is not there.
            if let Some(item) = item {
                w.pickup(i, item);
                w.set_tile(target, Tile::Counter);
            }
            0.0
        }
        Tile::Knife => {
            let Some(k) = w.knife_at(target) else {
                return 0.0;
            };
            match w.knives[k].holding {
                Some(Held::Plate(p)) => {
                    w.knives[k].holding = None;
                    w.pickup(i, Held::Plate(p));
                    0.0
                }
                Some(Held::Food(f)) if w.foods[f].chopped => {
                    w.knives[k].holding = None;
                    w.pickup(i, Held::Food(f));
                    0.0
                }
                Some(Held::Food(f)) => {
                    w.chop(f);
                    // V0's task is `obj`: every food is in it.
                    let needed = w.kit.rules == Rules::V0 || task.contains(FOOD_NAMES[f]);
                    if w.foods[f].chopped && needed {
                        r.subtask_finished
                    } else {
                        0.0
                    }
                }
                None => 0.0,
            }
        }
        _ => 0.0,
    }
}

/// Agent `i`, holding something, walks into `target` showing `tile`: puts it on a counter, a
/// chopped food on a plate or knife, a plate under a chopped food, or delivers. Returns the
/// reward and whether this was the correct delivery.
fn put(w: &mut World, i: usize, target: Cell, tile: Tile, task: &str, r: &Rewards) -> (f64, bool) {
    let Some(held) = w.cooks[i].holding else {
        return (0.0, false);
    };
    match tile {
        Tile::Counter => {
            let shown = match held {
                Held::Food(k) => Tile::Food(k as u8),
                Held::Plate(_) => Tile::Plate,
            };
            w.set_tile(target, shown);
            w.putdown(i, target);
        }
        Tile::Plate => {
            if let Held::Food(f) = held {
                if w.foods[f].chopped {
                    if let Some(p) = w.plate_at(target) {
                        w.putdown(i, target);
                        w.plate_contain(p, f);
                    }
                }
            }
        }
        Tile::Knife => {
            let Some(k) = w.knife_at(target) else {
                return (0.0, false);
            };
            match (w.knives[k].holding, held) {
                (None, _) => {
                    w.putdown(i, target);
                    w.knives[k].holding = Some(held);
                }
                (Some(Held::Food(f)), Held::Plate(p)) if w.foods[f].chopped => {
                    w.knives[k].holding = None;
                    w.plate_contain(p, f);
                }
                (Some(Held::Plate(p)), Held::Food(f)) if w.foods[f].chopped => {
                    w.knives[k].holding = None;
                    w.pickup(i, Held::Plate(p));
                    w.plate_contain(p, f);
                }
                _ => {}
            }
        }
        Tile::Delivery => return deliver(w, i, target, held, task, r),
        Tile::Food(k) => {
            if let (Some(f), Held::Plate(p)) = (w.food_at(target, k as usize), held) {
                if w.foods[f].chopped {
                    w.plate_contain(p, f);
                    w.set_tile(target, Tile::Counter);
                }
            }
        }
        _ => {}
    }
    (0.0, false)
}

/// Agent `i` hands `held` to the delivery counter at `target`. The task's dish stays there
/// (terminal); anything else costs "wrong delivery" and goes back, whole, to where it started.
/// V0's dish is a plate holding as many foods of `obj` as `obj` has: all of them.
fn deliver(
    w: &mut World,
    i: usize,
    target: Cell,
    held: Held,
    task: &str,
    r: &Rewards,
) -> (f64, bool) {
    match held {
        Held::Plate(p) if w.plates[p].holds.iter().any(|&h| h) => {
            let holds = &w.plates[p].holds[..w.kit.n_foods];
            let dish = match w.kit.rules {
                Rules::V1 => is_dish(holds, task),
                Rules::V0 => holds.iter().all(|&h| h),
            };
            if dish {
                w.putdown(i, target);
                w.delivery.holding = Some(held);
                return (r.correct_delivery, true);
            }
            w.putdown(i, target);
            let foods = w.plates[p].holds;
            w.plates[p].holds = [false; MAX_FOODS];
            w.plates[p].at = w.plates[p].start;
            w.set_tile(w.plates[p].at, Tile::Plate);
            for (k, _) in foods.iter().enumerate().filter(|(_, &h)| h) {
                w.refresh_food(k);
                w.set_tile(w.foods[k].at, Tile::Food(k as u8));
            }
        }
        Held::Plate(p) => {
            w.putdown(i, target);
            w.plates[p].at = w.plates[p].start;
            w.set_tile(w.plates[p].at, Tile::Plate);
        }
        Held::Food(k) => {
            w.putdown(i, target);
            w.refresh_food(k);
            w.set_tile(w.foods[k].at, Tile::Food(k as u8));
        }
    }
    (r.wrong_delivery, false)
}

#[cfg(test)]
mod tests {
    use super::super::layout::{large_start_map, MapType};
    use super::super::world::{Kit, Numbering};
    use super::*;

    /// Four agents in a 2 x 2 block, each walking into the next one's cell clockwise: ACAC's V0
    /// moves them all at once (`four_chain_case`); under V1 each waits for the next and nobody
    /// moves.
    #[test]
    fn a_cycle_of_four_moves_at_once_only_under_v0() {
        let kit = Kit {
            rules: Rules::V0,
            n_foods: 6,
            n_plates: 4,
            n_knives: 4,
        };
        let mut map = large_start_map(11, MapType::A, 6, 4, 4, 0).unwrap();
        for (x, y) in [(3, 2), (3, 3), (4, 2), (4, 3)] {
            map[x][y] = Tile::Agent;
        }
        let start = World::from_map(map, 11, Numbering::RowMajor, kit).unwrap();
        // Row-major: 0 (3,2), 1 (3,3), 2 (4,2), 3 (4,3); right, down, up, left.
        let actions = [0, 1, 3, 2];
        let at = |w: &World| w.cooks.iter().map(|c| (c.at.x, c.at.y)).collect::<Vec<_>>();
        let mut w = start.clone();
        primitive_step(&mut w, &actions, "", &Rewards::default());
        assert_eq!(at(&w), [(3, 3), (4, 3), (3, 2), (4, 2)]);
        let mut v1 = start.clone();
        v1.kit.rules = Rules::V1;
        primitive_step(&mut v1, &actions, "", &Rewards::default());
        assert_eq!(at(&v1), at(&start));
    }

    #[test]
    fn dish_names_follow_the_references_food_order() {
        assert!(is_dish(&[true, true, true], "lettuce-onion-tomato salad"));
        assert!(is_dish(&[true, false, true], "onion-tomato salad"));
        assert!(is_dish(&[false, true, false], "lettuce salad"));
        assert!(!is_dish(&[true, false, true], "tomato-onion salad"));
        assert!(!is_dish(&[true, false, false], "lettuce salad"));
        assert!(!is_dish(&[true, true, true], "lettuce-onion salad"));
        assert!(!is_dish(&[true, false, false], "tomato"));
        assert!(!is_dish(&[false; 3], " salad x"));
    }
}
