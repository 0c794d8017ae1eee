//! Warehouse specs for code and tests: [`spec`] with a horizon and noise, [`paper_spec`] as in
//! Figure 5 (configs and files make them through the registry instead).

use super::domain::WarehouseDomain;
use super::WarehouseParams;
use crate::envs::domain::{key_table, HORIZON_KEY};
use crate::envs::EnvSpec;

/// Warehouse with `horizon` primitive steps and Turtlebot movement noise std `tb_m_noisy`.
pub fn spec(horizon: usize, tb_m_noisy: f64) -> EnvSpec {
    EnvSpec::of(
        &WarehouseDomain,
        &key_table([
            (HORIZON_KEY, (horizon as i64).into()),
            ("tb_m_noisy", tb_m_noisy.into()),
        ]),
    )
    .expect("a valid Warehouse horizon and noise")
}

/// Warehouse as in Figure 5: horizon 150, no movement noise (`docs/ALGORITHMS.md` §10.3).
pub fn paper_spec() -> EnvSpec {
    let p = WarehouseParams::default();
    spec(p.terminate_step, p.tb_move_noisy)
}
