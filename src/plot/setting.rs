//! What a figure needs to know about the domain of its runs: a readable description for the title
//! and the optimal return for the red dash-dot line (spec `algorithms.md` 7.2).
//!
//! Read from each run's `config.toml` key by key rather than as a whole `RunConfig`, so an older
//! results tree still plots after the config gains a field.

use crate::envs::flags::{EnvFlags, EnvName, DEFAULT_GRID_DIM};
use crate::envs::EnvSpec;

pub use crate::envs::box_pushing::{BP10_OPTIMAL, BP30_OPTIMAL};
pub use crate::envs::warehouse::WTD_OPTIMAL;
use crate::envs::{AnyEnv, MacroEnv};

/// The domain settings of one run that decide the optimal return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvSetting {
    /// The run's domain (movement noise aside: it decides neither the optimum nor the title).
    pub env: EnvSpec,
    /// Evaluation discount (`discount`).
    pub discount: f64,
}

impl EnvSetting {
    /// Read the setting from a run's `config.toml` text; `Err` says which key is missing or bad.
    /// Only `env_name`, `env_terminate_step` and `discount` are required (`grid_dim` defaults to
    /// the reference's 10).
    pub fn from_config_toml(text: &str) -> Result<Self, String> {
        let mut table: toml::Table = toml::from_str(text).map_err(|e| e.message().to_string())?;
        // A run directory's config.toml holds the run's identity and its resolved config under
        // `[config]` (experiment::train_run::RunManifest); a bare RunConfig is accepted too.
        if let Some(toml::Value::Table(inner)) = table.remove("config") {
            table = inner;
        }
        let env_name: EnvName = table
            .get("env_name")
            .ok_or("no `env_name`")?
            .clone()
            .try_into()
            .map_err(|_| "`env_name` is not BP_MA or OSD_S_4".to_string())?;
        let int = |key: &str| -> Result<Option<usize>, String> {
            match table.get(key) {
                Some(toml::Value::Integer(n)) if *n >= 0 => Ok(Some(*n as usize)),
                Some(v) => Err(format!("`{key}` is not a non-negative integer: {v}")),
                None => Ok(None),
            }
        };
        let discount = match table.get("discount") {
            Some(toml::Value::Float(d)) => *d,
            Some(toml::Value::Integer(d)) => *d as f64,
            Some(v) => return Err(format!("`discount` is not a number: {v}")),
            None => return Err("no `discount`".into()),
        };
        let flags = EnvFlags {
            env_name,
            grid_dim: int("grid_dim")?.unwrap_or(DEFAULT_GRID_DIM),
            env_terminate_step: int("env_terminate_step")?.ok_or("no `env_terminate_step`")?,
            tb_m_noisy: 0.0,
        };
        Ok(EnvSetting {
            env: flags.spec(),
            discount,
        })
    }

    /// The domain this setting describes, built (in its reset state) so it can be asked what it
    /// knows about itself; `None` when the keys describe no valid domain.
    fn domain(&self) -> Option<AnyEnv> {
        self.env.build().ok()
    }

    /// The optimal return of this setting when the domain knows one ([`MacroEnv::optimal_return`]:
    /// BP 10x10 horizon 100 and BP 30x30 horizon 200 at gamma 0.98, WTD horizon 150 at gamma 1).
    /// `None` otherwise (another grid, horizon or discount has no verified optimum, so no line is
    /// drawn).
    pub fn optimal_return(&self) -> Option<f64> {
        self.domain()?.optimal_return(self.discount)
    }

    /// A short description for the figure title, e.g. "Box Pushing 10x10, horizon 100"
    /// ([`MacroEnv::describe`]).
    pub fn describe(&self) -> String {
        match self.domain() {
            Some(env) => env.describe(),
            None => format!("{}, horizon {}", self.env.name(), self.env.horizon()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::method::Method;
    use crate::experiment::run_settings::RunSettings;

    fn setting_of(env: EnvSpec) -> EnvSetting {
        let text = toml::to_string(&RunSettings::paper(env, Method::Our1)).unwrap();
        EnvSetting::from_config_toml(&text).unwrap()
    }

    #[test]
    fn a_run_manifest_is_read_through_its_config_table() {
        let manifest = crate::experiment::train_run::RunManifest {
            experiment: "e".into(),
            method: Method::Our1,
            variant: String::new(),
            seed: 3,
            config: RunSettings::paper(EnvSpec::paper_box_pushing(30), Method::Our1),
            provenance: None,
        };
        let s = EnvSetting::from_config_toml(&toml::to_string(&manifest).unwrap()).unwrap();
        assert_eq!(s.env, EnvSpec::paper_box_pushing(30));
        assert_eq!(s.optimal_return(), Some(BP30_OPTIMAL));
    }

    #[test]
    fn paper_settings_have_the_spec_optimal_returns() {
        assert_eq!(
            setting_of(EnvSpec::paper_box_pushing(10)).optimal_return(),
            Some(80.71093744250365)
        );
        assert_eq!(
            setting_of(EnvSpec::paper_box_pushing(30)).optimal_return(),
            Some(41.75397237445474)
        );
        assert_eq!(
            setting_of(EnvSpec::paper_warehouse()).optimal_return(),
            Some(262.0)
        );
    }

    #[test]
    fn other_grids_horizons_and_discounts_have_no_line() {
        let bp = |grid, horizon| EnvSpec::BoxPushing { grid, horizon };
        let mut s = setting_of(bp(10, 100));
        s.env = bp(12, 100);
        assert_eq!(s.optimal_return(), None);
        s.env = bp(10, 50);
        assert_eq!(s.optimal_return(), None);
        let mut s = setting_of(bp(10, 100));
        s.discount = 0.99;
        assert_eq!(s.optimal_return(), None);
    }

    #[test]
    fn missing_keys_are_named() {
        let err =
            EnvSetting::from_config_toml("env_name = \"BP_MA\"\ngrid_dim = 10\ndiscount = 0.98\n")
                .unwrap_err();
        assert!(err.contains("env_terminate_step"), "{err}");
        let err = EnvSetting::from_config_toml("env_name = \"Pong\"").unwrap_err();
        assert!(err.contains("env_name"), "{err}");
    }

    #[test]
    fn a_warehouse_config_needs_no_grid_dim() {
        let s = EnvSetting::from_config_toml(
            "env_name = \"OSD_S_4\"\nenv_terminate_step = 150\ndiscount = 1.0\n",
        )
        .unwrap();
        assert_eq!(s.optimal_return(), Some(WTD_OPTIMAL));
    }

    #[test]
    fn description_names_domain_grid_and_horizon() {
        assert_eq!(
            setting_of(EnvSpec::paper_box_pushing(30)).describe(),
            "Box Pushing 30x30, horizon 200"
        );
        assert_eq!(
            setting_of(EnvSpec::paper_warehouse()).describe(),
            "Warehouse Tool Delivery, horizon 150"
        );
    }
}
