//! ACAC's random starts (`rand_start=True`): `Overcooked_V1._make_new_rand_map`, which ACAC's
//! `Overcooked-MA-v0` (Large) inherits unchanged (`../shared/spec/acac_envs.md` §Overcooked-MA-v1
//! item 2).
//!
//! From the start map it keeps only the walls (agents become floor, every item a counter), then:
//! - the agents (code 2) on distinct free interior cells, `randint(1, side - 1, 2)` per agent
//!   (row, then column), redrawing a cell that is taken; on map B the whole set is redrawn until
//!   at least one agent is left of the divider (`column < side / 2`) and one is not;
//! - every other item, by ascending code and once per item, on a border counter (corners
//!   excluded; map B also excludes both ends of the divider column, map C its top end) still
//!   bare: `randint(0, len)` into the lexicographically sorted cell list (`np.unique(axis=0)`),
//!   redrawn when taken.
//!
//! Codes 0 (floor), 1 (counter) and 2 (agent) are shared by both Overcooked versions; the item
//! codes above 2 are each version's own. Allocation-free, so a reset may call it.

use super::layout::{MapType, MAX_AGENTS};
use super::numpy_random::DrawInt;
use super::world::Cell;

/// Border cells of the largest grid (11 x 11): 4 x 9.
const MAX_BORDER: usize = 36;

const SPACE: u8 = 0;
const COUNTER: u8 = 1;
const AGENT: u8 = 2;

/// A map of codes, `grid[x][y]` for `x, y < side` (the rest unused).
pub type Grid<const S: usize> = [[u8; S]; S];

/// The border cells items may be drawn on, sorted (`possible_pos` after `np.unique`); returns
/// how many of `out` are filled.
fn border_cells(side: usize, map: MapType, out: &mut [Cell; MAX_BORDER]) -> usize {
    let s = side as i32;
    let mid = s / 2;
    let excluded = |c: Cell| match map {
        MapType::A => false,
        MapType::B => c == Cell::new(0, mid) || c == Cell::new(s - 1, mid),
        MapType::C => c == Cell::new(0, mid),
    };
    let mut n = 0;
    // Row-major order is the lexicographic order of (x, y).
    for x in 0..s {
        for y in 0..s {
            let c = Cell::new(x, y);
            let on_border = x == 0 || y == 0 || x == s - 1 || y == s - 1;
            let corner = (x == 0 || x == s - 1) && (y == 0 || y == s - 1);
            if on_border && !corner && !excluded(c) {
                out[n] = c;
                n += 1;
            }
        }
    }
    n
}

/// The start map a reset with `rand_start` builds from `init` (the version's fixed start map).
///
/// Panics if `init` holds more than [`MAX_AGENTS`] agents or `side` exceeds `S` (the domains'
/// parameter checks rule both out).
pub fn random_start<const S: usize>(
    init: &Grid<S>,
    side: usize,
    map: MapType,
    draws: &mut impl DrawInt,
) -> Grid<S> {
    assert!(side <= S && side <= 11, "side {side} beyond the grid");
    let mut counts = [0usize; 256];
    let mut out = *init;
    for row in out.iter_mut().take(side) {
        for cell in row.iter_mut().take(side) {
            counts[*cell as usize] += 1;
            *cell = if *cell == SPACE || *cell == AGENT {
                SPACE
            } else {
                COUNTER
            };
        }
    }
    let n_agents = counts[AGENT as usize];
    assert!(n_agents <= MAX_AGENTS, "{n_agents} agents in a start map");
    if n_agents > 0 {
        let mid = (side / 2) as i32;
        let mut chosen = [Cell::new(0, 0); MAX_AGENTS];
        loop {
            for k in 0..n_agents {
                chosen[k] = loop {
                    let x = draws.draw(1, side as i64 - 1) as i32;
                    let y = draws.draw(1, side as i64 - 1) as i32;
                    let c = Cell::new(x, y);
                    if out[x as usize][y as usize] == SPACE && !chosen[..k].contains(&c) {
                        break c;
                    }
                };
            }
            let left = chosen[..n_agents].iter().filter(|c| c.y < mid).count();
            if map != MapType::B || (left >= 1 && left < n_agents) {
                break;
            }
        }
        for c in &chosen[..n_agents] {
            out[c.x as usize][c.y as usize] = AGENT;
        }
    }
    let mut cells = [Cell::new(0, 0); MAX_BORDER];
    let n_cells = border_cells(side, map, &mut cells);
    for code in AGENT + 1..=u8::MAX {
        for _ in 0..counts[code as usize] {
            loop {
                let c = cells[draws.draw(0, n_cells as i64) as usize];
                let cell = &mut out[c.x as usize][c.y as usize];
                if *cell == COUNTER {
                    *cell = code;
                    break;
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::numpy_random::NumpyRandom;
    use super::*;

    #[test]
    fn border_cells_skip_corners_and_divider_ends() {
        let mut out = [Cell::new(0, 0); MAX_BORDER];
        assert_eq!(border_cells(7, MapType::A, &mut out), 20);
        assert_eq!(
            &out[..3],
            &[Cell::new(0, 1), Cell::new(0, 2), Cell::new(0, 3)]
        );
        assert_eq!(out[5], Cell::new(1, 0));
        assert_eq!(border_cells(7, MapType::B, &mut out), 18);
        assert!(!out[..18].contains(&Cell::new(6, 3)));
        assert_eq!(border_cells(7, MapType::C, &mut out), 19);
        assert!(out[..19].contains(&Cell::new(6, 3)));
    }

    #[test]
    fn items_and_agents_keep_their_counts_and_map_b_splits_agents() {
        let init = [
            [1, 1, 1, 1, 1, 3, 1],
            [6, 0, 2, 1, 2, 0, 4],
            [6, 0, 0, 1, 0, 0, 8],
            [7, 0, 0, 1, 0, 0, 1],
            [1, 0, 0, 1, 0, 0, 1],
            [1, 0, 2, 1, 0, 0, 5],
            [1, 1, 1, 1, 1, 5, 1],
        ];
        for seed in 0..50 {
            let m = random_start(&init, 7, MapType::B, &mut NumpyRandom::seed(seed));
            let count = |code: u8| m.iter().flatten().filter(|&&c| c == code).count();
            assert_eq!([count(2), count(5), count(6), count(7)], [3, 2, 2, 1]);
            let agents: Vec<usize> = (0..7)
                .flat_map(|x| (0..7).filter(move |&y| m[x][y] == 2))
                .collect();
            assert!(agents.iter().any(|&y| y < 3) && agents.iter().any(|&y| y >= 3));
            for row in &m[1..6] {
                assert_eq!(row[3], 1, "the divider stays");
            }
        }
    }
}
