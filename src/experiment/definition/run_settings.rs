//! A run's domain and hyperparameters together, as its `config.toml` records them: the
//! learner's [`RunConfig`] names no domain, so the run layer keeps the domain ([`EnvSpec`])
//! beside it and writes both as one table: `env_name`, then the domain's own keys in its order
//! (for the built-in domains the reference's `grid_dim`, `env_terminate_step`, `tb_m_noisy`),
//! then every hyperparameter. Every existing run directory keeps reading and writing byte for
//! byte the same.

use crate::algos::families::{Method, RunConfig};
use crate::envs::EnvSpec;
use serde::{Serialize, Serializer};

/// The domain a run trains on and its hyperparameters: `config.toml`'s `[config]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSettings {
    /// The domain and its keys, horizon included (BP 10x10: 100, 30x30: 200; WTD: 150).
    pub env: EnvSpec,
    /// The run's hyperparameters.
    pub config: RunConfig,
}

impl RunSettings {
    /// The papers' settings for `method` on `env` (see [`Method::defaults`]).
    pub fn paper(env: EnvSpec, method: Method) -> Self {
        let config = method.defaults(&env);
        RunSettings { env, config }
    }

    /// The table `config.toml` records: `env_name`, the domain's keys, the hyperparameters.
    pub fn to_table(&self) -> toml::Table {
        let mut table = toml::Table::new();
        table.insert("env_name".into(), self.env.env_name().into());
        table.extend(self.env.keys().clone());
        table.extend(self.config.to_table());
        table
    }

    /// Read the table [`Self::to_table`] writes for a run of `method`. The domain is found by
    /// `env_name` (an alias too); it takes its own keys and checks them, the rest must be
    /// exactly the hyperparameters of the method's family (unknown keys are refused, so a typo
    /// in a hand-edited config fails instead of being ignored).
    pub fn from_table(method: Method, mut table: toml::Table) -> Result<Self, String> {
        let name = match table.remove("env_name") {
            Some(toml::Value::String(name)) => name,
            Some(other) => return Err(format!("`env_name` is not a name: {other}")),
            None => return Err("missing field `env_name`".into()),
        };
        let domain = crate::envs::registry::lookup(&name).map_err(|e| e.to_string())?;
        let env = EnvSpec::from_keys_in(domain, &table).map_err(|e| e.to_string())?;
        for key in env.keys().keys() {
            table.remove(key);
        }
        let config = method.config_from_table(table)?;
        Ok(RunSettings { env, config })
    }
}

impl Serialize for RunSettings {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_table().serialize(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn method(name: &str) -> Method {
        name.parse().unwrap()
    }

    fn paper(env: EnvSpec, name: &str) -> RunSettings {
        RunSettings::paper(env, method(name))
    }

    fn read(name: &str, text: &str) -> Result<RunSettings, String> {
        let table: toml::Table = toml::from_str(text).map_err(|e| e.message().to_string())?;
        RunSettings::from_table(method(name), table)
    }

    #[test]
    fn the_domain_is_written_as_the_four_reference_keys_first() {
        let c = paper(crate::envs::warehouse::paper_spec(), "our2");
        let text = toml::to_string(&c).unwrap();
        assert!(
            text.starts_with(
                "env_name = \"OSD_S_4\"\ngrid_dim = 10\nenv_terminate_step = 150\ntb_m_noisy = 0.0\ntotal_epi = 40000\n"
            ),
            "{text}"
        );
        let back = read("our2", &text).unwrap();
        assert_eq!(back, c);
        // The hyperparameters alone are the same keys without the domain's.
        let alone = toml::to_string(&c.config.to_table()).unwrap();
        assert!(alone.starts_with("total_epi = 40000\n"), "{alone}");
        assert!(text.ends_with(&alone));
    }

    #[test]
    fn unknown_keys_and_values_of_keys_the_domain_does_not_read_are_refused() {
        let c = paper(crate::envs::box_pushing::paper_spec(10), "our1");
        let text = toml::to_string(&c).unwrap();
        let err = read("our1", &format!("{text}trace_lenn = 3\n")).unwrap_err();
        assert!(err.contains("trace_lenn"), "{err}");
        let err = read("our1", &text.replace("BP_MA", "Pong")).unwrap_err();
        assert!(err.contains("Pong") && err.contains("OSD_S_4"), "{err}");
        // The method's family reads the keys: an ICRA config is not an actor-critic one.
        let err = read("mac-iac", &text).unwrap_err();
        assert!(err.contains("unknown field"), "{err}");
        // A Box Pushing config's tb_m_noisy is recorded as 0, which Box Pushing does not read:
        // a hand-edited other value is refused, not dropped.
        let noisy = text.replace("tb_m_noisy = 0.0", "tb_m_noisy = 0.3");
        assert_ne!(noisy, text);
        let err = read("our1", &noisy).unwrap_err();
        assert!(
            err.contains("`tb_m_noisy`") && err.contains("leave it out"),
            "{err}"
        );
        // A hyperparameter table refuses the domain's keys: the learner's config names none.
        let err = method("our1")
            .config_from_table(toml::from_str(&text).unwrap())
            .unwrap_err();
        assert!(err.contains("env_name"), "{err}");
    }
}
