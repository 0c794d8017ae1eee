//! Every domain this binary knows, found by name: the built-in ones (the list in
//! [`super::built_in`]) and those a program registers at start ([`register`]; a user's binary
//! does it through [`crate::cli::main_with`]).
//!
//! Registration is process-wide because reading any file that names a domain (a config, a run's
//! `config.toml`, a checkpoint, a policy) must find it, wherever in the program that happens.
//! Domains are only ever added, and a name can never change meaning.

use std::sync::RwLock;

use serde::{Deserialize, Deserializer};

use super::built_in::{built_in_domains, AnyEnv};
use super::custom_env::{CustomEnv, SavedEnv};
use super::domain::{Domain, KeyError};

/// Generate [`BUILT_IN`] from the list of built-in domains ([`built_in_domains`]).
macro_rules! built_in_list {
    ($($variant:ident($env:ty) = $domain:expr $(; $more:expr)*,)+) => {
        /// The built-in domains, in list order.
        pub static BUILT_IN: &[&'static dyn DomainEntry] = &[$(&$domain, $(&$more,)*)+];
    };
}
built_in_domains!(built_in_list);

/// A [`Domain`] with its environment type erased, as the registry and [`super::EnvSpec`] hold
/// it. Every [`Domain`] is one; there is nothing to implement.
pub trait DomainEntry: Send + Sync + 'static {
    /// See [`Domain::name`].
    fn name(&self) -> &'static str;
    /// See [`Domain::aliases`].
    fn aliases(&self) -> &'static [&'static str];
    /// See [`Domain::keys`].
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError>;
    /// Build the environment ([`Domain::build`]) as the pipeline holds it ([`AnyEnv::hold`]).
    fn build_any(&self, keys: &toml::Table) -> Result<AnyEnv, KeyError>;
    /// Rebuild an environment [`AnyEnv::Custom`] saved (bincode of [`Domain::Env`]).
    fn restore(&self, bytes: &[u8]) -> Result<AnyEnv, String>;
    /// See [`Domain::paper_discount`].
    fn paper_discount(&self, keys: &toml::Table) -> Option<f64>;
    /// See [`Domain::short_name`].
    fn short_name(&self, keys: &toml::Table) -> String;
    /// See [`Domain::tag`].
    fn tag(&self) -> &'static str;
    /// See [`Domain::to_tagged`].
    fn to_tagged(&self, keys: &toml::Table) -> serde_json::Map<String, serde_json::Value>;
    /// See [`Domain::keys_of_tagged`].
    fn keys_of_tagged(
        &self,
        fields: &serde_json::Map<String, serde_json::Value>,
    ) -> Result<toml::Table, KeyError>;
}

impl<D: Domain> DomainEntry for D {
    fn name(&self) -> &'static str {
        Domain::name(self)
    }
    fn aliases(&self) -> &'static [&'static str] {
        Domain::aliases(self)
    }
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        Domain::keys(self, given)
    }
    fn build_any(&self, keys: &toml::Table) -> Result<AnyEnv, KeyError> {
        Ok(AnyEnv::hold(Domain::name(self), self.build(keys)?))
    }
    fn restore(&self, bytes: &[u8]) -> Result<AnyEnv, String> {
        let env: D::Env = bincode::deserialize(bytes).map_err(|e| e.to_string())?;
        Ok(AnyEnv::hold(Domain::name(self), env))
    }
    fn paper_discount(&self, keys: &toml::Table) -> Option<f64> {
        Domain::paper_discount(self, keys)
    }
    fn short_name(&self, keys: &toml::Table) -> String {
        Domain::short_name(self, keys)
    }
    fn tag(&self) -> &'static str {
        Domain::tag(self)
    }
    fn to_tagged(&self, keys: &toml::Table) -> serde_json::Map<String, serde_json::Value> {
        Domain::to_tagged(self, keys)
    }
    fn keys_of_tagged(
        &self,
        fields: &serde_json::Map<String, serde_json::Value>,
    ) -> Result<toml::Table, KeyError> {
        Domain::keys_of_tagged(self, fields)
    }
}

/// Domains registered at run time, after the built-in ones.
static REGISTERED: RwLock<Vec<&'static dyn DomainEntry>> = RwLock::new(Vec::new());

/// Why a domain could not be registered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegistryError {
    /// A name, alias or tag another domain already has; holds it.
    #[error(
        "domain name `{0}` is taken by another domain (every name, alias and tag must be unique)"
    )]
    NameTaken(String),
    /// A name that is not 1 to 64 letters, digits, `_` or `-`; holds it.
    #[error("domain name {0:?} must be 1 to 64 letters, digits, `_` or `-`")]
    BadName(String),
}

/// Add `domain` to the process's domains. Registering the same domain again does nothing; a
/// domain whose name, alias or tag another domain already uses is refused.
pub fn register(domain: &'static dyn DomainEntry) -> Result<(), RegistryError> {
    let mut registered = REGISTERED.write().unwrap_or_else(|e| e.into_inner());
    // The same domain again (same name, aliases and tag; addresses cannot tell, as distinct
    // unit-struct domains may share one) is already there.
    let same = |d: &&'static dyn DomainEntry| {
        d.name() == domain.name() && d.aliases() == domain.aliases() && d.tag() == domain.tag()
    };
    if registered.iter().any(same) {
        return Ok(());
    }
    for name in names_of(domain) {
        let ok = !name.is_empty()
            && name.len() <= 64
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !ok {
            return Err(RegistryError::BadName(name.to_string()));
        }
        let clash = name == CUSTOM_TAG
            || BUILT_IN
                .iter()
                .chain(registered.iter())
                .any(|d| names_of(*d).any(|n| n == name));
        if clash {
            return Err(RegistryError::NameTaken(name.to_string()));
        }
    }
    registered.push(domain);
    Ok(())
}

/// The tag older policy files used for any domain not built in (`{"env": "custom", ...}`);
/// no domain may take it.
pub const CUSTOM_TAG: &str = "custom";

/// Every name a domain answers to: its name, aliases and tag.
fn names_of(d: &'static dyn DomainEntry) -> impl Iterator<Item = &'static str> {
    std::iter::once(d.name())
        .chain(d.aliases().iter().copied())
        .chain(std::iter::once(d.tag()))
}

/// The domain answering to `name` (its `env_name`, an alias or its file tag).
pub fn find(name: &str) -> Option<&'static dyn DomainEntry> {
    let registered = REGISTERED.read().unwrap_or_else(|e| e.into_inner());
    BUILT_IN
        .iter()
        .chain(registered.iter())
        .copied()
        .find(|d| names_of(*d).any(|n| n == name))
}

/// A name no known domain answers to, and the names that would have been found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("unknown domain `{name}`: this binary has {known}")]
pub struct UnknownDomain {
    /// The name asked for.
    pub name: String,
    /// Every known domain as `name (tag)` ([`names_and_tags`]).
    pub known: String,
}

/// The domain answering to `name` ([`find`]), or an error naming it and the known ones: what
/// every reader of a file that names a domain reports.
pub fn lookup(name: &str) -> Result<&'static dyn DomainEntry, UnknownDomain> {
    find(name).ok_or_else(|| UnknownDomain {
        name: name.to_string(),
        known: names_and_tags(),
    })
}

/// Every known domain as `name (tag)` (`BP_MA (box-pushing)`), for messages listing choices.
pub fn names_and_tags() -> String {
    let registered = REGISTERED.read().unwrap_or_else(|e| e.into_inner());
    BUILT_IN
        .iter()
        .chain(registered.iter())
        .map(|d| match d.tag() {
            tag if tag == d.name() => tag.to_string(),
            tag => format!("{} ({tag})", d.name()),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Whether `name` is a built-in domain's name, alias or tag.
pub fn is_built_in(name: &str) -> bool {
    BUILT_IN.iter().any(|d| names_of(*d).any(|n| n == name))
}

/// A custom environment in a checkpoint names its domain; reading it back asks that domain to
/// rebuild the environment, so a checkpoint of a domain this binary lacks is refused by name.
impl<'de> Deserialize<'de> for CustomEnv {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let saved = SavedEnv::deserialize(d)?;
        let domain = lookup(&saved.domain)
            .map_err(|e| D::Error::custom(format!("the saved environment's domain: {e}")))?;
        match domain.restore(&saved.env).map_err(D::Error::custom)? {
            AnyEnv::Custom(env) => Ok(env),
            _ => Err(D::Error::custom(format!(
                "domain `{}` is built in; its environment is not saved as a custom one",
                saved.domain
            ))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_domains_are_found_by_name_alias_and_tag() {
        assert_eq!(find("BP_MA").unwrap().name(), "BP_MA");
        assert_eq!(find("box-pushing").unwrap().name(), "BP_MA");
        assert_eq!(find("OSD_S_4").unwrap().name(), "OSD_S_4");
        assert_eq!(find("warehouse").unwrap().name(), "OSD_S_4");
        assert_eq!(find("BP-MA-v0").unwrap().name(), "BP-MA-v0");
        assert!(find("Pong").is_none());
        let all = names_and_tags();
        assert!(
            all.starts_with("BP_MA (box-pushing), BP-MA-v0, OSD_S_4 (warehouse)"),
            "{all}"
        );
    }

    /// Two distinct unit-struct domains (they may share an address) and a name clash.
    struct TestA;
    struct TestB;
    struct TestClash;
    macro_rules! test_domain {
        ($t:ident, $name:expr, $aliases:expr) => {
            impl Domain for $t {
                type Env = crate::envs::box_pushing::BoxPushing;
                fn name(&self) -> &'static str {
                    $name
                }
                fn aliases(&self) -> &'static [&'static str] {
                    $aliases
                }
                fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
                    crate::envs::domain::fill_keys(given, toml::toml! { env_terminate_step = 9 })
                }
                fn build(&self, _: &toml::Table) -> Result<Self::Env, KeyError> {
                    Err(KeyError::new("env_name", "not built in tests"))
                }
            }
        };
    }
    test_domain!(TestA, "registry-test-a", &[]);
    test_domain!(TestB, "registry-test-b", &[]);
    test_domain!(TestClash, "registry-test-c", &["registry-test-a"]);

    #[test]
    fn distinct_domains_register_once_each_and_clashes_are_refused() {
        register(&TestA).unwrap();
        register(&TestA).unwrap();
        register(&TestB).unwrap();
        assert_eq!(find("registry-test-a").unwrap().name(), "registry-test-a");
        assert_eq!(find("registry-test-b").unwrap().name(), "registry-test-b");
        assert_eq!(
            register(&TestClash),
            Err(RegistryError::NameTaken("registry-test-a".into()))
        );
        assert!(find("registry-test-c").is_none());
        assert!(names_and_tags().contains("registry-test-b"));
    }

    #[test]
    fn a_built_in_name_cannot_be_registered_again() {
        let bp = find("BP_MA").unwrap();
        // The same object is accepted (idempotent) ...
        let wtd = *BUILT_IN.iter().find(|d| d.name() == "OSD_S_4").unwrap();
        let err = register(wtd);
        // ... but built-in objects are not in the run-time list, so re-registering one clashes.
        assert_eq!(err, Err(RegistryError::NameTaken("OSD_S_4".into())));
        assert_eq!(bp.name(), "BP_MA");
    }
}
