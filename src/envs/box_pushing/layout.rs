//! The deterministic start configuration and waypoints (`docs/BOX_PUSHING.md` §2).

use super::geometry::{Cell, Heading};

/// Where everything starts on an N x N grid, and the four fixed waypoints.
///
/// For N >= 8 these are the reference's formulas (`docs/BOX_PUSHING.md` §2), written with N for both axes: the
/// reference computes several x positions from ylen (Q9), which only matters on non-square grids,
/// and those are not supported. MacroMARL's `box_pushing_MA.py` adds fixed layouts for N = 6
/// (robots and small boxes in the outer columns) and for smaller grids (the 4 x 4 one, robots in
/// the bottom row).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct GridLayout {
    /// Grid side N (even).
    pub n: i32,
    /// Robot start cells and headings: robot 0 facing east, robot 1 facing west; (1, 1) and
    /// (N-2, 1) from N = 8 on.
    pub robot_starts: [(Cell, Heading); 2],
    /// Small boxes 0 and 1; (1, N/2) and (N-2, N/2) from N = 8 on.
    pub small_boxes: [Cell; 2],
    /// Left cell of the 1 x 2 big box; (N/2-1, N/2) from N = 8 on. It also covers the cell east
    /// of it.
    pub big_box_left: Cell,
    /// W0..W3, each the cell below its box; W_k is the target of macro-action k (`docs/BOX_PUSHING.md` §2, 3).
    pub waypoints: [Cell; 4],
}

impl GridLayout {
    /// The layout of an N x N grid. `n` must be even and at least 4 (checked by the constructor
    /// of [`super::BoxPushing`]).
    pub fn new(n: i32) -> Self {
        let half = n / 2;
        // The robots' start row and the columns of small box 0, small box 1 and the big box's
        // left cell (the reference's three branches on ylen).
        let (start_row, [c0, c1, big]) = match n {
            8.. => (1, [1, n - 2, half - 1]),
            6 => (1, [0, 5, 2]),
            _ => (0, [0, 3, 1]),
        };
        Self {
            n,
            robot_starts: [
                (Cell::new(c0, start_row), Heading::East),
                (Cell::new(c1, start_row), Heading::West),
            ],
            small_boxes: [Cell::new(c0, half), Cell::new(c1, half)],
            big_box_left: Cell::new(big, half),
            waypoints: [
                Cell::new(c0, half - 1),
                Cell::new(c1, half - 1),
                Cell::new(big, half - 1),
                Cell::new(big + 1, half - 1),
            ],
        }
    }

    /// The goal row (the top row, `docs/BOX_PUSHING.md` §1).
    #[inline]
    pub fn goal_row(&self) -> i32 {
        self.n - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ten_by_ten_matches_the_spec_table() {
        let l = GridLayout::new(10);
        assert_eq!(l.robot_starts[0], (Cell::new(1, 1), Heading::East));
        assert_eq!(l.robot_starts[1], (Cell::new(8, 1), Heading::West));
        assert_eq!(l.small_boxes, [Cell::new(1, 5), Cell::new(8, 5)]);
        assert_eq!(l.big_box_left, Cell::new(4, 5));
        assert_eq!(
            l.waypoints,
            [
                Cell::new(1, 4),
                Cell::new(8, 4),
                Cell::new(4, 4),
                Cell::new(5, 4)
            ]
        );
        assert_eq!(l.goal_row(), 9);
    }

    #[test]
    fn thirty_by_thirty_matches_the_spec_table() {
        let l = GridLayout::new(30);
        assert_eq!(l.robot_starts[1], (Cell::new(28, 1), Heading::West));
        assert_eq!(l.small_boxes, [Cell::new(1, 15), Cell::new(28, 15)]);
        assert_eq!(l.big_box_left, Cell::new(14, 15));
        assert_eq!(
            l.waypoints,
            [
                Cell::new(1, 14),
                Cell::new(28, 14),
                Cell::new(14, 14),
                Cell::new(15, 14)
            ]
        );
    }

    #[test]
    fn six_and_four_follow_macromarls_fixed_layouts() {
        // box_pushing_MA.py: 6 x 6 robots at x 0.5 / 5.5, y 1.5; boxes at y 3.5, big box x 3.0.
        let l = GridLayout::new(6);
        assert_eq!(l.robot_starts[0], (Cell::new(0, 1), Heading::East));
        assert_eq!(l.robot_starts[1], (Cell::new(5, 1), Heading::West));
        assert_eq!(l.small_boxes, [Cell::new(0, 3), Cell::new(5, 3)]);
        assert_eq!(l.big_box_left, Cell::new(2, 3));
        // 4 x 4: robots at y 0.5, x 0.5 / 3.5; boxes at y 2.5, big box x 2.0.
        let l = GridLayout::new(4);
        assert_eq!(l.robot_starts[0], (Cell::new(0, 0), Heading::East));
        assert_eq!(l.robot_starts[1], (Cell::new(3, 0), Heading::West));
        assert_eq!(l.small_boxes, [Cell::new(0, 2), Cell::new(3, 2)]);
        assert_eq!(l.big_box_left, Cell::new(1, 2));
        assert_eq!(l.waypoints[3], Cell::new(2, 1));
    }

    #[test]
    fn every_waypoint_is_directly_below_its_box() {
        for n in [4, 6, 8, 10, 12, 30] {
            let l = GridLayout::new(n);
            assert_eq!(l.waypoints[0].step(Heading::North), l.small_boxes[0]);
            assert_eq!(l.waypoints[1].step(Heading::North), l.small_boxes[1]);
            assert_eq!(l.waypoints[2].step(Heading::North), l.big_box_left);
            assert_eq!(
                l.waypoints[3].step(Heading::North),
                l.big_box_left.step(Heading::East)
            );
        }
    }
}
