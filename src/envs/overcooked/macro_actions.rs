//! Macro-actions (`Overcooked_MA_V1`; ACAC's `Overcooked_MA_V0` names them by its items): what each one means, the primitive move it takes this
//! step (`_computeLowLevelActions`, before the primitive step, on the belief of the previous
//! step) and whether it ended (decided there, then again by `_checkMacroActionDone` after the
//! step, on the updated belief). Targets come from the agent's belief (`_findPOitem`), not from
//! where things are, so an agent can walk to a remembered place and find nothing.

use serde::{Deserialize, Serialize};

use super::astar::{navigate, PyHeap};
use super::layout::{counter_sequence, MapType, Rules, Tile};
use super::observe::{in_view, Belief};
use super::world::{Cell, Held, Kit, World, DIRECTION, STAY};

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

/// ACAC's Large kitchen at its published settings (`obj` "A".."F", 4 plates, 4 knives), map A:
/// `Overcooked_MA_V0.macroActionName`. The delivery is named `delivery`, so none of V1's special
/// cases keyed on `"deliver"` fire.
pub const NAMES_LARGE_A: [&str; 21] = [
    "stay",
    "get A",
    "get B",
    "get C",
    "get D",
    "get E",
    "get F",
    "get plate 1",
    "get plate 2",
    "get plate 3",
    "get plate 4",
    "go to knife 1",
    "go to knife 2",
    "go to knife 3",
    "go to knife 4",
    "delivery",
    "chop",
    "right",
    "down",
    "left",
    "up",
];

/// [`NAMES_LARGE_A`] with "go to counter" before the moves (maps B and C).
pub const NAMES_LARGE_BC: [&str; 22] = [
    "stay",
    "get A",
    "get B",
    "get C",
    "get D",
    "get E",
    "get F",
    "get plate 1",
    "get plate 2",
    "get plate 3",
    "get plate 4",
    "go to knife 1",
    "go to knife 2",
    "go to knife 3",
    "go to knife 4",
    "delivery",
    "chop",
    "go to counter",
    "right",
    "down",
    "left",
    "up",
];

/// The macro-action names of an `Overcooked_V1` map type.
pub fn names(map: MapType) -> &'static [&'static str] {
    match map {
        MapType::A => &NAMES_A,
        MapType::B | MapType::C => &NAMES_BC,
    }
}

/// The macro-action names of a Large kitchen of objects `obj` (`Overcooked_MA_V0`'s
/// `macroActionName`): "stay", "get `<o>`" per object, "get plate k", "go to knife k",
/// "delivery", "chop", "go to counter" on maps B and C, the four moves. The published kitchen's
/// are [`NAMES_LARGE_A`] / [`NAMES_LARGE_BC`]; any other's are built once per process and kept.
pub fn large_names(map: MapType, obj: &[String], kit: &Kit) -> &'static [&'static str] {
    use std::sync::Mutex;
    type Interned = Vec<(Vec<String>, &'static [&'static str])>;
    static BUILT: Mutex<Interned> = Mutex::new(Vec::new());
    let mut list = vec!["stay".to_string()];
    list.extend(obj.iter().map(|o| format!("get {o}")));
    list.extend((1..=kit.n_plates).map(|k| format!("get plate {k}")));
    list.extend((1..=kit.n_knives).map(|k| format!("go to knife {k}")));
    list.extend(["delivery", "chop"].map(String::from));
    if map != MapType::A {
        list.push("go to counter".into());
    }
    list.extend(["right", "down", "left", "up"].map(String::from));
    for published in [&NAMES_LARGE_A[..], &NAMES_LARGE_BC[..]] {
        if list.iter().eq(published.iter()) {
            return published;
        }
    }
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, names)) = built.iter().find(|(l, _)| *l == list) {
        return names;
    }
    let names: Vec<&'static str> = list
        .iter()
        .map(|n| &*Box::leak(n.clone().into_boxed_str()))
        .collect();
    let names: &'static [&'static str] = Box::leak(names.into_boxed_slice());
    built.push((list, names));
    names
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
    /// Macro-action `index` of map type `map` in a kitchen holding `kit`: stay, a "get" per food,
    /// a "get plate" per plate, a "go to knife" per knife, deliver, chop, "go to counter" (maps
    /// B and C), the four moves (V1: 14 or 15; ACAC's Large kitchen: 21 or 22).
    pub fn of(index: usize, map: MapType, kit: &Kit) -> Macro {
        let plates = 1 + kit.n_foods;
        let knives = plates + kit.n_plates;
        let deliver = knives + kit.n_knives;
        let moves_from = deliver + 2 + usize::from(map != MapType::A);
        match index {
            0 => Macro::Stay,
            i if i < plates => Macro::GetFood(i - 1),
            i if i < knives => Macro::GetPlate(i - plates),
            i if i < deliver => Macro::GoToKnife(i - knives),
            i if i == deliver => Macro::Deliver,
            i if i == deliver + 1 => Macro::Chop,
            i if i >= moves_from => Macro::Move((i - moves_from) as u8),
            _ => Macro::GoToCounter,
        }
    }

    /// How many macro-actions a kitchen holding `kit` has on map `map`.
    pub fn count(map: MapType, kit: &Kit) -> usize {
        1 + kit.n_foods + kit.n_plates + kit.n_knives + 2 + usize::from(map != MapType::A) + 4
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
/// times the side, truncated (V0 looks `idx` up in `idx_in_obs`, which gives the same entries).
pub fn target_of(b: &Belief, m: Macro, side: usize, kit: &Kit) -> Cell {
    let plates = 3 * kit.n_foods;
    let knives = plates + 2 * kit.n_plates;
    let idx = match m {
        Macro::GetFood(k) => 3 * k,
        Macro::GetPlate(k) => plates + 2 * k,
        Macro::GoToKnife(k) => knives + 2 * k,
        // Deliver; the reference never asks for the others.
        _ => knives + 2 * kit.n_knives,
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
    let m = Macro::of(s.current, ctx.map, &w.kit);
    let me = w.cooks[i].at;
    let pomap = |c: Cell| super::world::tile_of(&b.pomap, w.side, c);
    // V1's "deliver" special case; V0 names the macro-action "delivery" and never takes it.
    let v1 = w.kit.rules == Rules::V1;
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
        Macro::Deliver if v1 && me == Cell::new(1, 1) && pomap(Cell::new(2, 1)) == Tile::Agent => 0,
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
    let target = target_of(b, m, w.side, &w.kit);
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
    let m = Macro::of(s.current, ctx.map, &w.kit);
    let target = |m| target_of(b, m, w.side, &w.kit);
    let empty_handed = w.cooks[i].holding.is_none();
    let next_to = |t: Cell| me.distance(t) == 1;
    let mut done = match m {
        Macro::GoToKnife(_) if empty_handed => next_to(target(m)),
        Macro::GetFood(k) => {
            let t = target(m);
            next_to(t)
                && w.knife_at(t).is_some()
                && w.food_at(t, k).is_some_and(|f| !w.foods[f].chopped)
        }
        // V1 only: V0's "delivery" is not "deliver".
        Macro::Deliver if empty_handed && w.kit.rules == Rules::V1 => next_to(target(m)),
        _ => false,
    };
    if let Some(at) = true_place(w, m) {
        if at != target(m) {
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
        let v1 = &Kit::V1;
        assert_eq!(Macro::of(10, MapType::A, v1), Macro::Move(0));
        assert_eq!(Macro::of(13, MapType::A, v1), Macro::Move(3));
        assert_eq!(Macro::of(10, MapType::B, v1), Macro::GoToCounter);
        assert_eq!(Macro::of(11, MapType::C, v1), Macro::Move(0));
        assert_eq!(Macro::of(5, MapType::C, v1), Macro::GetPlate(1));
        assert_eq!(Macro::of(8, MapType::C, v1), Macro::Deliver);
        assert_eq!(NAMES_BC[10], "go to counter");
        assert_eq!(Macro::count(MapType::A, v1), NAMES_A.len());
        assert_eq!(Macro::count(MapType::B, v1), NAMES_BC.len());
    }

    #[test]
    fn large_names_decode_by_their_counts() {
        let kit = Kit {
            rules: Rules::V0,
            n_foods: 6,
            n_plates: 4,
            n_knives: 4,
        };
        let obj: Vec<String> = "ABCDEF".chars().map(String::from).collect();
        for map in [MapType::A, MapType::B] {
            let names = large_names(map, &obj, &kit);
            assert_eq!(names.len(), Macro::count(map, &kit));
            for (i, n) in names.iter().enumerate() {
                let want = match *n {
                    "stay" => Macro::Stay,
                    "delivery" => Macro::Deliver,
                    "chop" => Macro::Chop,
                    "go to counter" => Macro::GoToCounter,
                    "right" => Macro::Move(0),
                    "down" => Macro::Move(1),
                    "left" => Macro::Move(2),
                    "up" => Macro::Move(3),
                    n if n.starts_with("get plate ") => get_plate_of(n),
                    n if n.starts_with("go to knife ") => go_to_knife_of(n),
                    n => Macro::GetFood(obj.iter().position(|o| n == format!("get {o}")).unwrap()),
                };
                assert_eq!(Macro::of(i, map, &kit), want, "{n}");
            }
        }
        let two = Kit {
            n_foods: 2,
            n_plates: 2,
            ..kit
        };
        let names = large_names(MapType::C, &obj[..2], &two);
        assert_eq!(names[3], "get plate 1");
        assert_eq!(names, large_names(MapType::C, &obj[..2], &two));
    }

    fn get_plate_of(n: &str) -> Macro {
        Macro::GetPlate(n["get plate ".len()..].parse::<usize>().unwrap() - 1)
    }

    fn go_to_knife_of(n: &str) -> Macro {
        Macro::GoToKnife(n["go to knife ".len()..].parse::<usize>().unwrap() - 1)
    }
}
