//! The deterministic start configuration and waypoints (spec `box_pushing.md` section 2).

use super::geometry::{Cell, Heading};

/// Where everything starts on an N x N grid, and the four fixed waypoints.
///
/// These are the reference's formulas for ylen >= 8 (spec 2). They are written with N for both
/// axes: the reference computes several x positions from ylen (Q9), which only matters on
/// non-square grids, and those are not supported.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct GridLayout {
    /// Grid side N (even, >= 8).
    pub n: i32,
    /// Robot start cells and headings: robot 0 at (1, 1) facing east, robot 1 at (N-2, 1) facing
    /// west.
    pub robot_starts: [(Cell, Heading); 2],
    /// Small boxes 0 and 1 at (1, N/2) and (N-2, N/2).
    pub small_boxes: [Cell; 2],
    /// Left cell of the 1 x 2 big box, (N/2-1, N/2); it also covers (N/2, N/2).
    pub big_box_left: Cell,
    /// W0..W3, each the cell below its box; W_k is the target of macro-action k (spec 2, 3).
    pub waypoints: [Cell; 4],
}

impl GridLayout {
    /// The layout of an N x N grid. `n` must be even and >= 8 (checked by the constructor of
    /// [`super::BoxPushing`]).
    pub fn new(n: i32) -> Self {
        let half = n / 2;
        Self {
            n,
            robot_starts: [
                (Cell::new(1, 1), Heading::East),
                (Cell::new(n - 2, 1), Heading::West),
            ],
            small_boxes: [Cell::new(1, half), Cell::new(n - 2, half)],
            big_box_left: Cell::new(half - 1, half),
            waypoints: [
                Cell::new(1, half - 1),
                Cell::new(n - 2, half - 1),
                Cell::new(half - 1, half - 1),
                Cell::new(half, half - 1),
            ],
        }
    }

    /// The goal row (the top row, spec 1).
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
    fn every_waypoint_is_directly_below_its_box() {
        for n in [8, 10, 12, 30] {
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
