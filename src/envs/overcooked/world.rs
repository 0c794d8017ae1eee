//! The kitchen's objects and the map that mirrors them (`items.py` and `Overcooked_V1`'s item
//! lists; ACAC's `Overcooked_V0` has more of each): the foods, the plates, the knives (cutting
//! boards), the delivery counter and the agents, each where the reference keeps it, with the
//! reference's moves, pick-ups and put-downs.
//!
//! The map (`self.map` in the reference) is not derived from the objects: the step writes it
//! beside them, and a few of its writes can disagree with them (a refreshed food written over a
//! plate left on its start counter). Both are kept exactly as the reference keeps them.

use serde::{Deserialize, Serialize};

use super::layout::{Cells, Rules, Tile, MAX_FOODS, MAX_KNIVES, MAX_PLATES};

/// A grid cell `(x, y)`: `x` the row of the printed map, `y` the column (the reference's order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Cell {
    /// Row of the printed map, 0 at the top.
    pub x: i32,
    /// Column of the printed map, 0 at the left.
    pub y: i32,
}

impl Cell {
    /// The cell at row `x`, column `y`.
    pub const fn new(x: i32, y: i32) -> Self {
        Cell { x, y }
    }

    /// Manhattan distance (the reference's `_calDistance`).
    pub fn distance(self, other: Cell) -> i32 {
        (self.x - other.x).abs() + (self.y - other.y).abs()
    }

    /// The neighbour in direction `(dx, dy)`.
    pub fn plus(self, (dx, dy): (i32, i32)) -> Cell {
        Cell::new(self.x + dx, self.y + dy)
    }
}

/// The reference's primitive moves `DIRECTION`: right, down, left, up (index = action), then
/// 4 = stay.
pub const DIRECTION: [(i32, i32); 4] = [(0, 1), (1, 0), (0, -1), (-1, 0)];
/// The primitive action "stay".
pub const STAY: u8 = 4;

/// `Overcooked_V1`'s foods' `rawName`s, in item order (tiles `Food(0)`, `Food(1)`, `Food(2)`).
pub const FOOD_NAMES: [&str; 3] = ["tomato", "lettuce", "onion"];
/// Where an unused slot of the item buffers is: off the grid, so no search finds it.
pub const NOWHERE: Cell = Cell::new(-1, -1);
/// Chops a food needs (`Food.required_chopped_times`).
pub const REQUIRED_CHOPS: u32 = 3;

/// Something an agent, a knife or the delivery counter can hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Held {
    /// Food `k` in item order.
    Food(usize),
    /// Plate `k` (0 is the first in map scan order, "plate 1").
    Plate(usize),
}

/// A food (`Overcooked_V1`: tomato, lettuce, onion; ACAC's Large kitchen: an object of `obj`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Food {
    /// Where it is now (on a counter, a knife, a plate or carried, the carrier's cell).
    pub at: Cell,
    /// Its start counter, where the reference's `Food.refresh` puts it back whole.
    pub start: Cell,
    /// Chopped [`REQUIRED_CHOPS`] times, or a Large kitchen's food not yet refreshed: it may go
    /// onto a plate.
    pub chopped: bool,
    /// Chops so far, 0 to [`REQUIRED_CHOPS`].
    pub chops: u32,
}

/// A plate and the foods on it (the reference's `containing` list; each food exists once, so
/// flags in item order say the same).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Plate {
    /// Where it is now.
    pub at: Cell,
    /// Its start counter, where it goes back after a delivery that is not the finished dish.
    pub start: Cell,
    /// Which foods are on it, in item order.
    pub holds: [bool; MAX_FOODS],
}

/// A knife's cutting board or the delivery counter: fixed, and holding at most one thing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Station {
    /// Its cell.
    pub at: Cell,
    /// What lies on it, if anything.
    pub holding: Option<Held>,
}

/// An agent in the kitchen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Cook {
    /// Its cell.
    pub at: Cell,
    /// Where it starts each episode.
    pub start: Cell,
    /// What it carries, if anything.
    pub holding: Option<Held>,
    /// Done with the current primitive step's move (the reference's `moved`).
    pub moved: bool,
}

/// Everything that moves or is held, and the map beside it.
#[derive(Debug, PartialEq, Serialize, Deserialize)]
pub struct World {
    /// Side of the square map in cells (at most `MAX_SIDE`).
    pub side: usize,
    /// The tiles as the reference's `self.map` holds them, written beside the objects.
    pub map: Cells,
    /// What the kitchen holds and whose rules it follows.
    pub kit: Kit,
    /// The foods in item order (`kit.n_foods` of them; the rest [`NOWHERE`]).
    pub foods: [Food; MAX_FOODS],
    /// The plates, in map scan order (`kit.n_plates`; the rest [`NOWHERE`]).
    pub plates: [Plate; MAX_PLATES],
    /// The cutting boards, in map scan order (`kit.n_knives`; the rest [`NOWHERE`]).
    pub knives: [Station; MAX_KNIVES],
    /// The delivery counter.
    pub delivery: Station,
    /// The agents, in agent order.
    pub cooks: Vec<Cook>,
}

impl Clone for World {
    fn clone(&self) -> Self {
        World {
            side: self.side,
            map: self.map,
            kit: self.kit,
            foods: self.foods,
            plates: self.plates,
            knives: self.knives,
            delivery: self.delivery,
            cooks: self.cooks.clone(),
        }
    }

    /// Every reset copies the start kitchen into the running one: reuse the agents' buffer so
    /// resetting allocates nothing.
    fn clone_from(&mut self, source: &Self) {
        self.side = source.side;
        self.map = source.map;
        self.kit = source.kit;
        self.foods = source.foods;
        self.plates = source.plates;
        self.knives = source.knives;
        self.delivery = source.delivery;
        self.cooks.clone_from(&source.cooks);
    }
}

/// Why a start map cannot make a kitchen (the reference's maps always can).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MissingItem(pub &'static str);

/// How many foods, plates and knives a kitchen has, and whose rules it follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Kit {
    /// `Overcooked_V1` or ACAC's `Overcooked_V0`.
    pub rules: Rules,
    /// Foods (V1: 3; V0: `len(obj)`).
    pub n_foods: usize,
    /// Plates (V1: 2; V0: `n_plate`).
    pub n_plates: usize,
    /// Knives (V1: 2; V0: `n_knife`).
    pub n_knives: usize,
}

impl Kit {
    /// `Overcooked_V1`'s kitchen: tomato, lettuce, onion, two plates, two knives.
    pub const V1: Kit = Kit {
        rules: Rules::V1,
        n_foods: 3,
        n_plates: 2,
        n_knives: 2,
    };
}

/// The order in which `_createItems` scans a start map, which numbers the agents, plates and
/// knives (each kind in the order found). Not a relabelling only: the primitive step moves agents
/// in index order, so the order decides who wins a contended cell (`../shared/spec/acac_envs.md`
/// §Overcooked-MA-v1 item 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Numbering {
    /// gym-macro-overcooked (MacroMARL): row `x` outer, column `y` inner.
    RowMajor,
    /// ACAC's copy: column `y` outer, row `x` inner.
    ColumnMajor,
}

impl World {
    /// The kitchen of a start map holding `kit`'s items, numbered in `numbering`'s scan order as
    /// `_createItems` finds them.
    pub fn from_map(
        map: Cells,
        side: usize,
        numbering: Numbering,
        kit: Kit,
    ) -> Result<World, MissingItem> {
        let station = Station {
            at: NOWHERE,
            holding: None,
        };
        let mut w = World {
            side,
            map,
            kit,
            foods: [Food {
                at: NOWHERE,
                start: NOWHERE,
                chopped: false,
                chops: 0,
            }; MAX_FOODS],
            plates: [Plate {
                at: NOWHERE,
                start: NOWHERE,
                holds: [false; MAX_FOODS],
            }; MAX_PLATES],
            knives: [station; MAX_KNIVES],
            delivery: station,
            cooks: Vec::with_capacity(super::layout::MAX_AGENTS),
        };
        w.restart_from(map, numbering)?;
        Ok(w)
    }

    /// Make this the kitchen of start map `map` (same side and kit), reusing the agents' buffer,
    /// so a reset that draws a new start allocates nothing. On an error the kitchen is unusable.
    ///
    /// Foods start unchopped, except in ACAC's Large kitchen: `GeneralFood` passes its name
    /// where `Food` takes `chopped`, so a fresh object counts as chopped (a truthy string) until
    /// a wrong delivery's `refresh()` sets it to `False` (spec acac_envs.md §Overcooked-MA-v0).
    pub fn restart_from(&mut self, map: Cells, numbering: Numbering) -> Result<(), MissingItem> {
        self.map = map;
        self.cooks.clear();
        let kit = self.kit;
        let fresh_chopped = kit.rules == Rules::V0;
        let (mut foods, mut n_plates, mut n_knives, mut delivery) =
            ([false; MAX_FOODS], 0, 0, None);
        for i in 0..self.side {
            for j in 0..self.side {
                let (x, y) = match numbering {
                    Numbering::RowMajor => (i, j),
                    Numbering::ColumnMajor => (j, i),
                };
                let c = Cell::new(x as i32, y as i32);
                match map[x][y] {
                    Tile::Agent => self.cooks.push(Cook {
                        at: c,
                        start: c,
                        holding: None,
                        moved: false,
                    }),
                    Tile::Knife => {
                        if n_knives < kit.n_knives {
                            self.knives[n_knives] = Station {
                                at: c,
                                holding: None,
                            };
                        }
                        n_knives += 1;
                    }
                    Tile::Delivery => delivery = Some(c),
                    Tile::Plate => {
                        if n_plates < kit.n_plates {
                            self.plates[n_plates] = Plate {
                                at: c,
                                start: c,
                                holds: [false; MAX_FOODS],
                            };
                        }
                        n_plates += 1;
                    }
                    Tile::Food(k) if (k as usize) < kit.n_foods => {
                        let k = k as usize;
                        if !foods[k] {
                            self.foods[k] = Food {
                                at: c,
                                start: c,
                                chopped: fresh_chopped,
                                chops: 0,
                            };
                        }
                        foods[k] = true;
                    }
                    _ => {}
                }
            }
        }
        if foods[..kit.n_foods].iter().any(|&f| !f) {
            return Err(MissingItem("food"));
        }
        if n_plates != kit.n_plates {
            return Err(MissingItem("plate of its count"));
        }
        if n_knives != kit.n_knives {
            return Err(MissingItem("knife of its count"));
        }
        self.delivery = Station {
            at: delivery.ok_or(MissingItem("delivery"))?,
            holding: None,
        };
        Ok(())
    }

    /// The map's tile at `c`, a counter outside the grid.
    pub fn tile(&self, c: Cell) -> Tile {
        tile_of(&self.map, self.side, c)
    }

    /// Write the map at `c` (ignored outside the grid).
    pub fn set_tile(&mut self, c: Cell, t: Tile) {
        if inside(self.side, c) {
            self.map[c.x as usize][c.y as usize] = t;
        }
    }

    /// Where `h` is.
    pub fn position(&self, h: Held) -> Cell {
        match h {
            Held::Food(k) => self.foods[k].at,
            Held::Plate(k) => self.plates[k].at,
        }
    }

    /// Move `h` to `to`; a plate carries its foods (`MovableItem.move`, `Plate.move`).
    pub fn move_thing(&mut self, h: Held, to: Cell) {
        match h {
            Held::Food(k) => self.foods[k].at = to,
            Held::Plate(p) => {
                self.plates[p].at = to;
                for k in 0..self.kit.n_foods {
                    if self.plates[p].holds[k] {
                        self.foods[k].at = to;
                    }
                }
            }
        }
    }

    /// Put food `k` on plate `p` (`Plate.contain`): it and all the plate's foods go to the plate.
    pub fn plate_contain(&mut self, p: usize, k: usize) {
        self.plates[p].holds[k] = true;
        let at = self.plates[p].at;
        self.move_thing(Held::Plate(p), at);
    }

    /// Move agent `i` to `to`, with what it holds (`Agent.move`; sets `moved`).
    pub fn move_cook(&mut self, i: usize, to: Cell) {
        self.cooks[i].at = to;
        self.cooks[i].moved = true;
        if let Some(h) = self.cooks[i].holding {
            self.move_thing(h, to);
        }
    }

    /// Agent `i` takes `h` (`Agent.pickup`).
    pub fn pickup(&mut self, i: usize, h: Held) {
        self.cooks[i].holding = Some(h);
        self.move_thing(h, self.cooks[i].at);
    }

    /// Agent `i` puts what it holds at `to` (`Agent.putdown`); returns it.
    pub fn putdown(&mut self, i: usize, to: Cell) -> Option<Held> {
        let h = self.cooks[i].holding.take()?;
        self.move_thing(h, to);
        Some(h)
    }

    /// Food `k` back to its start, whole (`Food.refresh`).
    pub fn refresh_food(&mut self, k: usize) {
        let f = &mut self.foods[k];
        f.at = f.start;
        f.chopped = false;
        f.chops = 0;
    }

    /// One chop of food `k` (`Food.chop`): nothing once chopped.
    pub fn chop(&mut self, k: usize) {
        let f = &mut self.foods[k];
        if !f.chopped {
            f.chops += 1;
            if f.chops >= REQUIRED_CHOPS {
                f.chopped = true;
            }
        }
    }

    /// The food `_findItem(c, name)` finds where the map shows food `k`: `Overcooked_V1` looks
    /// in `k`'s own list; ACAC's `Overcooked_V0` maps every one-letter name to the list of all
    /// foods, so it finds the first food (in item order) at `c`, of any kind.
    pub fn food_at(&self, c: Cell, k: usize) -> Option<usize> {
        match self.kit.rules {
            Rules::V1 => (self.foods.get(k)?.at == c).then_some(k),
            Rules::V0 => self.foods[..self.kit.n_foods]
                .iter()
                .position(|f| f.at == c),
        }
    }

    /// The first plate at `c`.
    pub fn plate_at(&self, c: Cell) -> Option<usize> {
        self.plates.iter().position(|p| p.at == c)
    }

    /// The first knife at `c`.
    pub fn knife_at(&self, c: Cell) -> Option<usize> {
        self.knives.iter().position(|k| k.at == c)
    }

    /// The first agent at `c`.
    pub fn cook_at(&self, c: Cell) -> Option<usize> {
        self.cooks.iter().position(|k| k.at == c)
    }

    /// Number of entries of the reference's `itemList`: foods, plates, knives, delivery, agents.
    pub fn n_items(&self) -> usize {
        let k = &self.kit;
        k.n_foods + k.n_plates + k.n_knives + 1 + self.cooks.len()
    }

    /// What `itemList[k]` is: a food, plate, knife, the delivery or an agent, with its index.
    fn item_kind(&self, k: usize) -> (Tile, usize) {
        let kit = &self.kit;
        let plates = kit.n_foods;
        let knives = plates + kit.n_plates;
        let delivery = knives + kit.n_knives;
        if k < plates {
            (Tile::Food(k as u8), k)
        } else if k < knives {
            (Tile::Plate, k - plates)
        } else if k < delivery {
            (Tile::Knife, k - knives)
        } else if k == delivery {
            (Tile::Delivery, 0)
        } else {
            (Tile::Agent, k - delivery - 1)
        }
    }

    /// Where `itemList[k]` is now, and where it started (fixed items never move).
    pub fn item(&self, k: usize) -> (Cell, Cell) {
        match self.item_kind(k) {
            (Tile::Food(_), i) => (self.foods[i].at, self.foods[i].start),
            (Tile::Plate, i) => (self.plates[i].at, self.plates[i].start),
            (Tile::Knife, i) => (self.knives[i].at, self.knives[i].at),
            (Tile::Delivery, _) => (self.delivery.at, self.delivery.at),
            (_, i) => (self.cooks[i].at, self.cooks[i].start),
        }
    }

    /// The tile of `itemList[k]`'s `rawName`.
    pub fn item_tile(&self, k: usize) -> Tile {
        self.item_kind(k).0
    }

    /// Food `k` of `itemList[k]`, when it is one (the observation's chop progress).
    pub fn item_food(&self, k: usize) -> Option<usize> {
        (k < self.kit.n_foods).then_some(k)
    }
}

/// Whether `c` is on a `side` x `side` grid.
pub fn inside(side: usize, c: Cell) -> bool {
    c.x >= 0 && c.y >= 0 && (c.x as usize) < side && (c.y as usize) < side
}

/// `map[c]`, a counter outside the grid.
pub fn tile_of(map: &Cells, side: usize, c: Cell) -> Tile {
    if inside(side, c) {
        map[c.x as usize][c.y as usize]
    } else {
        Tile::Counter
    }
}

#[cfg(test)]
mod tests {
    use super::super::layout::{start_map, MapType};
    use super::*;

    #[test]
    fn items_are_found_in_map_scan_order() {
        let w = World::from_map(
            start_map(7, MapType::A, 3).unwrap(),
            7,
            Numbering::RowMajor,
            Kit::V1,
        )
        .unwrap();
        assert_eq!(w.foods[0].at, Cell::new(0, 5));
        assert_eq!(w.foods[1].at, Cell::new(1, 6));
        assert_eq!(w.foods[2].at, Cell::new(2, 6));
        assert_eq!(w.plates[0].at, Cell::new(5, 6));
        assert_eq!(w.plates[1].at, Cell::new(6, 5));
        assert_eq!(w.knives[1].at, Cell::new(2, 0));
        assert_eq!(w.delivery.at, Cell::new(3, 0));
        let cooks: Vec<Cell> = w.cooks.iter().map(|c| c.at).collect();
        assert_eq!(cooks, [Cell::new(1, 2), Cell::new(1, 4), Cell::new(5, 2)]);
        assert_eq!(w.n_items(), 11);
    }

    /// ACAC's `_createItems` scans column by column (spec acac_envs.md item 1).
    #[test]
    fn acac_numbers_agents_and_plates_column_by_column() {
        let w = World::from_map(
            start_map(7, MapType::A, 3).unwrap(),
            7,
            Numbering::ColumnMajor,
            Kit::V1,
        )
        .unwrap();
        let cooks: Vec<Cell> = w.cooks.iter().map(|c| c.at).collect();
        assert_eq!(cooks, [Cell::new(1, 2), Cell::new(5, 2), Cell::new(1, 4)]);
        assert_eq!(w.plates[0].at, Cell::new(6, 5));
        assert_eq!(w.plates[1].at, Cell::new(5, 6));
        assert_eq!(w.knives[0].at, Cell::new(1, 0));
        assert_eq!(w.foods[0].at, Cell::new(0, 5));
    }

    #[test]
    fn a_plate_carries_its_foods() {
        let mut w = World::from_map(
            start_map(7, MapType::A, 2).unwrap(),
            7,
            Numbering::RowMajor,
            Kit::V1,
        )
        .unwrap();
        w.plate_contain(0, 2);
        assert_eq!(w.foods[2].at, w.plates[0].at);
        w.pickup(0, Held::Plate(0));
        w.move_cook(0, Cell::new(2, 2));
        assert_eq!(w.foods[2].at, Cell::new(2, 2));
        assert_eq!(w.putdown(0, Cell::new(2, 3)), Some(Held::Plate(0)));
        assert_eq!(w.foods[2].at, Cell::new(2, 3));
    }
}
