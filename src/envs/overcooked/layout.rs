//! The reference's fixed layouts (`overcooked_V1.py: __init__`, `_get_vector_obs`,
//! `overcooked_MA_V1.py: __init__`): the start maps per grid, map type and agent count, the
//! walls-only maps each agent's belief map starts from every step, and the order in which "go to
//! counter" tries the divider's cells.
//!
//! Coordinates are the reference's: `x` is the row of the printed map (0 at the top), `y` the
//! column; `map[x][y]`.

use serde::{Deserialize, Serialize};

/// Largest grid side the reference has maps for (9 x 9).
pub const MAX_SIDE: usize = 9;
/// Most agents a kitchen holds (ACAC's Large kitchen has 6): the capacity of the agents' buffers
/// and of a random start's draws.
pub const MAX_AGENTS: usize = 6;

/// What a cell of a map holds, as the reference's `ITEMNAME` / `ITEMIDX` number it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[repr(u8)]
pub enum Tile {
    /// Floor an agent may walk on.
    Space = 0,
    /// Counter (walls and the divider); items may be put on it.
    Counter = 1,
    /// An agent.
    Agent = 2,
    /// The tomato.
    Tomato = 3,
    /// The lettuce.
    Lettuce = 4,
    /// A plate.
    Plate = 5,
    /// A knife (cutting board).
    Knife = 6,
    /// The delivery counter.
    Delivery = 7,
    /// The onion.
    Onion = 8,
}

impl Tile {
    /// The tile of the reference's index `i` (maps are written with these numbers; above 8,
    /// the onion).
    pub const fn of(i: u8) -> Tile {
        match i {
            0 => Tile::Space,
            1 => Tile::Counter,
            2 => Tile::Agent,
            3 => Tile::Tomato,
            4 => Tile::Lettuce,
            5 => Tile::Plate,
            6 => Tile::Knife,
            7 => Tile::Delivery,
            _ => Tile::Onion,
        }
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

/// A map from rows of the reference's numbers (`rows.len()` is the side).
fn cells<const N: usize>(rows: [[u8; N]; N]) -> Cells {
    let mut c = [[Tile::Counter; MAX_SIDE]; MAX_SIDE];
    for (x, row) in rows.iter().enumerate() {
        for (y, &v) in row.iter().enumerate() {
            c[x][y] = Tile::of(v);
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

/// The divider rows "go to counter" tries in order (column `side / 2`), the reference's
/// `counterSequence`; empty for map A, which has no such macro-action.
pub fn counter_sequence(side: usize, map: MapType) -> &'static [i32] {
    match (side, map) {
        (7, MapType::B) => &[3, 2, 4, 1, 5],
        (7, MapType::C) => &[3, 2, 4, 1],
        (9, MapType::B) => &[4, 3, 5, 2, 6, 1, 7],
        (9, MapType::C) => &[4, 3, 5, 2, 6, 1],
        _ => &[],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(c: &Cells, side: usize) -> Vec<Vec<u8>> {
        (0..side)
            .map(|x| (0..side).map(|y| c[x][y] as u8).collect())
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
}
