//! Choosing a domain by value: [`EnvSpec`] is a domain and its config keys, complete and checked,
//! as configs record it; [`EnvSpec::build`] gives the environment as an [`AnyEnv`].
//!
//! In policy and replay files a spec is one JSON object, the domain's tag and its fields
//! ([`Domain::to_tagged`](super::domain::Domain::to_tagged)): `{"env": "box-pushing", "grid":
//! 10, "horizon": 100}`, `{"env": "warehouse", "horizon": 150, "tb_m_noisy": 0.0}`, or a user's
//! domain's `{"env": "rendezvous", "env_terminate_step": 20}`.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::domain::{key_horizon, KeyError};
use super::registry::DomainEntry;
use super::{registry, AnyEnv, EnvError};

/// A domain and the values of all its config keys (checked by the domain).
#[derive(Clone)]
pub struct EnvSpec {
    domain: &'static dyn DomainEntry,
    keys: toml::Table,
}

/// Why a spec could not be made: no such domain, or a bad key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpecError {
    /// No domain answers to the name.
    #[error(transparent)]
    UnknownDomain(#[from] registry::UnknownDomain),
    /// A domain key is unknown or has a bad value.
    #[error("{domain}: {source}")]
    Key {
        /// The domain's name.
        domain: &'static str,
        /// Which key and why.
        #[source]
        source: KeyError,
    },
}

impl SpecError {
    /// The config key to blame: `env_name` for an unknown domain, else the bad key.
    pub fn key(&self) -> &str {
        match self {
            SpecError::UnknownDomain(_) => "env_name",
            SpecError::Key { source, .. } => &source.key,
        }
    }
}

impl EnvSpec {
    /// The domain named `name` (its `env_name`, an alias or its tag) with the keys `given`
    /// (the rest at the domain's defaults).
    pub fn new(name: &str, given: &toml::Table) -> Result<EnvSpec, SpecError> {
        Self::of(registry::lookup(name)?, given)
    }

    /// `domain` with the keys `given` (the rest at the domain's defaults).
    pub fn of(domain: &'static dyn DomainEntry, given: &toml::Table) -> Result<EnvSpec, SpecError> {
        let key_error = |source| SpecError::Key {
            domain: domain.name(),
            source,
        };
        let keys = domain.keys(given).map_err(key_error)?;
        key_horizon(&keys).map_err(key_error)?;
        // Every key given is kept: a domain refuses what it does not read (`tb_m_noisy` for Box
        // Pushing unless 0, MacroMARL's shared kwargs its env ignores) rather than dropping it.
        // This is the one place every caller (configs, Python, replay files, `import`) makes a
        // spec through, so a domain that forgot is caught here, by name.
        if let Some(dropped) = given.keys().find(|k| !keys.contains_key(*k)) {
            return Err(key_error(KeyError::new(
                dropped,
                "this domain does not read this key; leave it out",
            )));
        }
        Ok(EnvSpec { domain, keys })
    }

    /// `domain` with the keys of `table` that are its own ([`DomainEntry::keys`] of an empty
    /// table lists them); the table may hold anything else too (a config's hyperparameters).
    pub fn from_keys_in(
        domain: &'static dyn DomainEntry,
        table: &toml::Table,
    ) -> Result<EnvSpec, SpecError> {
        let key_error = |source| SpecError::Key {
            domain: domain.name(),
            source,
        };
        let own = domain.keys(&toml::Table::new()).map_err(key_error)?;
        let given: toml::Table = table
            .iter()
            .filter(|(k, _)| own.contains_key(*k))
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect();
        Self::of(domain, &given)
    }

    /// The domain.
    pub fn domain(&self) -> &'static dyn DomainEntry {
        self.domain
    }

    /// Every key of the domain with its value, in the order `config.toml` records them.
    pub fn keys(&self) -> &toml::Table {
        &self.keys
    }

    /// The domain's `env_name` (`BP_MA`, `OSD_S_4`, a user's domain's name).
    pub fn env_name(&self) -> &'static str {
        self.domain.name()
    }

    /// The domain's tag in policy and replay files (`box-pushing`, `warehouse`), the name
    /// messages use.
    pub fn name(&self) -> &'static str {
        self.domain.tag()
    }

    /// The horizon in primitive steps (the `env_terminate_step` key).
    pub fn horizon(&self) -> usize {
        key_horizon(&self.keys).expect("checked when the spec was made")
    }

    /// A short label for tables, benchmarks and file names: `bp10`, `wtd`, ...
    pub fn short_name(&self) -> String {
        self.domain.short_name(&self.keys)
    }

    /// The discount per primitive step the papers train and evaluate this setting under (Box
    /// Pushing 0.98, Warehouse 1.0; `docs/ALGORITHMS.md` §10), the one its known optimum is
    /// stated for ([`super::domain::Domain::paper_discount`]); `None` for a domain no paper
    /// trained on.
    pub fn paper_discount(&self) -> Option<f64> {
        self.domain.paper_discount(&self.keys)
    }

    /// Build the environment, in its reset state. Errors name the bad key.
    pub fn build(&self) -> Result<AnyEnv, EnvError> {
        self.domain
            .build_any(&self.keys)
            .map_err(|e| EnvError::InvalidKey {
                key: e.key,
                reason: e.message,
            })
    }
}

impl PartialEq for EnvSpec {
    fn eq(&self, other: &Self) -> bool {
        self.domain.name() == other.domain.name() && self.keys == other.keys
    }
}

impl std::fmt::Debug for EnvSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "EnvSpec({} {})", self.domain.name(), self.keys)
    }
}

impl Serialize for EnvSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut object = serde_json::Map::new();
        object.insert("env".into(), self.domain.tag().into());
        object.extend(self.domain.to_tagged(&self.keys));
        object.serialize(s)
    }
}

impl<'de> Deserialize<'de> for EnvSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut object = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
        let tag = match object.remove("env") {
            Some(serde_json::Value::String(tag)) => tag,
            Some(other) => return Err(D::Error::custom(format!("`env` is not a name: {other}"))),
            None => return Err(D::Error::missing_field("env")),
        };
        let domain = registry::lookup(&tag).map_err(D::Error::custom)?;
        let keys = domain
            .keys_of_tagged(&object)
            .map_err(|e| D::Error::custom(format!("{tag}: {e}")))?;
        EnvSpec::of(domain, &keys).map_err(D::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::box_pushing::BoxPushing;
    use crate::envs::box_pushing::{paper_spec as paper_bp_spec, spec as bp_spec};
    use crate::envs::warehouse::spec as wtd_spec;
    use crate::envs::{EnvRng, MacroEnv};

    #[test]
    fn box_pushing_spec_parses_from_its_tagged_form() {
        let spec: EnvSpec =
            serde_json::from_str(r#"{"env": "box-pushing", "grid": 30, "horizon": 200}"#).unwrap();
        assert_eq!(spec, bp_spec(30, 200));
        assert_eq!(spec, paper_bp_spec(30));
        let env = spec.build().unwrap();
        assert_eq!(env.horizon(), 200);
        assert_eq!(env.n_joint_actions(), 64);
        assert_eq!(
            serde_json::to_string(&spec).unwrap(),
            r#"{"env":"box-pushing","grid":30,"horizon":200}"#
        );
    }

    #[test]
    fn warehouse_spec_parses_with_paper_noise_by_default() {
        let spec: EnvSpec =
            serde_json::from_str(r#"{"env": "warehouse", "horizon": 150}"#).unwrap();
        assert_eq!(spec, wtd_spec(150, 0.0));
        let env = spec.build().unwrap();
        assert_eq!(env.obs_sizes(), &[13, 13, 4]);
        assert_eq!(env.n_joint_actions(), 54);
        assert_eq!(
            serde_json::to_string(&spec).unwrap(),
            r#"{"env":"warehouse","horizon":150,"tb_m_noisy":0.0}"#
        );
    }

    #[test]
    fn unknown_env_and_missing_grid_are_named() {
        let err = serde_json::from_str::<EnvSpec>(r#"{"env": "boxpushing", "horizon": 1}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("boxpushing") && err.contains("BP_MA"), "{err}");
        let err = serde_json::from_str::<EnvSpec>(r#"{"env": "box-pushing", "horizon": 1}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("grid"), "{err}");
        let err = serde_json::from_str::<EnvSpec>(
            r#"{"env": "box-pushing", "grid": 10, "horizon": 1, "gird": 3}"#,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("gird"), "{err}");
    }

    #[test]
    fn a_horizon_beyond_the_limit_is_refused_for_every_domain() {
        // A policy or replay file is read through this one constructor, so a crafted horizon
        // is refused before anything is sized by it.
        for tagged in [
            r#"{"env": "box-pushing", "grid": 10, "horizon": 1000000000000000}"#,
            r#"{"env": "warehouse", "horizon": 100001}"#,
        ] {
            let err = serde_json::from_str::<EnvSpec>(tagged)
                .unwrap_err()
                .to_string();
            assert!(err.contains("at most 100000"), "{tagged}: {err}");
        }
        let table: toml::Table = toml::from_str("env_terminate_step = 100000").unwrap();
        assert_eq!(EnvSpec::new("BP_MA", &table).unwrap().horizon(), 100_000);
    }

    #[test]
    fn any_env_steps_like_the_wrapped_env() {
        let mut rng = <EnvRng as rand::SeedableRng>::seed_from_u64(0);
        let mut any = bp_spec(10, 100).build().unwrap();
        let mut bp = BoxPushing::new(10, 100).unwrap();
        for _ in 0..7 {
            let a = any.step(&[2, 3], &mut rng).unwrap();
            let b = bp.step(&[2, 3], &mut rng).unwrap();
            assert_eq!(a, b);
        }
        assert_eq!(any.obs(0), bp.obs(0));
        assert_eq!(any.mac_done(), &[true, true]);
    }
}
