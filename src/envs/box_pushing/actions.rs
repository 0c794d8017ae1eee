//! The eight macro-actions of each robot (`docs/BOX_PUSHING.md` §3).

/// Reference names, indexed by macro-action (`docs/BOX_PUSHING.md` §3). Kept as the reference spells them so a
/// replay can be diffed against it.
pub const ACTION_NAMES: [&str; 8] = [
    "GT_SB0", "GT_SB1", "GT_BB0", "GT_BB1", "Push", "T_L", "T_R", "Stay",
];

/// Number of macro-actions per robot.
pub const N_ACTIONS: usize = 8;

/// Index of Push, the action the joint big-box check looks for (`docs/BOX_PUSHING.md` §4 step 3).
pub const PUSH: usize = 4;

/// A robot's macro-action. Indices 0..3 navigate to waypoint W0..W3 (`docs/BOX_PUSHING.md` §5.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MacroAction {
    /// Move to waypoint `k` (0..=3), the cell below small box 0 / small box 1 / the big box's
    /// left / right half.
    MoveTo(u8),
    /// Push forward until a stop condition (`docs/BOX_PUSHING.md` §5.2, §5.4).
    Push,
    /// Turn left, one step (`docs/BOX_PUSHING.md` §5.3).
    TurnLeft,
    /// Turn right, one step (`docs/BOX_PUSHING.md` §5.3).
    TurnRight,
    /// Do nothing for one step (`docs/BOX_PUSHING.md` §5.3).
    Stay,
}

impl MacroAction {
    /// The action with index `i`, or `None` if `i >= 8`.
    #[inline]
    pub fn from_index(i: usize) -> Option<Self> {
        Some(match i {
            0..=3 => MacroAction::MoveTo(i as u8),
            4 => MacroAction::Push,
            5 => MacroAction::TurnLeft,
            6 => MacroAction::TurnRight,
            7 => MacroAction::Stay,
            _ => return None,
        })
    }

    /// The action's index in 0..8.
    #[inline]
    pub fn index(self) -> usize {
        match self {
            MacroAction::MoveTo(k) => k as usize,
            MacroAction::Push => 4,
            MacroAction::TurnLeft => 5,
            MacroAction::TurnRight => 6,
            MacroAction::Stay => 7,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_round_trip_and_stop_at_eight() {
        for i in 0..N_ACTIONS {
            assert_eq!(MacroAction::from_index(i).map(MacroAction::index), Some(i));
        }
        assert_eq!(MacroAction::from_index(8), None);
        assert_eq!(ACTION_NAMES[PUSH], "Push");
    }
}
