//! Which domain a policy is for: one this binary knows (built in or registered, an [`EnvSpec`]
//! written as its tag and keys, exactly as replay files write it), or one it does not (a
//! library user's, `{"env": "custom", "name": "rendezvous", "horizon": 20}`, or a registered
//! domain of another binary, read as such).
//!
//! A robot needs only its net and the layout in the policy file, so it serves either. Commands
//! that simulate the domain (`eval`, `deploy`, `domain`, `render`) can build only a known one and
//! refuse the other with [`NotInBinary`], naming it.

use crate::envs::{AnyEnv, EnvError, EnvSpec, MacroEnv};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The `env` tag of a custom domain.
pub const CUSTOM: &str = "custom";
/// Longest custom domain name (it is shown in messages and `info` replies).
pub const MAX_NAME_CHARS: usize = 64;

/// The domain of an exported policy.
#[derive(Debug, Clone, PartialEq)]
pub enum PolicyEnv {
    /// A domain this binary has: serialized as the bare [`EnvSpec`] (Box Pushing and Warehouse
    /// byte for byte as before custom domains existed, so every existing policy reads unchanged).
    Known(EnvSpec),
    /// A domain this binary does not have: its name and horizon.
    Custom(CustomEnv),
}

/// A custom domain as its policy records it: a name for people and its horizon. Its layout
/// (observation sizes and names, macro-action names) is in the manifest's agent entries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CustomEnv {
    /// The domain's name, e.g. `rendezvous`.
    pub name: String,
    /// Its horizon in primitive steps.
    pub horizon: usize,
}

/// A command that must simulate the domain was given a policy of a domain this binary lacks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("the policy's domain `{name}` is not in this binary (it has {}): `macdec robot` serves its agents, but running its episodes needs its simulator: use a binary that registers the domain (`macdec::cli::main_with`, see examples/custom_domain.rs), or drive the robots from your own program (macdec::deploy::run_episodes with your MacroEnv and JsonLink::connect)", crate::envs::registry::names_and_tags())]
pub struct NotInBinary {
    /// The domain's name, as the policy records it.
    pub name: String,
}

impl PolicyEnv {
    /// A custom domain named `name` with `env`'s horizon.
    pub fn custom(name: impl Into<String>, env: &impl MacroEnv) -> PolicyEnv {
        PolicyEnv::Custom(CustomEnv {
            name: name.into(),
            horizon: env.horizon(),
        })
    }

    /// The domain's name: its `env` tag (`box-pushing`, `warehouse`, `rendezvous`) or the custom
    /// name.
    pub fn name(&self) -> &str {
        match self {
            PolicyEnv::Known(spec) => spec.name(),
            PolicyEnv::Custom(c) => &c.name,
        }
    }

    /// The horizon in primitive steps.
    pub fn horizon(&self) -> usize {
        match self {
            PolicyEnv::Known(spec) => spec.horizon(),
            PolicyEnv::Custom(c) => c.horizon,
        }
    }

    /// The known domain's spec, or [`NotInBinary`] naming the other.
    pub fn known(&self) -> Result<EnvSpec, NotInBinary> {
        match self {
            PolicyEnv::Known(spec) => Ok(spec.clone()),
            PolicyEnv::Custom(c) => Err(NotInBinary {
                name: c.name.clone(),
            }),
        }
    }

    /// Build the domain to simulate it: only a known one can be.
    pub fn build(&self) -> Result<AnyEnv, BuildError> {
        Ok(self.known()?.build()?)
    }
}

/// Why [`PolicyEnv::build`] failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// The domain is not registered in this binary.
    #[error(transparent)]
    NotInBinary(#[from] NotInBinary),
    /// The domain refused the policy's config.
    #[error(transparent)]
    Env(#[from] EnvError),
}

impl CustomEnv {
    /// The name is 1 to [`MAX_NAME_CHARS`] printable characters and not a built-in domain's (a
    /// policy saying `box-pushing` must be Box Pushing's); the horizon is in 1..=[`MAX_HORIZON`](crate::envs::domain::MAX_HORIZON).
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        let n = self.name.chars().count();
        if n == 0 || n > MAX_NAME_CHARS || self.name.chars().any(char::is_control) {
            return Err((
                "env.name",
                format!(
                    "must be 1 to {MAX_NAME_CHARS} printable characters, got {:?}",
                    self.name
                ),
            ));
        }
        if self.name == CUSTOM || crate::envs::registry::is_built_in(&self.name) {
            return Err((
                "env.name",
                format!(
                    "`{}` is a built-in domain's name or the custom tag; name your domain differently",
                    self.name
                ),
            ));
        }
        if self.horizon == 0 || self.horizon > crate::envs::domain::MAX_HORIZON {
            return Err((
                "env.horizon",
                format!(
                    "must be in 1..={}, got {}",
                    crate::envs::domain::MAX_HORIZON,
                    self.horizon
                ),
            ));
        }
        Ok(())
    }
}

impl PartialEq<EnvSpec> for PolicyEnv {
    fn eq(&self, other: &EnvSpec) -> bool {
        matches!(self, PolicyEnv::Known(spec) if spec == other)
    }
}

impl From<EnvSpec> for PolicyEnv {
    fn from(spec: EnvSpec) -> Self {
        PolicyEnv::Known(spec)
    }
}

/// The custom form on the wire: the tag, then the fields.
#[derive(Serialize)]
struct CustomWire<'a> {
    env: &'static str,
    name: &'a str,
    horizon: usize,
}

impl Serialize for PolicyEnv {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            PolicyEnv::Known(spec) => spec.serialize(s),
            PolicyEnv::Custom(c) => CustomWire {
                env: CUSTOM,
                name: &c.name,
                horizon: c.horizon,
            }
            .serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for PolicyEnv {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let mut value = serde_json::Value::deserialize(d)?;
        let is_custom = value.get("env").and_then(|t| t.as_str()) == Some(CUSTOM);
        if is_custom {
            if let Some(object) = value.as_object_mut() {
                object.remove("env");
            }
            return serde_json::from_value(value)
                .map(PolicyEnv::Custom)
                .map_err(|e| D::Error::custom(format!("custom env: {e}")));
        }
        // A domain this binary does not have (a user's own, served by `macdec robot`): keep its
        // name and horizon, as for the older custom form.
        if let Some(tag) = value.get("env").and_then(|t| t.as_str()) {
            if crate::envs::registry::find(tag).is_none() {
                let horizon = value
                    .get(crate::envs::domain::HORIZON_KEY)
                    .and_then(|h| h.as_u64())
                    .and_then(|h| usize::try_from(h).ok());
                if let Some(horizon) = horizon {
                    let env = CustomEnv {
                        name: tag.to_string(),
                        horizon,
                    };
                    env.validate()
                        .map_err(|(k, m)| D::Error::custom(format!("{k}: {m}")))?;
                    return Ok(PolicyEnv::Custom(env));
                }
            }
        }
        serde_json::from_value(value)
            .map(PolicyEnv::Known)
            .map_err(|e| {
                let hint = if e.to_string().contains("unknown domain") {
                    format!(" (or `{CUSTOM}` for a domain defined outside this binary)")
                } else {
                    String::new()
                };
                D::Error::custom(format!("{e}{hint}"))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_built_in_domain_serializes_exactly_as_its_spec() {
        for spec in [
            crate::envs::box_pushing::paper_spec(10),
            crate::envs::warehouse::spec(150, 0.25),
        ] {
            let env = PolicyEnv::Known(spec.clone());
            assert_eq!(
                serde_json::to_string_pretty(&env).unwrap(),
                serde_json::to_string_pretty(&spec).unwrap()
            );
            let text = serde_json::to_string(&spec).unwrap();
            assert_eq!(serde_json::from_str::<PolicyEnv>(&text).unwrap(), spec);
        }
        let old: PolicyEnv =
            serde_json::from_str(r#"{"env": "warehouse", "horizon": 150}"#).unwrap();
        assert_eq!(old, crate::envs::warehouse::paper_spec());
    }

    #[test]
    fn a_custom_domain_round_trips_with_its_tag() {
        let env = PolicyEnv::Custom(CustomEnv {
            name: "rendezvous".into(),
            horizon: 20,
        });
        let text = serde_json::to_string(&env).unwrap();
        assert_eq!(text, r#"{"env":"custom","name":"rendezvous","horizon":20}"#);
        assert_eq!(serde_json::from_str::<PolicyEnv>(&text).unwrap(), env);
        assert_eq!((env.name(), env.horizon()), ("rendezvous", 20));
    }

    #[test]
    fn bad_domains_are_named() {
        let err = serde_json::from_str::<PolicyEnv>(r#"{"env": "boxpushing", "horizon": 1}"#)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("boxpushing") && err.contains("box-pushing") && err.contains("custom"),
            "{err}"
        );
        let err = serde_json::from_str::<PolicyEnv>(
            r#"{"env": "custom", "name": "x", "horizon": 3, "grid": 4}"#,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("grid"), "{err}");
        let err = serde_json::from_str::<PolicyEnv>(r#"{"env": "custom", "horizon": 3}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("name"), "{err}");
    }

    #[test]
    fn a_custom_domain_cannot_be_built_and_says_so_by_name() {
        let env = PolicyEnv::Custom(CustomEnv {
            name: "rendezvous".into(),
            horizon: 20,
        });
        let err = env.build().unwrap_err().to_string();
        assert!(
            err.contains("`rendezvous`")
                && err.contains("not in this binary")
                && err.contains("main_with"),
            "{err}"
        );
        assert!(PolicyEnv::Known(crate::envs::warehouse::paper_spec())
            .build()
            .is_ok());
    }

    #[test]
    fn custom_names_and_horizons_are_checked() {
        let c = |name: &str, horizon| CustomEnv {
            name: name.into(),
            horizon,
        };
        assert!(c("rendezvous", 20).validate().is_ok());
        for (bad, key) in [
            (c("", 20), "env.name"),
            (c("a\nb", 20), "env.name"),
            (c(&"x".repeat(65), 20), "env.name"),
            (c("warehouse", 20), "env.name"),
            (c("rendezvous", 0), "env.horizon"),
            (c("rendezvous", 100_001), "env.horizon"),
        ] {
            assert_eq!(bad.validate().unwrap_err().0, key, "{bad:?}");
        }
    }
}
