//! What the pipeline knows about a domain besides its dynamics: its name in configs, its config
//! keys and their defaults, how to build it from them, the paper's hyperparameters on it, and
//! how its policy and replay files name it.
//!
//! A domain implements [`Domain`] once, in its own folder (`src/envs/box_pushing/domain.rs`,
//! `src/envs/warehouse/domain.rs`) or in a user's own crate, and every command works on it:
//! configs select it by `env_name`, runs record its keys in `config.toml`, checkpoints hold its
//! environment, plots ask it for its optimum and policies name it. The pipeline holds domains as
//! [`crate::envs::registry::DomainEntry`] trait objects (every [`Domain`] is one), found by name
//! in [`crate::envs::registry`].
//!
//! Keys are TOML values so that one code path reads, checks, records and compares them for every
//! domain; a domain reads them into its own typed parameters with [`key_usize`] and [`key_f64`].

use serde::de::DeserializeOwned;
use serde::Serialize;

use super::MacroEnv;

/// The config key every domain has: the horizon in primitive steps (the references' name).
pub const HORIZON_KEY: &str = "env_terminate_step";

/// Longest horizon any domain may have, in primitive steps (papers: 100 to 200). Every spec is
/// held to it wherever it comes from (a config, a policy or replay file, `import --horizon`), so
/// a crafted file cannot make a reader allocate or loop for ever.
pub const MAX_HORIZON: usize = 100_000;

/// The domain's horizon from its keys: present, an integer, 1..=[`MAX_HORIZON`].
pub fn key_horizon(keys: &toml::Table) -> Result<usize, KeyError> {
    match key_usize(keys, HORIZON_KEY)? {
        0 => Err(KeyError::new(HORIZON_KEY, "must be at least 1")),
        h if h > MAX_HORIZON => Err(KeyError::new(
            HORIZON_KEY,
            format!("must be at most {MAX_HORIZON}, got {h}"),
        )),
        h => Ok(h),
    }
}

/// A bad domain key: which key, and why. Shown as "`key`: message" by config errors.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{key}`: {message}")]
pub struct KeyError {
    /// The key, as written.
    pub key: String,
    /// Why it is refused and what is expected.
    pub message: String,
}

impl KeyError {
    /// A bad value of `key`.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        KeyError {
            key: key.into(),
            message: message.into(),
        }
    }
}

/// A macro-action domain as configs, runs, plots and policy files know it.
///
/// Implement it on a small (usually unit) struct next to your [`MacroEnv`]:
///
/// ```
/// # use macdec::envs::domain::{fill_keys, key_usize, Domain, KeyError};
/// # use macdec::envs::{EnvError, EnvRng, MacroEnv, StepOutcome};
/// # #[derive(Clone, serde::Serialize, serde::Deserialize)]
/// # struct Corridor { len: usize, horizon: usize }
/// # impl MacroEnv for Corridor {
/// #     fn n_agents(&self) -> usize { 1 }
/// #     fn obs_sizes(&self) -> &[usize] { &[1] }
/// #     fn n_actions(&self) -> &[usize] { &[1] }
/// #     fn action_names(&self, _: usize) -> &'static [&'static str] { &["go"] }
/// #     fn obs_names(&self, _: usize) -> Vec<String> { vec!["x".into()] }
/// #     fn horizon(&self) -> usize { self.horizon }
/// #     fn reset(&mut self, _: &mut EnvRng) {}
/// #     fn step(&mut self, _: &[usize], _: &mut EnvRng) -> Result<StepOutcome, EnvError> {
/// #         Ok(StepOutcome::ended(0.0, true))
/// #     }
/// #     fn obs(&self, _: usize) -> &[f32] { &[0.0] }
/// #     fn executed(&self) -> &[usize] { &[0] }
/// #     fn mac_done(&self) -> &[bool] { &[true] }
/// #     fn t(&self) -> usize { 0 }
/// #     fn render_ascii(&self) -> String { String::new() }
/// # }
/// struct CorridorDomain;
///
/// impl Domain for CorridorDomain {
///     type Env = Corridor;
///     fn name(&self) -> &'static str {
///         "corridor"
///     }
///     fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
///         let keys = fill_keys(given, toml::toml! { corridor_len = 9  env_terminate_step = 20 })?;
///         if key_usize(&keys, "corridor_len")? < 2 {
///             return Err(KeyError::new("corridor_len", "must be at least 2"));
///         }
///         Ok(keys)
///     }
///     fn build(&self, keys: &toml::Table) -> Result<Corridor, KeyError> {
///         Ok(Corridor {
///             len: key_usize(keys, "corridor_len")?,
///             horizon: key_usize(keys, "env_terminate_step")?,
///         })
///     }
/// }
/// ```
pub trait Domain: Send + Sync + 'static {
    /// The environment the domain builds. `Clone` and serde are what a run's checkpoint needs.
    type Env: MacroEnv + Clone + Serialize + DeserializeOwned + Send + 'static;

    /// The `env_name` value that selects the domain in configs and that runs record (the
    /// reference's name where there is one: `BP_MA`, `OSD_S_4`).
    fn name(&self) -> &'static str;

    /// Other `env_name` values accepted for it (`box-pushing`); runs record [`Self::name`].
    fn aliases(&self) -> &'static [&'static str] {
        &[]
    }

    /// Every config key of the domain with its value, given the ones the user set (`given`
    /// holds only keys of this domain: those [`Self::keys`] returns for an empty `given`).
    /// The result lists the keys in the order `config.toml` records them, includes
    /// [`HORIZON_KEY`], and holds only valid values: refuse a bad one here, naming its key,
    /// so a config fails before any run starts. A default may depend on other keys (Box
    /// Pushing's horizon follows its grid). [`fill_keys`] does the usual part.
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError>;

    /// Build the environment, in its reset state, from keys [`Self::keys`] returned.
    fn build(&self, keys: &toml::Table) -> Result<Self::Env, KeyError>;

    /// The discount per primitive step the papers that trained on this setting report its
    /// returns under (and state its optimum for): a fact of the benchmark, not of a learner.
    /// Methods take it as their default discount where their family publishes none; `None`
    /// (the default) for a domain no paper trained on. Learners' other published settings live
    /// in their family's folder (`src/algos/<family>/published*`), never in a domain's.
    fn paper_discount(&self, keys: &toml::Table) -> Option<f64> {
        let _ = keys;
        None
    }

    /// A short label for tables, benchmarks and file names (`bp10`, `wtd`); the name by default.
    fn short_name(&self, keys: &toml::Table) -> String {
        let _ = keys;
        self.name().to_lowercase()
    }

    /// The `env` tag that names the domain in policy and replay files; the name by default.
    fn tag(&self) -> &'static str {
        self.name()
    }

    /// The fields written beside the tag in policy and replay files: the keys by default. A
    /// domain whose files predate this trait keeps their older form here and in
    /// [`Self::keys_of_tagged`].
    fn to_tagged(&self, keys: &toml::Table) -> serde_json::Map<String, serde_json::Value> {
        keys.iter()
            .map(|(k, v)| (k.clone(), toml_to_json(v)))
            .collect()
    }

    /// The keys [`Self::to_tagged`] wrote (checked by [`Self::keys`]).
    fn keys_of_tagged(
        &self,
        fields: &serde_json::Map<String, serde_json::Value>,
    ) -> Result<toml::Table, KeyError> {
        let mut given = toml::Table::new();
        for (k, v) in fields {
            let value = json_to_toml(v)
                .ok_or_else(|| KeyError::new(k, format!("{v} is not a key value")))?;
            given.insert(k.clone(), value);
        }
        let known = self.keys(&toml::Table::new())?;
        if let Some(k) = given.keys().find(|k| !known.contains_key(*k)) {
            return Err(KeyError::new(k, format!("{} has no such key", self.name())));
        }
        self.keys(&given)
    }
}

/// [`fill_keys`]'s reason for a key the domain does not have at all.
pub const NOT_A_KEY: &str = "not a key of this domain";

/// The usual [`Domain::keys`]: `defaults` lists every key with its default value, in order;
/// `given` overrides some. A given key must have its default's type (an integer where a float
/// is expected is taken as that float); integers must be >= 0, floats finite. Keys of `given`
/// not in `defaults` are refused.
pub fn fill_keys(given: &toml::Table, defaults: toml::Table) -> Result<toml::Table, KeyError> {
    let mut keys = defaults;
    for (key, value) in given {
        let Some(default) = keys.get(key) else {
            return Err(KeyError::new(key, NOT_A_KEY));
        };
        let value = match (default, value) {
            (toml::Value::Float(_), toml::Value::Integer(i)) => toml::Value::Float(*i as f64),
            _ => value.clone(),
        };
        if std::mem::discriminant(default) != std::mem::discriminant(&value) {
            return Err(KeyError::new(
                key,
                format!("expected {}, got {value}", default.type_str()),
            ));
        }
        match value {
            toml::Value::Integer(i) if i < 0 => {
                return Err(KeyError::new(key, format!("must be >= 0, got {i}")))
            }
            toml::Value::Float(f) if !f.is_finite() => {
                return Err(KeyError::new(key, format!("must be finite, got {f}")))
            }
            _ => {}
        }
        keys.insert(key.clone(), value);
    }
    Ok(keys)
}

/// Records `key` at `value` whatever the domain is given, refusing any other value instead of
/// dropping it: for a key the reference's command line has for every domain that this one does
/// not read (`tb_m_noisy` of Box Pushing, recorded 0; `grid_dim` of a Warehouse, recorded 10).
/// `keys` holds what [`fill_keys`] made of the given keys (an integer given for a float key is
/// its float by then).
pub fn fixed_key(
    keys: &mut toml::Table,
    key: &str,
    value: toml::Value,
    domain: &str,
) -> Result<(), KeyError> {
    match keys.get(key) {
        Some(given) if *given != value => Err(KeyError::new(
            key,
            format!("{domain} does not read this key (its runs record {value}); leave it out, got {given}"),
        )),
        _ => {
            keys.insert(key.into(), value);
            Ok(())
        }
    }
}

/// A key table from `(key, value)` pairs, in order: `key_table([("grid_dim", 10.into())])`.
pub fn key_table<const N: usize>(pairs: [(&str, toml::Value); N]) -> toml::Table {
    pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}

/// The non-negative integer key `key` of `keys`.
pub fn key_usize(keys: &toml::Table, key: &str) -> Result<usize, KeyError> {
    match keys.get(key) {
        Some(toml::Value::Integer(i)) => {
            usize::try_from(*i).map_err(|_| KeyError::new(key, format!("must be >= 0, got {i}")))
        }
        Some(v) => Err(KeyError::new(key, format!("expected an integer, got {v}"))),
        None => Err(KeyError::new(key, "missing")),
    }
}

/// The number key `key` of `keys` (an integer is taken as a float).
pub fn key_f64(keys: &toml::Table, key: &str) -> Result<f64, KeyError> {
    match keys.get(key) {
        Some(toml::Value::Float(f)) => Ok(*f),
        Some(toml::Value::Integer(i)) => Ok(*i as f64),
        Some(v) => Err(KeyError::new(key, format!("expected a number, got {v}"))),
        None => Err(KeyError::new(key, "missing")),
    }
}

/// For a domain's own [`Domain::keys_of_tagged`]: refuse a field of its tagged form not in
/// `known`, naming the field and the known ones.
pub fn refuse_unknown_fields(
    fields: &serde_json::Map<String, serde_json::Value>,
    tag: &str,
    known: &[&str],
) -> Result<(), KeyError> {
    match fields.keys().find(|k| !known.contains(&k.as_str())) {
        Some(k) => Err(KeyError::new(
            k,
            format!("unknown field; {tag} has `{}`", known.join("`, `")),
        )),
        None => Ok(()),
    }
}

/// For a domain's own [`Domain::keys_of_tagged`]: the required non-negative integer field `key`.
pub fn tagged_count(
    fields: &serde_json::Map<String, serde_json::Value>,
    key: &str,
) -> Result<i64, KeyError> {
    match fields.get(key) {
        Some(v) => v
            .as_i64()
            .filter(|n| *n >= 0)
            .ok_or_else(|| KeyError::new(key, format!("expected a non-negative integer, got {v}"))),
        None => Err(KeyError::new(key, format!("missing field `{key}`"))),
    }
}

/// A key value as JSON (policy and replay files).
pub fn toml_to_json(v: &toml::Value) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or(serde_json::Value::Null)
}

/// A JSON value as a key value: numbers, strings, booleans, and arrays and objects of them
/// (MacroMARL's Overcooked takes a `rewardList` table); `None` for `null` anywhere.
pub fn json_to_toml(v: &serde_json::Value) -> Option<toml::Value> {
    use serde_json::Value as J;
    Some(match v {
        J::Bool(b) => toml::Value::Boolean(*b),
        J::Number(n) => match (n.as_i64(), n.as_f64()) {
            (Some(i), _) if !n.is_f64() => toml::Value::Integer(i),
            (_, Some(f)) => toml::Value::Float(f),
            _ => return None,
        },
        J::String(s) => toml::Value::String(s.clone()),
        J::Array(a) => toml::Value::Array(a.iter().map(json_to_toml).collect::<Option<_>>()?),
        J::Object(m) => toml::Value::Table(
            m.iter()
                .map(|(k, v)| Some((k.clone(), json_to_toml(v)?)))
                .collect::<Option<_>>()?,
        ),
        J::Null => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_keys_keeps_order_types_and_names_bad_keys() {
        let defaults = toml::toml! { a = 1  b = 0.5  c = "x" };
        let given = toml::toml! { b = 2 };
        let keys = fill_keys(&given, defaults.clone()).unwrap();
        assert_eq!(keys.keys().collect::<Vec<_>>(), ["a", "b", "c"]);
        assert_eq!(key_f64(&keys, "b").unwrap(), 2.0);
        let err = fill_keys(&toml::toml! { a = "no" }, defaults.clone()).unwrap_err();
        assert_eq!(err.key, "a");
        let err = fill_keys(&toml::toml! { a = -1 }, defaults.clone()).unwrap_err();
        assert!(err.message.contains(">= 0"), "{err}");
        let err = fill_keys(&toml::toml! { z = 1 }, defaults.clone()).unwrap_err();
        assert_eq!(err.key, "z");
        let err = fill_keys(&toml::toml! { b = nan }, defaults).unwrap_err();
        assert_eq!(err.key, "b");
    }

    #[test]
    fn json_and_toml_values_round_trip() {
        for v in [
            toml::Value::Integer(3),
            toml::Value::Float(0.25),
            toml::Value::Float(1.0),
            toml::Value::String("s".into()),
            toml::Value::Boolean(true),
        ] {
            assert_eq!(json_to_toml(&toml_to_json(&v)), Some(v));
        }
        assert_eq!(json_to_toml(&serde_json::json!(null)), None);
    }
}
