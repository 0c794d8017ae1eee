//! What the two references' Box Pushing differ in: rewards, grid sizes and the horizon's meaning.
//!
//! The ICRA code (`MacDec-via-Cen`) and MacroMARL run the same dynamics (MacroMARL's core file
//! only adds the `penalty` parameter), but MacroMARL rewards 300 / 20 / -10 instead of 100 / 10 /
//! -5, defines layouts for 6 x 6 and 4 x 4 grids, and leaves the horizon to its runner, which
//! bootstraps at the cut instead of treating it as terminal (ICRA quirk Q7).

/// The rules a [`super::BoxPushing`] plays by.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Rules {
    /// Bonus when the big box enters the goal row.
    pub big_box_reward: f64,
    /// Bonus per small box entering the goal row.
    pub small_box_reward: f64,
    /// Cost of a Push into a wall edge, into the big box alone or into a small box sideways.
    pub penalty: f64,
    /// Whether an episode cut by the horizon ends in a terminal state (ICRA, Q7) or is truncated
    /// so that a learner bootstraps from it (MacroMARL's runner).
    pub horizon_is_terminal: bool,
    /// The smallest grid side: 8 for the ICRA spec's layout formulas, 4 where MacroMARL adds
    /// fixed layouts for 4 x 4 and 6 x 6.
    pub min_grid: usize,
}

impl Rules {
    /// The ICRA paper's Box Pushing (`docs/BOX_PUSHING.md` §7).
    pub const ICRA: Rules = Rules {
        big_box_reward: 100.0,
        small_box_reward: 10.0,
        penalty: -5.0,
        horizon_is_terminal: true,
        min_grid: 8,
    };

    /// MacroMARL's `BP-MA-v0` with its published rewards (`docs/MACROMARL.md` §3.1).
    pub const MACROMARL: Rules = Rules {
        big_box_reward: 300.0,
        small_box_reward: 20.0,
        penalty: -10.0,
        horizon_is_terminal: false,
        min_grid: 4,
    };
}
