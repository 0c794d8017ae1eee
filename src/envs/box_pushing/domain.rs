//! Box Pushing as configs, runs and policy files know it: `env_name = "BP_MA"` (alias
//! `box-pushing`), its keys `grid_dim` and `env_terminate_step` (the reference's names), the
//! paper's settings for it (`docs/ALGORITHMS.md` §10.1, 10.2) and its tagged form in policy and
//! replay files, `{"env": "box-pushing", "grid": 10, "horizon": 100}`.

use super::{BoxPushing, Rules};
use crate::envs::domain::{
    fill_keys, fixed_key, key_table, key_usize, refuse_unknown_fields, tagged_count, Domain,
    KeyError, HORIZON_KEY,
};
use crate::envs::EnvError;

/// Largest grid side a config may ask for (paper: 10 and 30), far below [`super::MAX_GRID`]
/// so that a run's memory stays bounded (README "Limits and guarantees").
pub const MAX_GRID_DIM: usize = 1_000;

/// The reference's `--grid_dim` default, Figure 4a's grid.
pub const DEFAULT_GRID_DIM: usize = 10;

/// The Box Pushing domain.
pub struct BoxPushingDomain;

/// The paper's horizon for a grid: 100 steps below 30 x 30 (Figure 4a's 10 x 10), 200 from
/// 30 x 30 on (Figure 4b) (`docs/ALGORITHMS.md` §10.1, 10.2).
pub(super) fn paper_horizon(grid: usize) -> usize {
    if grid >= 30 {
        200
    } else {
        100
    }
}

/// The config key of a parameter [`BoxPushing::check_params`] names (`grid_dim`, the horizon).
pub(crate) fn key_of(e: EnvError) -> KeyError {
    match e {
        EnvError::InvalidParameter {
            name: "grid",
            reason,
        } => KeyError::new("grid_dim", reason),
        EnvError::InvalidParameter { reason, .. } => KeyError::new(HORIZON_KEY, reason),
        other => KeyError::new("env_name", other.to_string()),
    }
}

impl Domain for BoxPushingDomain {
    type Env = BoxPushing;

    fn name(&self) -> &'static str {
        "BP_MA"
    }

    fn aliases(&self) -> &'static [&'static str] {
        &["box-pushing"]
    }

    /// `grid_dim` (default 10), `env_terminate_step` (default: the paper's for the grid), and
    /// `tb_m_noisy`, which the reference's command line has for every domain and Box Pushing
    /// runs record as 0: Box Pushing does not read it, so it is always 0 (another value is
    /// refused, not dropped).
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        let mut keys = fill_keys(
            given,
            key_table([
                ("grid_dim", (DEFAULT_GRID_DIM as i64).into()),
                (HORIZON_KEY, (paper_horizon(DEFAULT_GRID_DIM) as i64).into()),
                ("tb_m_noisy", 0.0.into()),
            ]),
        )?;
        let grid = key_usize(&keys, "grid_dim")?;
        if grid > MAX_GRID_DIM {
            return Err(KeyError::new(
                "grid_dim",
                format!("must be at most {MAX_GRID_DIM}, got {grid}"),
            ));
        }
        if !given.contains_key(HORIZON_KEY) {
            keys.insert(HORIZON_KEY.into(), (paper_horizon(grid) as i64).into());
        }
        fixed_key(
            &mut keys,
            "tb_m_noisy",
            toml::Value::Float(0.0),
            "Box Pushing",
        )?;
        BoxPushing::check_params(grid, key_usize(&keys, HORIZON_KEY)?, &Rules::ICRA)
            .map_err(key_of)?;
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<BoxPushing, KeyError> {
        BoxPushing::new(key_usize(keys, "grid_dim")?, key_usize(keys, HORIZON_KEY)?).map_err(key_of)
    }

    /// Figure 4 discounts by 0.98 at every grid (`docs/ALGORITHMS.md` §10.1, 10.2).
    fn paper_discount(&self, _keys: &toml::Table) -> Option<f64> {
        Some(0.98)
    }

    fn short_name(&self, keys: &toml::Table) -> String {
        format!(
            "bp{}",
            key_usize(keys, "grid_dim").unwrap_or(DEFAULT_GRID_DIM)
        )
    }

    fn tag(&self) -> &'static str {
        "box-pushing"
    }

    fn to_tagged(&self, keys: &toml::Table) -> serde_json::Map<String, serde_json::Value> {
        let mut m = serde_json::Map::new();
        m.insert(
            "grid".into(),
            key_usize(keys, "grid_dim").unwrap_or(0).into(),
        );
        m.insert(
            "horizon".into(),
            key_usize(keys, HORIZON_KEY).unwrap_or(0).into(),
        );
        m
    }

    fn keys_of_tagged(
        &self,
        fields: &serde_json::Map<String, serde_json::Value>,
    ) -> Result<toml::Table, KeyError> {
        refuse_unknown_fields(fields, Domain::tag(self), &["grid", "horizon"])?;
        let grid = tagged_count(fields, "grid")?;
        let horizon = tagged_count(fields, "horizon")?;
        Domain::keys(
            self,
            &key_table([("grid_dim", grid.into()), (HORIZON_KEY, horizon.into())]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::box_pushing::paper_spec;

    #[test]
    fn the_horizon_follows_the_grid_and_keys_are_named() {
        assert_eq!(paper_spec(10).horizon(), 100);
        assert_eq!(paper_spec(30).horizon(), 200);
        assert_eq!(paper_spec(30).short_name(), "bp30");
        let d = BoxPushingDomain;
        for (given, key) in [
            (toml::toml! { grid_dim = 6 }, "grid_dim"),
            (toml::toml! { grid_dim = 11 }, "grid_dim"),
            (toml::toml! { grid_dim = 100000 }, "grid_dim"),
            (toml::toml! { env_terminate_step = 0 }, "env_terminate_step"),
        ] {
            assert_eq!(Domain::keys(&d, &given).unwrap_err().key, key, "{given}");
        }
    }

    #[test]
    fn figure_4_discounts_by_0_98() {
        assert_eq!(paper_spec(10).paper_discount(), Some(0.98));
        assert_eq!(paper_spec(30).paper_discount(), Some(0.98));
    }
}
