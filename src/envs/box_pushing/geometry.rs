//! Cells and headings of the Box Pushing grid (`docs/BOX_PUSHING.md` §1).
//!
//! The reference works in continuous coordinates whose reachable values are all exact
//! half-integers, so integer cells reproduce its float equality tests exactly: col = x - 0.5 and
//! row = y - 0.5. Row 0 is the bottom row; rows grow to the north.

/// A grid cell `(col, row)`. Signed, because the Q2 "teleport" joint push may lift a robot above
/// the top row (`docs/BOX_PUSHING.md` Q2), and a front cell may lie outside the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Cell {
    /// Column, 0 at the west edge.
    pub col: i32,
    /// Row, 0 at the bottom (south) edge.
    pub row: i32,
}

impl Cell {
    /// The cell at column `col`, row `row`.
    pub const fn new(col: i32, row: i32) -> Self {
        Self { col, row }
    }

    /// The neighbouring cell one step in `heading`.
    #[inline]
    pub fn step(self, heading: Heading) -> Self {
        let (dc, dr) = heading.delta();
        Self::new(self.col + dc, self.row + dr)
    }

    /// The neighbouring cell one step against `heading` (where a bounced robot returns to).
    #[inline]
    pub fn step_back(self, heading: Heading) -> Self {
        let (dc, dr) = heading.delta();
        Self::new(self.col - dc, self.row - dr)
    }

    /// Manhattan distance in cells, the navigation planner's score (`docs/BOX_PUSHING.md` §5.1).
    #[inline]
    pub fn manhattan(self, other: Cell) -> i32 {
        (self.col - other.col).abs() + (self.row - other.row).abs()
    }

    /// Outside an `n` x `n` grid (`docs/BOX_PUSHING.md` §1: col or row below 0 or at least `n`).
    #[inline]
    pub fn is_outside(self, n: i32) -> bool {
        self.col < 0 || self.row < 0 || self.col >= n || self.row >= n
    }
}

/// A robot heading, in the reference's direction order (`docs/BOX_PUSHING.md` §1): 0 north, 1 east, 2 south,
/// 3 west. The index also orders the planner's tie-break (`docs/BOX_PUSHING.md` §5.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[repr(u8)]
pub enum Heading {
    /// Towards higher rows.
    North = 0,
    /// Towards higher columns.
    East = 1,
    /// Towards lower rows.
    South = 2,
    /// Towards lower columns.
    West = 3,
}

impl Heading {
    /// All headings in direction-index order.
    pub const ALL: [Heading; 4] = [Heading::North, Heading::East, Heading::South, Heading::West];

    /// The heading with direction index `i mod 4`.
    #[inline]
    pub fn from_index(i: usize) -> Self {
        Self::ALL[i % 4]
    }

    /// The direction index, 0 to 3.
    #[inline]
    pub fn index(self) -> usize {
        self as usize
    }

    /// Unit vector `(dcol, drow)`: north is `(0, +1)`, east `(+1, 0)`.
    #[inline]
    pub fn delta(self) -> (i32, i32) {
        match self {
            Heading::North => (0, 1),
            Heading::East => (1, 0),
            Heading::South => (0, -1),
            Heading::West => (-1, 0),
        }
    }

    /// Clockwise quarter turn, h -> (h+1) mod 4 (Turn-right, and the planner's "behind" turn, Q7).
    #[inline]
    pub fn right(self) -> Self {
        Self::from_index(self.index() + 1)
    }

    /// Counter-clockwise quarter turn, h -> (h+3) mod 4 (Turn-left).
    #[inline]
    pub fn left(self) -> Self {
        Self::from_index(self.index() + 3)
    }

    /// The heading directly behind, (h+2) mod 4.
    #[inline]
    pub fn behind(self) -> Self {
        Self::from_index(self.index() + 2)
    }

    /// One character for the ASCII picture.
    pub fn arrow(self) -> char {
        match self {
            Heading::North => '^',
            Heading::East => '>',
            Heading::South => 'v',
            Heading::West => '<',
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_follow_the_reference_direction_order() {
        assert_eq!(Heading::North.right(), Heading::East);
        assert_eq!(Heading::West.right(), Heading::North);
        assert_eq!(Heading::North.left(), Heading::West);
        assert_eq!(Heading::East.left(), Heading::North);
        assert_eq!(Heading::South.behind(), Heading::North);
    }

    #[test]
    fn north_increases_the_row_and_east_the_column() {
        let c = Cell::new(3, 4);
        assert_eq!(c.step(Heading::North), Cell::new(3, 5));
        assert_eq!(c.step(Heading::East), Cell::new(4, 4));
        assert_eq!(c.step_back(Heading::East), Cell::new(2, 4));
    }

    #[test]
    fn outside_means_beyond_any_edge() {
        assert!(Cell::new(-1, 0).is_outside(10));
        assert!(Cell::new(0, 10).is_outside(10));
        assert!(Cell::new(10, 3).is_outside(10));
        assert!(!Cell::new(9, 9).is_outside(10));
        assert!(!Cell::new(0, 0).is_outside(10));
    }
}
