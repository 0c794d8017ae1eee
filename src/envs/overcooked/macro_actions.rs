//! Macro-actions (`Overcooked_MA_V1`): what each one means, the primitive move it takes this
//! step (`_computeLowLevelActions`, before the primitive step, on the belief of the previous
//! step) and whether it ended (decided there, then again by `_checkMacroActionDone` after the
//! step, on the updated belief). Targets come from the agent's belief (`_findPOitem`), not from
//! where things are, so an agent can walk to a remembered place and find nothing.

use serde::{Deserialize, Serialize};

use super::astar::{navigate, PyHeap};
use super::layout::{counter_sequence, MapType, Tile};
use super::observe::{in_view, Belief};
use super::world::{Cell, Held, World, DIRECTION, FOOD_TILES, STAY};

/// Map A's macro-actions (the reference's `macroActionName`).
pub const NAMES_A: [&str; 14] = [
    "stay",
    "get tomato",
    "get lettuce",
    "get onion",
    "get plate 1",
    "get plate 2",
    "go to knife 1",
    "go to knife 2",
    "deliver",
    "chop",
    "right",
    "down",
    "left",
    "up",
];

/// Maps B and C add "go to counter" (a free cell of the divider) before the moves.
pub const NAMES_BC: [&str; 15] = [
    "stay",
    "get tomato",
    "get lettuce",
    "get onion",
    "get plate 1",
    "get plate 2",
    "go to knife 1",
    "go to knife 2",
    "deliver",
    "chop",
    "go to counter",
    "right",
    "down",
    "left",
    "up",
];

/// The macro-action names of a map type.
pub fn names(map: MapType) -> &'static [&'static str] {
    match map {
        MapType::A => &NAMES_A,
        MapType::B | MapType::C => &NAMES_BC,
    }
}

/// What a macro-action index means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Macro {
    /// Stay in place for one step.
    Stay,
    /// Go to food `k` (tomato, lettuce, onion) and take it.
    GetFood(usize),
    /// Go to plate `k` and take it (or put a chopped food held on it).
    GetPlate(usize),
    /// Go next to knife `k` (and put down what is held on it).
    GoToKnife(usize),
    /// Go to the delivery counter (and put down what is held there).
    Deliver,
    /// Chop the unchopped food on an adjacent knife, up to 3 times.
    Chop,
    /// Go next to the first divider cell shown as free counter (maps B, C).
    GoToCounter,
    /// One primitive move (0 right, 1 down, 2 left, 3 up), if the belief shows floor there.
    Move(u8),
}

impl Macro {
    /// Macro-action `index` of map type `map`.
    pub fn of(index: usize, map: MapType) -> Macro {
        let moves_from = names(map).len() - 4;
        match index {
            0 => Macro::Stay,
            1..=3 => Macro::GetFood(index - 1),
            4 | 5 => Macro::GetPlate(index - 4),
            6 | 7 => Macro::GoToKnife(index - 6),
            8 => Macro::Deliver,
            9 => Macro::Chop,
            i if i >= moves_from => Macro::Move((i - moves_from) as u8),
            _ => Macro::GoToCounter,
        }
    }
}

/// An agent's macro-action bookkeeping (`MacAgent`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct MacState {
    /// The macro-action under way (0 before the first step).
    pub current: usize,
    /// It ended: the agent picks a new one at the next step.
    pub done: bool,
    /// Chops in the current run of "chop" (`cur_chop_times`). It is reset only after 3, so a
    /// chop cut short leaves its count to the next one, as in the reference.
    pub chop_times: u32,
}

impl MacState {
    /// The state at reset: macro-action 0 (stay), done, no chops.
    pub const FRESH: MacState = MacState {
        current: 0,
        done: true,
        chop_times: 0,
    };
}

/// What the macro layer reads: the kitchen, the map type and the view radius.
pub struct Ctx<'a> {
    /// The kitchen.
    pub world: &'a World,
    /// The map type (B and C have the divider).
    pub map: MapType,
    /// The agents' view radius in cells (0: the whole map).
    pub radius: i32,
}

/// The belief's place of the target of `m` (`_findPOitem`): entry `idx` of the observation
/// times the side, truncated.
pub fn target_of(b: &Belief, m: Macro, side: usize) -> Cell {
    let idx = match m {
        Macro::GetFood(k) => 3 * k,
        Macro::GetPlate(k) => 9 + 2 * k,
        Macro::GoToKnife(k) => 13 + 2 * k,
        // Deliver; the reference never asks for the others.
        _ => 17,
    };
    let s = side as f64;
    Cell::new((b.obs[idx] * s) as i32, (b.obs[idx + 1] * s) as i32)
}

/// The true place of the object "get" macro-action `m` names.
fn true_place(w: &World, m: Macro) -> Option<Cell> {
    match m {
        Macro::GetFood(k) => Some(w.foods[k].at),
        Macro::GetPlate(k) => Some(w.plates[k].at),
        _ => None,
    }
}

/// Whether knife-held food at `target` is still to be chopped.
fn unchopped_on_knife(w: &World, target: Cell) -> bool {
    w.knives
        .iter()
        .any(|k| k.at == target && matches!(k.holding, Some(Held::Food(f)) if !w.foods[f].chopped))
}

/// The divider cell "go to counter" heads for: the first of `counterSequence` (column
/// `side / 2`) the belief shows as bare counter.
fn free_counter(b: &Belief, side: usize, map: MapType) -> Option<Cell> {
    let y = (side / 2) as i32;
    counter_sequence(side, map)
        .iter()
        .map(|&x| Cell::new(x, y))
        .find(|c| b.pomap[c.x as usize][c.y as usize] == Tile::Counter)
}

/// The primitive move agent `i` takes this step (`_computeLowLevelActions`), starting
/// `chosen` first if the agent is free; updates its [`MacState`].
pub fn low_level(
    ctx: &Ctx,
    i: usize,
    chosen: usize,
    b: &Belief,
    s: &mut MacState,
    heap: &mut PyHeap,
) -> u8 {
    let w = ctx.world;
    if s.done {
        s.current = chosen;
        s.done = false;
    }
    let m = Macro::of(s.current, ctx.map);
    let me = w.cooks[i].at;
    let pomap = |c: Cell| super::world::tile_of(&b.pomap, w.side, c);
    match m {
        Macro::Stay => {
            s.done = true;
            STAY
        }
        Macro::Chop => {
            for (a, &d) in DIRECTION.iter().enumerate() {
                let c = me.plus(d);
                if w.tile(c) != Tile::Knife {
                    continue;
                }
                let holding = w.knife_at(c).and_then(|k| w.knives[k].holding);
                if let Some(Held::Food(f)) = holding {
                    if !w.foods[f].chopped {
                        s.chop_times += 1;
                        if s.chop_times >= 3 {
                            s.done = true;
                            s.chop_times = 0;
                        }
                        return a as u8;
                    }
                }
            }
            s.done = true;
            STAY
        }
        Macro::Deliver if me == Cell::new(1, 1) && pomap(Cell::new(2, 1)) == Tile::Agent => 0,
        Macro::GoToCounter => match free_counter(b, w.side, ctx.map) {
            Some(target) => {
                let a = navigate(&b.pomap, w.side, me, target, heap);
                if me.distance(target) == 1 {
                    s.done = true;
                }
                a
            }
            None => {
                s.done = true;
                STAY
            }
        },
        Macro::Move(d) => {
            s.done = true;
            if pomap(me.plus(DIRECTION[d as usize])) == Tile::Space {
                d
            } else {
                STAY
            }
        }
        _ => go_to_target(ctx, i, m, b, s, heap),
    }
}

/// The "get", "go to knife" and "deliver" macro-actions: walk (A*) to the believed target and
/// into it, with the reference's special cases.
fn go_to_target(
    ctx: &Ctx,
    i: usize,
    m: Macro,
    b: &Belief,
    s: &mut MacState,
    heap: &mut PyHeap,
) -> u8 {
    let w = ctx.world;
    let me = w.cooks[i].at;
    let target = target_of(b, m, w.side);
    let target_in_view = in_view(me, target, ctx.radius);
    // A food believed on a plate cannot be taken: give up.
    if matches!(m, Macro::GetFood(_)) && target_in_view && w.plates.iter().any(|p| p.at == target) {
        s.done = true;
        return STAY;
    }
    let pomap = |c: Cell| super::world::tile_of(&b.pomap, w.side, c);
    if target == Cell::new(1, 0) && me == Cell::new(3, 1) && pomap(Cell::new(2, 1)) == Tile::Agent {
        return 0;
    }
    if pomap(target) == Tile::Agent && target_in_view {
        s.done = true;
        return STAY;
    }
    let mut a = navigate(&b.pomap, w.side, me, target, heap);
    if a == STAY {
        s.done = true;
    }
    if me.distance(target) == 1 {
        s.done = true;
        let holding = w.cooks[i].holding;
        if let (Macro::GetPlate(_), Some(Held::Food(f))) = (m, holding) {
            if w.foods[f].chopped {
                s.done = false;
            } else {
                a = STAY;
            }
        }
        if matches!(m, Macro::GoToKnife(_)) && holding.is_none() {
            a = STAY;
        }
        if matches!(m, Macro::GetFood(_)) && unchopped_on_knife(w, target) {
            a = STAY;
        }
        if true_place(w, m).is_some_and(|at| at != target) {
            a = STAY;
        }
    }
    a
}

/// Whether agent `i`'s macro-action ended with this step (`_checkMacroActionDone`, on the
/// belief after the step). Its "go to counter" branch tests the name `"go to counter "` (a
/// trailing space) and so never fires; that macro-action ends only as [`low_level`] decides.
pub fn ended_after_step(ctx: &Ctx, i: usize, b: &Belief, s: &MacState) -> bool {
    if s.done {
        return true;
    }
    let w = ctx.world;
    let me = w.cooks[i].at;
    let m = Macro::of(s.current, ctx.map);
    let empty_handed = w.cooks[i].holding.is_none();
    let next_to = |t: Cell| me.distance(t) == 1;
    let mut done = match m {
        Macro::GoToKnife(_) if empty_handed => next_to(target_of(b, m, w.side)),
        Macro::GetFood(k) => {
            let t = target_of(b, m, w.side);
            next_to(t)
                && w.knife_at(t).is_some()
                && w.food_at(t, FOOD_TILES[k])
                    .is_some_and(|f| !w.foods[f].chopped)
        }
        Macro::Deliver if empty_handed => next_to(target_of(b, m, w.side)),
        _ => false,
    };
    if let Some(at) = true_place(w, m) {
        if at != target_of(b, m, w.side) {
            done = true;
        }
    }
    done
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_decode_per_map_type() {
        assert_eq!(Macro::of(10, MapType::A), Macro::Move(0));
        assert_eq!(Macro::of(13, MapType::A), Macro::Move(3));
        assert_eq!(Macro::of(10, MapType::B), Macro::GoToCounter);
        assert_eq!(Macro::of(11, MapType::C), Macro::Move(0));
        assert_eq!(Macro::of(5, MapType::C), Macro::GetPlate(1));
        assert_eq!(NAMES_BC[10], "go to counter");
    }
}
