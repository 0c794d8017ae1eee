//! The reference's fixed layouts (`overcooked_V1.py: __init__`, `_get_vector_obs`,
//! `overcooked_MA_V1.py: __init__`): the start maps per grid, map type and agent count, the
//! walls-only maps each agent's belief map starts from every step, and the order in which "go to
//! counter" tries the divider's cells.
//!
//! Coordinates are the reference's: `x` is the row of the printed map (0 at the top), `y` the
//! column; `map[x][y]`.

use serde::{Deserialize, Serialize};

/// Largest grid side the references have maps for (ACAC's Large kitchen, 11 x 11).
pub const MAX_SIDE: usize = 11;
/// Most agents a kitchen holds (ACAC's Large kitchen has 6): the capacity of the agents' buffers
/// and of a random start's draws.
pub const MAX_AGENTS: usize = 6;
/// Most foods (ACAC's Large kitchen: objects "A".."F").
pub const MAX_FOODS: usize = 6;
/// Most plates (ACAC's Large kitchen: 4).
pub const MAX_PLATES: usize = 4;
/// Most knives (ACAC's Large kitchen: 4).
pub const MAX_KNIVES: usize = 4;

/// What a cell of a map holds. Each reference numbers the tiles its own way ([`Rules::code`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Tile {
    /// Floor an agent may walk on.
    Space,
    /// Counter (walls and the divider); items may be put on it.
    Counter,
    /// An agent.
    Agent,
    /// A plate.
    Plate,
    /// A knife (cutting board).
    Knife,
    /// The delivery counter.
    Delivery,
    /// Food `k` in item order (`Overcooked_V1`: tomato, lettuce, onion; ACAC's `Overcooked_V0`:
    /// the objects of `obj` in order).
    Food(u8),
}

/// Whose rules the kitchen follows: `Overcooked_V1` (gym-macro-overcooked's and ACAC's copy of
/// it) or ACAC's `Overcooked_V0` (Overcooked-Large, `../shared/spec/acac_envs.md`
/// §Overcooked-MA-v0). They differ in the tile codes, the start map, the foods (named objects that
/// start "chopped"), the dish, the macro-action names and the moves of a cycle of agents.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Rules {
    /// `Overcooked_V1`: `ITEMIDX` space 0, counter 1, agent 2, tomato 3, lettuce 4, plate 5,
    /// knife 6, delivery 7, onion 8.
    V1,
    /// ACAC's `Overcooked_V0`: `DEFAULT_ITEMIDX` space 0, counter 1, agent 2, plate 3, knife 4,
    /// delivery 5, then the objects of `obj` from 6 in order.
    V0,
}

impl Rules {
    /// The reference's number of `t`.
    pub const fn code(self, t: Tile) -> u8 {
        match (self, t) {
            (_, Tile::Space) => 0,
            (_, Tile::Counter) => 1,
            (_, Tile::Agent) => 2,
            (Rules::V1, Tile::Food(0)) => 3,
            (Rules::V1, Tile::Food(1)) => 4,
            (Rules::V1, Tile::Plate) => 5,
            (Rules::V1, Tile::Knife) => 6,
            (Rules::V1, Tile::Delivery) => 7,
            (Rules::V1, Tile::Food(_)) => 8,
            (Rules::V0, Tile::Plate) => 3,
            (Rules::V0, Tile::Knife) => 4,
            (Rules::V0, Tile::Delivery) => 5,
            (Rules::V0, Tile::Food(k)) => 6 + k,
        }
    }

    /// The tile the reference numbers `code` with `n_foods` foods, `None` for a number it has
    /// not.
    pub const fn tile(self, code: u8, n_foods: usize) -> Option<Tile> {
        Some(match (self, code) {
            (_, 0) => Tile::Space,
            (_, 1) => Tile::Counter,
            (_, 2) => Tile::Agent,
            (Rules::V1, 3) => Tile::Food(0),
            (Rules::V1, 4) => Tile::Food(1),
            (Rules::V1, 5) => Tile::Plate,
            (Rules::V1, 6) => Tile::Knife,
            (Rules::V1, 7) => Tile::Delivery,
            (Rules::V1, 8) => Tile::Food(2),
            (Rules::V0, 3) => Tile::Plate,
            (Rules::V0, 4) => Tile::Knife,
            (Rules::V0, 5) => Tile::Delivery,
            (Rules::V0, c) if (c as usize) < 6 + n_foods => Tile::Food(c - 6),
            _ => return None,
        })
    }
}

/// A map: `cells[x][y]` for `x < side`, `y < side` (the rest is unused counter).
pub type Cells = [[Tile; MAX_SIDE]; MAX_SIDE];

/// The reference's map types: A open, B divided by a counter column, C the divider with a gap.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum MapType {
    /// Open kitchen.
    A,
    /// Divided by a counter column.
    B,
    /// Divided, with a gap in the divider.
    C,
}

impl MapType {
    /// `"A"`, `"B"` or `"C"` (the reference's `map_type` values).
    pub fn parse(s: &str) -> Option<MapType> {
        match s {
            "A" => Some(MapType::A),
            "B" => Some(MapType::B),
            "C" => Some(MapType::C),
            _ => None,
        }
    }

    /// The reference's letter.
    pub fn letter(self) -> &'static str {
        match self {
            MapType::A => "A",
            MapType::B => "B",
            MapType::C => "C",
        }
    }
}

/// A map from rows of `Overcooked_V1`'s numbers (`rows.len()` is the side).
fn cells<const N: usize>(rows: [[u8; N]; N]) -> Cells {
    let mut c = [[Tile::Counter; MAX_SIDE]; MAX_SIDE];
    for (x, row) in rows.iter().enumerate() {
        for (y, &v) in row.iter().enumerate() {
            c[x][y] = Rules::V1
                .tile(v, 3)
                .expect("the literal maps hold V1's codes");
        }
    }
    c
}

/// The start map of `side` x `side`, `map`, `n_agent` agents, or `None` where the reference has
/// none (its `map` stays `[]` and construction fails): sides 7 and 9, 2 or 3 agents.
pub fn start_map(side: usize, map: MapType, n_agent: usize) -> Option<Cells> {
    // The 7 x 7 maps: the 2-agent ones are the 3-agent ones without the third agent at (5, 2).
    let seven = |divider_rows: usize| {
        let mut rows = [
            [1, 1, 1, 1, 1, 3, 1],
            [6, 0, 2, 0, 2, 0, 4],
            [6, 0, 0, 0, 0, 0, 8],
            [7, 0, 0, 0, 0, 0, 1],
            [1, 0, 0, 0, 0, 0, 1],
            [1, 0, 0, 0, 0, 0, 5],
            [1, 1, 1, 1, 1, 5, 1],
        ];
        for row in rows.iter_mut().take(divider_rows).skip(1) {
            row[3] = 1;
        }
        rows
    };
    let nine = |divider_rows: usize| {
        let mut rows = [
            [1, 1, 1, 1, 1, 1, 1, 3, 1],
            [6, 0, 2, 0, 0, 0, 2, 0, 4],
            [6, 0, 0, 0, 0, 0, 0, 0, 8],
            [7, 0, 0, 0, 0, 0, 0, 0, 1],
            [1, 0, 0, 0, 0, 0, 0, 0, 1],
            [1, 0, 0, 0, 0, 0, 0, 0, 1],
            [1, 0, 0, 0, 0, 0, 0, 0, 1],
            [1, 0, 0, 0, 0, 0, 0, 0, 5],
            [1, 1, 1, 1, 1, 1, 1, 5, 1],
        ];
        for row in rows.iter_mut().take(divider_rows).skip(1) {
            row[4] = 1;
        }
        rows
    };
    // Rows 1.. up to this one (exclusive) carry the divider: B all inner rows, C all but the last.
    let divider = |inner: usize| match map {
        MapType::A => 1,
        MapType::B => inner + 1,
        MapType::C => inner,
    };
    if n_agent != 2 && n_agent != 3 {
        return None;
    }
    let mut c = match side {
        7 => cells(seven(divider(5))),
        9 => cells(nine(divider(7))),
        _ => return None,
    };
    if n_agent == 3 {
        c[side - 2][2] = Tile::Agent;
    }
    Some(c)
}

/// The walls-only map an agent's belief map is rebuilt from at every observation (the
/// reference's literal `pomap`s): the border and the divider as counters, all else space.
pub fn belief_base(side: usize, map: MapType) -> Cells {
    let mut c = [[Tile::Counter; MAX_SIDE]; MAX_SIDE];
    let mid = side / 2;
    for (x, row) in c.iter_mut().enumerate().take(side - 1).skip(1) {
        for (y, cell) in row.iter_mut().enumerate().take(side - 1).skip(1) {
            let divider = y == mid
                && match map {
                    MapType::A => false,
                    MapType::B => true,
                    MapType::C => x < side - 2,
                };
            *cell = if divider { Tile::Counter } else { Tile::Space };
        }
    }
    c
}

/// ACAC's Large start map (`map_utils.make_custom_map`) of `side` x `side`, `map`, with
/// `n_foods` objects, `n_plates` plates, `n_knives` knives and `n_agent` agents, or why ACAC's
/// asserts refuse it. On the walls of [`belief_base`]:
/// - objects alternately down the right column (rows 1, 2, ...) and leftwards along the top row
///   (columns `side - 2`, `side - 3`, ...);
/// - the delivery at (`side / 2`, 0);
/// - knives down column 0 from row 1 (a knife meeting the delivery cell skips it);
/// - plates alternately leftwards along the bottom row and upwards along the right column, each
///   on a bare counter;
/// - agents in turn in columns `side / 2 - 1` and `side / 2 + 1`, from the top row down, then
///   from the bottom row up, each on floor.
///
/// Panics if a count exceeds its buffer ([`MAX_FOODS`], [`MAX_PLATES`], [`MAX_KNIVES`],
/// [`MAX_AGENTS`]) or `side` exceeds [`MAX_SIDE`]; the domain's checks rule these out.
pub fn large_start_map(
    side: usize,
    map: MapType,
    n_foods: usize,
    n_plates: usize,
    n_knives: usize,
    n_agent: usize,
) -> Result<Cells, String> {
    assert!(n_foods <= MAX_FOODS && n_plates <= MAX_PLATES && n_knives <= MAX_KNIVES);
    assert!(n_agent <= MAX_AGENTS && side <= MAX_SIDE);
    let mut c = belief_base(side, map);
    let last = side - 1;
    let (mut row, mut col) = (0usize, last);
    for k in 0..n_foods {
        if k % 2 == 0 {
            row += 1;
            if row >= side {
                return Err("too many objects".into());
            }
            c[row][last] = Tile::Food(k as u8);
        } else {
            col = col.checked_sub(1).ok_or("too many objects")?;
            c[0][col] = Tile::Food(k as u8);
        }
    }
    c[side / 2][0] = Tile::Delivery;
    let mut pos = 1;
    for _ in 0..n_knives {
        if pos >= side {
            return Err("too many knives".into());
        }
        if c[pos][0] != Tile::Counter {
            pos += 1;
            if pos >= side {
                return Err("too many knives".into());
            }
        }
        c[pos][0] = Tile::Knife;
        pos += 1;
    }
    let (mut row, mut col) = (last, last);
    for p in 0..n_plates {
        let cell = if p % 2 == 0 {
            col = col.checked_sub(1).ok_or("too many plates")?;
            &mut c[last][col]
        } else {
            row = row.checked_sub(1).ok_or("too many plates")?;
            &mut c[row][last]
        };
        if *cell != Tile::Counter {
            return Err("too many plates".into());
        }
        *cell = Tile::Plate;
    }
    let (left, right) = (side / 2 - 1, side / 2 + 1);
    let (mut top_l, mut top_r, mut bottom_l, mut bottom_r) = (0, 0, last, last);
    for i in 0..n_agent {
        let (x, y) = match i % 4 {
            0 => {
                top_l += 1;
                (top_l, left)
            }
            1 => {
                top_r += 1;
                (top_r, right)
            }
            2 => {
                bottom_l -= 1;
                (bottom_l, left)
            }
            _ => {
                bottom_r -= 1;
                (bottom_r, right)
            }
        };
        if c[x][y] != Tile::Space {
            return Err("too many agents".into());
        }
        c[x][y] = Tile::Agent;
    }
    Ok(c)
}

/// The divider rows "go to counter" tries in order (column `side / 2`), the reference's
/// `counterSequence`; empty for map A, which has no such macro-action.
pub fn counter_sequence(side: usize, map: MapType) -> &'static [i32] {
    match (side, map) {
        (7, MapType::B) => &[3, 2, 4, 1, 5],
        (7, MapType::C) => &[3, 2, 4, 1],
        (9, MapType::B) => &[4, 3, 5, 2, 6, 1, 7],
        (9, MapType::C) => &[4, 3, 5, 2, 6, 1],
        (11, MapType::B) => &[5, 4, 6, 3, 7, 2, 8, 1, 9],
        (11, MapType::C) => &[5, 4, 6, 3, 7, 2, 8, 1],
        _ => &[],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(c: &Cells, side: usize) -> Vec<Vec<u8>> {
        (0..side)
            .map(|x| (0..side).map(|y| Rules::V1.code(c[x][y])).collect())
            .collect()
    }

    #[test]
    fn seven_by_seven_maps_are_the_references() {
        let b3 = start_map(7, MapType::B, 3).unwrap();
        assert_eq!(
            rows(&b3, 7),
            vec![
                vec![1, 1, 1, 1, 1, 3, 1],
                vec![6, 0, 2, 1, 2, 0, 4],
                vec![6, 0, 0, 1, 0, 0, 8],
                vec![7, 0, 0, 1, 0, 0, 1],
                vec![1, 0, 0, 1, 0, 0, 1],
                vec![1, 0, 2, 1, 0, 0, 5],
                vec![1, 1, 1, 1, 1, 5, 1],
            ]
        );
        let c2 = start_map(7, MapType::C, 2).unwrap();
        assert_eq!(rows(&c2, 7)[5], vec![1, 0, 0, 0, 0, 0, 5]);
        assert_eq!(rows(&c2, 7)[4], vec![1, 0, 0, 1, 0, 0, 1]);
        let a3 = start_map(7, MapType::A, 3).unwrap();
        assert_eq!(rows(&a3, 7)[5], vec![1, 0, 2, 0, 0, 0, 5]);
        assert!(start_map(7, MapType::A, 4).is_none());
        assert!(start_map(8, MapType::A, 3).is_none());
    }

    #[test]
    fn nine_by_nine_and_belief_maps_are_the_references() {
        let c3 = start_map(9, MapType::C, 3).unwrap();
        assert_eq!(rows(&c3, 9)[7], vec![1, 0, 2, 0, 0, 0, 0, 0, 5]);
        assert_eq!(rows(&c3, 9)[6], vec![1, 0, 0, 0, 1, 0, 0, 0, 1]);
        let base = belief_base(7, MapType::C);
        assert_eq!(rows(&base, 7)[4], vec![1, 0, 0, 1, 0, 0, 1]);
        assert_eq!(rows(&base, 7)[5], vec![1, 0, 0, 0, 0, 0, 1]);
        assert_eq!(rows(&belief_base(9, MapType::B), 9)[7][4], 1);
    }

    /// ACAC's `make_custom_map(map_type="B", n_agent=6, size=11, obj=A..F, n_plate=4,
    /// n_knife=4)`, printed by ACAC's code (V0's codes).
    #[test]
    fn acacs_large_map_b() {
        let c = large_start_map(11, MapType::B, 6, 4, 4, 6).unwrap();
        let rows: Vec<Vec<u8>> = (0..11)
            .map(|x| (0..11).map(|y| Rules::V0.code(c[x][y])).collect())
            .collect();
        assert_eq!(
            rows,
            vec![
                vec![1, 1, 1, 1, 1, 1, 1, 11, 9, 7, 1],
                vec![4, 0, 0, 0, 2, 1, 2, 0, 0, 0, 6],
                vec![4, 0, 0, 0, 2, 1, 2, 0, 0, 0, 8],
                vec![4, 0, 0, 0, 0, 1, 0, 0, 0, 0, 10],
                vec![4, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
                vec![5, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
                vec![1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
                vec![1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
                vec![1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 3],
                vec![1, 0, 0, 0, 2, 1, 2, 0, 0, 0, 3],
                vec![1, 1, 1, 1, 1, 1, 1, 1, 3, 3, 1],
            ]
        );
        assert_eq!(
            large_start_map(11, MapType::A, 6, 4, 4, 6).unwrap()[9][5],
            Tile::Space
        );
        for code in 0..12 {
            let t = Rules::V0.tile(code, 6).unwrap();
            assert_eq!(Rules::V0.code(t), code);
        }
        assert_eq!(Rules::V0.tile(12, 6), None);
        for code in 0..9 {
            assert_eq!(Rules::V1.code(Rules::V1.tile(code, 3).unwrap()), code);
        }
    }
}
