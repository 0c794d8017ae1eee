//! What a figure needs to know about the domain of its runs: a readable description for the title
//! and the optimal return for the red dash-dot line (`docs/ALGORITHMS.md` §7.2).
//!
//! Read from each run's `config.toml` key by key rather than as a whole run config, so an older
//! results tree still plots after the config gains a field, and a run of a domain this binary
//! does not have (a user's own, plotted by `macdec`) still plots, without an optimum.

use crate::envs::{registry, EnvSpec, MacroEnv};

pub use crate::envs::box_pushing::{BP10_OPTIMAL, BP30_OPTIMAL};
pub use crate::envs::warehouse::WTD_OPTIMAL;

/// The domain settings of one run that decide the optimal return.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvSetting {
    /// The run's domain, or `None` for a domain this binary does not have (`env_name` kept).
    pub env: Result<EnvSpec, String>,
    /// Evaluation discount (`discount`, or `gamma` for an actor-critic run).
    pub discount: f64,
}

impl EnvSetting {
    /// Read the setting from a run's `config.toml` text; `Err` says which key is missing or bad.
    /// Only `env_name` and `discount` (`gamma`) are required; the domain's keys are read when present and
    /// take the domain's defaults otherwise (`grid_dim` the reference's 10).
    pub fn from_config_toml(text: &str) -> Result<Self, String> {
        let mut table: toml::Table = toml::from_str(text).map_err(|e| e.message().to_string())?;
        // A run directory's config.toml holds the run's identity and its resolved config under
        // `[config]` (experiment::run::train_run::RunManifest); a bare config is accepted too.
        if let Some(toml::Value::Table(inner)) = table.remove("config") {
            table = inner;
        }
        let name = match table.get("env_name") {
            Some(toml::Value::String(name)) => name.clone(),
            Some(v) => return Err(format!("`env_name` is not a name: {v}")),
            None => return Err("no `env_name`".into()),
        };
        // The value methods' `discount`, the actor-critic methods' `gamma`.
        let key = if table.contains_key("gamma") {
            "gamma"
        } else {
            "discount"
        };
        let discount = match table.get(key) {
            Some(toml::Value::Float(d)) => *d,
            Some(toml::Value::Integer(d)) => *d as f64,
            Some(v) => return Err(format!("`{key}` is not a number: {v}")),
            None => return Err("no `discount` (nor `gamma`)".into()),
        };
        let env = match registry::find(&name) {
            None => Err(name),
            Some(domain) => Ok(EnvSpec::from_keys_in(domain, &table).map_err(|e| e.to_string())?),
        };
        Ok(EnvSetting { env, discount })
    }

    /// The optimal return of this setting when the domain knows one ([`MacroEnv::optimal_return`]:
    /// BP 10x10 horizon 100 and BP 30x30 horizon 200 at gamma 0.98, WTD horizon 150 at gamma 1).
    /// `None` otherwise (another grid, horizon or discount has no verified optimum, and a
    /// domain this binary does not have is not known, so no line is drawn).
    pub fn optimal_return(&self) -> Option<f64> {
        self.env
            .as_ref()
            .ok()?
            .build()
            .ok()?
            .optimal_return(self.discount)
    }

    /// A short description for the figure title, e.g. "Box Pushing 10x10, horizon 100"
    /// ([`MacroEnv::describe`]).
    pub fn describe(&self) -> String {
        match &self.env {
            Ok(spec) => match spec.build() {
                Ok(env) => env.describe(),
                Err(_) => format!("{}, horizon {}", spec.name(), spec.horizon()),
            },
            Err(name) => name.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::actor_critic::method::AcMethod;
    use crate::algos::families::Method;
    use crate::algos::value::method::ValueMethod;
    use crate::experiment::definition::run_settings::RunSettings;

    fn setting_of(env: EnvSpec) -> EnvSetting {
        let text =
            toml::to_string(&RunSettings::paper(env, Method::Value(ValueMethod::Our1))).unwrap();
        EnvSetting::from_config_toml(&text).unwrap()
    }

    #[test]
    fn a_run_manifest_is_read_through_its_config_table() {
        let manifest = crate::experiment::run::train_run::RunManifest {
            experiment: "e".into(),
            method: Method::Value(ValueMethod::Our1),
            variant: String::new(),
            seed: 3,
            config: RunSettings::paper(
                crate::envs::box_pushing::paper_spec(30),
                Method::Value(ValueMethod::Our1),
            ),
            provenance: None,
        };
        let s = EnvSetting::from_config_toml(&toml::to_string(&manifest).unwrap()).unwrap();
        assert_eq!(s.env, Ok(crate::envs::box_pushing::paper_spec(30)));
        assert_eq!(s.optimal_return(), Some(BP30_OPTIMAL));
    }

    #[test]
    fn paper_settings_have_the_spec_optimal_returns() {
        assert_eq!(
            setting_of(crate::envs::box_pushing::paper_spec(10)).optimal_return(),
            Some(80.71093744250365)
        );
        assert_eq!(
            setting_of(crate::envs::box_pushing::paper_spec(30)).optimal_return(),
            Some(41.75397237445474)
        );
        assert_eq!(
            setting_of(crate::envs::warehouse::paper_spec()).optimal_return(),
            Some(262.0)
        );
    }

    #[test]
    fn an_actor_critic_run_reads_its_gamma() {
        let spec = crate::envs::bp_ma_v0::spec(6, 100);
        let text = toml::to_string(&RunSettings::paper(
            spec,
            Method::ActorCritic(AcMethod::MacIaisc),
        ))
        .unwrap();
        let s = EnvSetting::from_config_toml(&text).unwrap();
        assert_eq!(s.discount, 0.98);
        let optimum = s
            .optimal_return()
            .expect("BP-MA-v0 6x6 has an optimum at gamma 0.98");
        assert!((optimum - 270.61).abs() < 0.01, "{optimum}");
    }

    #[test]
    fn other_grids_horizons_and_discounts_have_no_line() {
        let bp = |grid, horizon| crate::envs::box_pushing::spec(grid, horizon);
        let mut s = setting_of(bp(10, 100));
        s.env = Ok(bp(12, 100));
        assert_eq!(s.optimal_return(), None);
        s.env = Ok(bp(10, 50));
        assert_eq!(s.optimal_return(), None);
        let mut s = setting_of(bp(10, 100));
        s.discount = 0.99;
        assert_eq!(s.optimal_return(), None);
    }

    #[test]
    fn missing_keys_are_named_and_missing_domain_keys_take_their_defaults() {
        let err = EnvSetting::from_config_toml("grid_dim = 10\ndiscount = 0.98\n").unwrap_err();
        assert!(err.contains("env_name"), "{err}");
        let err = EnvSetting::from_config_toml("env_name = \"BP_MA\"").unwrap_err();
        assert!(err.contains("discount"), "{err}");
        let s =
            EnvSetting::from_config_toml("env_name = \"BP_MA\"\ngrid_dim = 10\ndiscount = 0.98\n")
                .unwrap();
        assert_eq!(s.optimal_return(), Some(BP10_OPTIMAL));
        let err =
            EnvSetting::from_config_toml("env_name = \"BP_MA\"\ngrid_dim = 7\ndiscount = 0.98\n")
                .unwrap_err();
        assert!(err.contains("grid_dim"), "{err}");
    }

    #[test]
    fn a_domain_this_binary_lacks_plots_without_an_optimum() {
        let s =
            EnvSetting::from_config_toml("env_name = \"rendezvous\"\ndiscount = 0.95\n").unwrap();
        assert_eq!(s.optimal_return(), None);
        assert_eq!(s.describe(), "rendezvous");
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
            setting_of(crate::envs::box_pushing::paper_spec(30)).describe(),
            "Box Pushing 30x30, horizon 200"
        );
        assert_eq!(
            setting_of(crate::envs::warehouse::paper_spec()).describe(),
            "Warehouse Tool Delivery, horizon 150"
        );
    }
}
