//! Warehouse Tool Delivery as configs, runs and policy files know it: `env_name = "OSD_S_4"`
//! (alias `warehouse`), its keys `env_terminate_step` and `tb_m_noisy` (the reference's names),
//! Figure 5's settings (`docs/ALGORITHMS.md` §10.3) and its tagged form in policy and replay
//! files, `{"env": "warehouse", "horizon": 150, "tb_m_noisy": 0.0}`.

use super::{Warehouse, WarehouseParams};
use crate::envs::domain::{
    fill_keys, fixed_key, key_f64, key_table, key_usize, refuse_unknown_fields, tagged_count,
    Domain, KeyError, HORIZON_KEY,
};
use crate::envs::EnvError;

/// The grid side Warehouse runs record: the reference's `--grid_dim` default, which Warehouse
/// does not read.
const RECORDED_GRID_DIM: i64 = 10;

/// The Warehouse Tool Delivery domain.
pub struct WarehouseDomain;

/// The full parameter set: the keys' horizon and noise, the paper's values for the rest.
fn params(keys: &toml::Table) -> Result<WarehouseParams, KeyError> {
    Ok(WarehouseParams {
        terminate_step: key_usize(keys, HORIZON_KEY)?,
        tb_move_noisy: key_f64(keys, "tb_m_noisy")?,
        ..WarehouseParams::default()
    })
}

/// The config key of a parameter [`WarehouseParams::validate`] names; the fixed layout's
/// parameters, which no key sets, are blamed on `env_name`.
fn key_of(e: EnvError) -> KeyError {
    match e {
        EnvError::InvalidParameter { name, reason } => KeyError::new(
            match name {
                "terminate_step" => HORIZON_KEY,
                "tb_move_noisy" => "tb_m_noisy",
                _ => "env_name",
            },
            format!("{reason} (warehouse parameter `{name}`)"),
        ),
        other => KeyError::new("env_name", other.to_string()),
    }
}

impl Domain for WarehouseDomain {
    type Env = Warehouse;

    fn name(&self) -> &'static str {
        "OSD_S_4"
    }

    fn aliases(&self) -> &'static [&'static str] {
        &["warehouse"]
    }

    /// `grid_dim` (recorded as the reference's 10 and not read), `env_terminate_step` (default
    /// 150) and `tb_m_noisy` (default 0).
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        let p = WarehouseParams::default();
        let mut keys = fill_keys(
            given,
            key_table([
                ("grid_dim", RECORDED_GRID_DIM.into()),
                (HORIZON_KEY, (p.terminate_step as i64).into()),
                ("tb_m_noisy", p.tb_move_noisy.into()),
            ]),
        )?;
        fixed_key(
            &mut keys,
            "grid_dim",
            RECORDED_GRID_DIM.into(),
            "the ICRA Warehouse",
        )?;
        params(&keys)?.validate().map_err(key_of)?;
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<Warehouse, KeyError> {
        Warehouse::new(params(keys)?).map_err(key_of)
    }

    /// Figure 5 is undiscounted (`docs/ALGORITHMS.md` §10.3).
    fn paper_discount(&self, _keys: &toml::Table) -> Option<f64> {
        Some(1.0)
    }

    fn short_name(&self, _keys: &toml::Table) -> String {
        "wtd".into()
    }

    fn tag(&self) -> &'static str {
        "warehouse"
    }

    fn to_tagged(&self, keys: &toml::Table) -> serde_json::Map<String, serde_json::Value> {
        let mut m = serde_json::Map::new();
        m.insert(
            "horizon".into(),
            key_usize(keys, HORIZON_KEY).unwrap_or(0).into(),
        );
        m.insert(
            "tb_m_noisy".into(),
            key_f64(keys, "tb_m_noisy").unwrap_or(0.0).into(),
        );
        m
    }

    fn keys_of_tagged(
        &self,
        fields: &serde_json::Map<String, serde_json::Value>,
    ) -> Result<toml::Table, KeyError> {
        refuse_unknown_fields(fields, Domain::tag(self), &["horizon", "tb_m_noisy"])?;
        let horizon = tagged_count(fields, "horizon")?;
        let noise = match fields.get("tb_m_noisy") {
            Some(v) => v.as_f64().ok_or_else(|| {
                KeyError::new("tb_m_noisy", format!("expected a number, got {v}"))
            })?,
            None => 0.0,
        };
        Domain::keys(
            self,
            &key_table([(HORIZON_KEY, horizon.into()), ("tb_m_noisy", noise.into())]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::warehouse::{paper_spec, spec};

    #[test]
    fn each_bad_parameter_is_named_by_its_config_key() {
        let d = WarehouseDomain;
        for (given, key) in [
            (key_table([(HORIZON_KEY, 0.into())]), HORIZON_KEY),
            (key_table([("tb_m_noisy", (-1.0).into())]), "tb_m_noisy"),
            (key_table([("tb_m_noisy", f64::NAN.into())]), "tb_m_noisy"),
        ] {
            assert_eq!(Domain::keys(&d, &given).unwrap_err().key, key, "{given}");
        }
        assert_eq!(spec(150, 0.3).horizon(), 150);
        assert_eq!(paper_spec().paper_discount(), Some(1.0));
        // The unused grid is recorded as the reference's default; another value is refused,
        // not dropped.
        let keys = Domain::keys(&d, &key_table([("grid_dim", 10.into())])).unwrap();
        assert_eq!(keys["grid_dim"].as_integer(), Some(10));
        let err = Domain::keys(&d, &key_table([("grid_dim", 30.into())])).unwrap_err();
        assert_eq!(err.key, "grid_dim");
        assert!(err.message.contains("does not read this key"), "{err:?}");
    }
}
