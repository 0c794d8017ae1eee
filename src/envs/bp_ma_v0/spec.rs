//! `BP-MA-v0` specs for code and tests (configs and files make them through the registry).

use super::BpMaV0Domain;
use crate::envs::domain::{key_table, HORIZON_KEY};
use crate::envs::EnvSpec;

/// `BP-MA-v0` on a `grid` x `grid` grid with the published rewards and a runner horizon of
/// `horizon` primitive steps.
pub fn spec(grid: usize, horizon: usize) -> EnvSpec {
    EnvSpec::of(
        &BpMaV0Domain,
        &key_table([
            ("grid_dim", (grid as i64).into()),
            (HORIZON_KEY, (horizon as i64).into()),
        ]),
    )
    .expect("a valid BP-MA-v0 grid and horizon")
}
