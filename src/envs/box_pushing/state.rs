//! The mutable world: robots and boxes (`docs/BOX_PUSHING.md` §2 and 4).

use super::actions::MacroAction;
use super::geometry::{Cell, Heading};

/// One robot's physical and controller state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Robot {
    /// The cell it stands on.
    pub cell: Cell,
    /// Which way it faces.
    pub heading: Heading,
    /// The macro-action being executed (None only between reset and the first step).
    pub current: Option<MacroAction>,
    /// Whether the current macro-action finished in the last step, so the robot picks a new one
    /// at the next step ("macro-action done"; true at reset).
    pub finished: bool,
    /// The waypoint index of the last completed Move-to-waypoint. Never cleared until reset
    /// (quirk Q2), and the only thing besides the heading that the joint push check looks at.
    pub waypoint: Option<u8>,
}

impl Robot {
    /// A free robot with no history, as after reset (`docs/BOX_PUSHING.md` §2, "Internal state at reset").
    pub fn at_start(cell: Cell, heading: Heading) -> Self {
        Self {
            cell,
            heading,
            current: None,
            finished: true,
            waypoint: None,
        }
    }
}

/// The three boxes. Small boxes occupy one cell; the big box occupies its left cell and the cell to
/// the east of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Boxes {
    /// The two small boxes' cells.
    pub small: [Cell; 2],
    /// The big box's left (western) cell.
    pub big_left: Cell,
}

impl Boxes {
    /// Whether `cell` is one of the big box's two cells.
    #[inline]
    pub fn big_covers(&self, cell: Cell) -> bool {
        cell.row == self.big_left.row
            && (cell.col == self.big_left.col || cell.col == self.big_left.col + 1)
    }

    /// Whether box `k` (0, 1 small, 2 big; the reference's box order) occupies `cell`.
    #[inline]
    pub fn box_covers(&self, k: usize, cell: Cell) -> bool {
        if k < 2 {
            self.small[k] == cell
        } else {
            self.big_covers(cell)
        }
    }

    /// Whether `cell` is a navigation obstacle (`docs/BOX_PUSHING.md` §5.1 (b), quirk Q3): its row is small box 0's
    /// current row and its column is one of the four box columns. Nothing else blocks.
    #[inline]
    pub fn blocks_navigation(&self, cell: Cell) -> bool {
        cell.row == self.small[0].row
            && (cell.col == self.small[0].col
                || cell.col == self.small[1].col
                || cell.col == self.big_left.col
                || cell.col == self.big_left.col + 1)
    }
}
