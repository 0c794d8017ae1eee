//! Box Pushing specs for code and tests: [`spec`] with a grid and horizon, [`paper_spec`] at the
//! paper's horizon for the grid (configs and files make them through the registry instead).

use super::domain::{paper_horizon, BoxPushingDomain};
use crate::envs::domain::{key_table, HORIZON_KEY};
use crate::envs::EnvSpec;

/// Box Pushing on a `grid` x `grid` grid with `horizon` primitive steps.
pub fn spec(grid: usize, horizon: usize) -> EnvSpec {
    EnvSpec::of(
        &BoxPushingDomain,
        &key_table([
            ("grid_dim", (grid as i64).into()),
            (HORIZON_KEY, (horizon as i64).into()),
        ]),
    )
    .expect("a valid Box Pushing grid and horizon")
}

/// Box Pushing at the paper's horizon for its grid (100 steps below 30 x 30, 200 from 30 x 30
/// on; `docs/ALGORITHMS.md` §10.1, 10.2).
pub fn paper_spec(grid: usize) -> EnvSpec {
    spec(grid, paper_horizon(grid))
}
