//! The method families: **the one list** a new family joins (the macro `method_families`). Each
//! line names the family's variant and its methods' enum (a [`FamilyMethod`] in the family's
//! folder); the list becomes [`Family`], [`Method`] (every family's methods), [`RunConfig`] (every
//! family's config) and [`AnyLoop`] (the training loop of whichever family a run's method
//! belongs to), with their forwarding here.
//!
//! Everything else about a family lives in its folder (`src/algos/<family>/`): its methods and
//! where they differ, its typed config and its checks, its published settings, its quick start,
//! its errors, its learner and its goldens (README "Adding a method family").

use crate::algos::family::{FamilyFacts, FamilyMethod};
use crate::algos::learner::{FamilyConfig, MethodName, SavedNets};
use crate::algos::training_loop::{Advance, EvalPoint, RunRngs, TrainError, TrainingLoop};
use crate::envs::{AnyEnv, EnvError, EnvShape, EnvSpec, MacroEnv};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::str::FromStr;

/// The list of method families, handed to the macro `$then` (which generates what the list
/// decides): `Variant(methods enum),`. Order matters: it is the order of `--methods` listings,
/// and the first family's quick start is `macdec train`'s default.
macro_rules! method_families {
    ($then:ident) => {
        $then! {
            Value(crate::algos::value::method::ValueMethod),
            ActorCritic(crate::algos::actor_critic::method::AcMethod),
            MacValue(crate::algos::mac_value::method::MacValueMethod),
            Acac(crate::algos::acac::method::AcacMethod),
        }
    };
}

/// Generate the family-indexed types and their forwarding from the list.
macro_rules! families {
    ($($family:ident($methods:ty),)+) => {
        /// A method family: the learner type the training loop drives for a method.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Family {
            $(
                #[doc = concat!("The methods of `", stringify!($methods), "`.")]
                $family,
            )+
        }

        impl Family {
            /// Every family, in the list's order.
            pub const ALL: &'static [Family] = &[$(Family::$family),+];

            /// The family's facts (name, quick start, how it evaluates).
            pub fn facts(self) -> FamilyFacts {
                match self {
                    $(Family::$family => <$methods as FamilyMethod>::FACTS,)+
                }
            }

            /// The family's methods, in its papers' order.
            pub fn methods(self) -> Vec<Method> {
                match self {
                    $(Family::$family => <$methods as FamilyMethod>::ALL
                        .iter()
                        .map(|&m| Method::$family(m))
                        .collect(),)+
                }
            }
        }

        /// One learning method, by its command-line name: a method of one family.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum Method {
            $(
                #[doc = concat!("A method of `", stringify!($methods), "`.")]
                $family($methods),
            )+
        }

        $(
            impl From<$methods> for Method {
                fn from(m: $methods) -> Method {
                    Method::$family(m)
                }
            }
        )+

        impl Method {
            /// Every method: each family's in its papers' order, families in the list's order.
            pub fn all() -> Vec<Method> {
                Family::ALL.iter().flat_map(|f| f.methods()).collect()
            }

            /// The family whose learner trains this method.
            pub fn family(self) -> Family {
                match self {
                    $(Method::$family(_) => Family::$family,)+
                }
            }

            /// The command-line and directory name.
            pub fn name(self) -> &'static str {
                match self {
                    $(Method::$family(m) => m.name(),)+
                }
            }

            /// The name in the papers' figure legends.
            pub fn legend(self) -> &'static str {
                match self {
                    $(Method::$family(m) => m.legend(),)+
                }
            }

            /// The papers' settings for this method on `env`, before the user's keys (see
            /// [`FamilyMethod::defaults`]).
            pub fn defaults(self, env: &EnvSpec) -> RunConfig {
                match self {
                    $(Method::$family(m) => RunConfig::$family(m.defaults(env)),)+
                }
            }

            /// The family's range checks of `config` (see [`FamilyMethod::check`]); a config of
            /// another family is refused.
            pub fn check(
                self,
                config: &RunConfig,
                shape: &EnvShape,
            ) -> Result<(), (&'static str, String)> {
                #[allow(unreachable_patterns)]
                match (self, config) {
                    $((Method::$family(m), RunConfig::$family(c)) => m.check(c, shape),)+
                    _ => Err((
                        "config",
                        format!(
                            "{self} needs the keys of the {} family; this config holds the {} family's",
                            self.family().facts().name,
                            config.family().facts().name
                        ),
                    )),
                }
            }

            /// Read this method's config from a flat table of keys (`config.toml` less the
            /// domain's keys); unknown keys are refused, naming them.
            pub fn config_from_table(self, table: toml::Table) -> Result<RunConfig, String> {
                let value = toml::Value::Table(table);
                match self {
                    $(Method::$family(_) => {
                        <<$methods as FamilyMethod>::Config>::deserialize(value)
                            .map(RunConfig::$family)
                    })+
                }
                .map_err(|e| e.message().to_string())
            }
        }

        /// The resolved hyperparameters of one run, by method family: every one concrete and
        /// validated. On disk (`config.toml`) it is the family's flat table of keys.
        #[derive(Debug, Clone, PartialEq)]
        pub enum RunConfig {
            $(
                #[doc = concat!("The config of `", stringify!($methods), "`.")]
                $family(<$methods as FamilyMethod>::Config),
            )+
        }

        $(
            impl From<<$methods as FamilyMethod>::Config> for RunConfig {
                fn from(c: <$methods as FamilyMethod>::Config) -> RunConfig {
                    RunConfig::$family(c)
                }
            }

            impl InList for $methods {
                fn config_of(c: &RunConfig) -> Option<&Self::Config> {
                    #[allow(unreachable_patterns)]
                    match c {
                        RunConfig::$family(c) => Some(c),
                        _ => None,
                    }
                }
                fn config_of_mut(c: &mut RunConfig) -> Option<&mut Self::Config> {
                    #[allow(unreachable_patterns)]
                    match c {
                        RunConfig::$family(c) => Some(c),
                        _ => None,
                    }
                }
                fn of(m: Method) -> Option<Self> {
                    #[allow(unreachable_patterns)]
                    match m {
                        Method::$family(m) => Some(m),
                        _ => None,
                    }
                }
            }
        )+

        /// Forward a call to the family's config.
        macro_rules! config_dispatch {
            ($self:expr, $c:ident => $call:expr) => {
                match $self {
                    $(RunConfig::$family($c) => $call,)+
                }
            };
        }

        impl RunConfig {
            /// The family this config is of.
            pub fn family(&self) -> Family {
                match self {
                    $(RunConfig::$family(_) => Family::$family,)+
                }
            }
        }

        /// The training loop of one run, by family: the run on disk, its checkpoint and the
        /// library API hold an [`AnyLoop`] and never name a learner type.
        #[derive(Debug, Clone, Serialize, Deserialize)]
        #[serde(bound(serialize = "E: Serialize"))]
        #[serde(bound(deserialize = "E: serde::de::DeserializeOwned"))]
        pub enum AnyLoop<E = AnyEnv> {
            $(
                #[doc = concat!("A run of a method of `", stringify!($methods), "`.")]
                $family(Box<TrainingLoop<<$methods as FamilyMethod>::Learner, E>>),
            )+
        }

        /// Forward a call to the family's loop.
        macro_rules! loop_dispatch {
            ($self:expr, $l:ident => $call:expr) => {
                match $self {
                    $(AnyLoop::$family($l) => $call,)+
                }
            };
        }

        impl<E: MacroEnv> AnyLoop<E> {
            /// Build the loop of `method`'s family (see [`TrainingLoop::new`]); a config of
            /// another family is refused.
            pub fn new(
                config: &RunConfig,
                method: Method,
                seed: u64,
                rngs: RunRngs,
                make_env: impl Fn() -> Result<E, EnvError>,
            ) -> Result<Self, TrainError> {
                #[allow(unreachable_patterns)]
                match (method, config) {
                    $((Method::$family(m), RunConfig::$family(c)) => Ok(AnyLoop::$family(
                        Box::new(TrainingLoop::new(c, m, seed, rngs, make_env)?),
                    )),)+
                    _ => Err(TrainError::WrongFamily { method: method.name() }),
                }
            }

            /// The run's configuration.
            pub fn config(&self) -> RunConfig {
                loop_dispatch!(self, l => l.config().clone().into())
            }

            /// The method being trained.
            pub fn method(&self) -> Method {
                loop_dispatch!(self, l => l.method().into())
            }
        }
    };
}

method_families!(families);

/// How the list reaches one family's parts of [`Method`] and [`RunConfig`] (implemented for every
/// listed family by the list).
pub trait InList: FamilyMethod {
    /// This family's config, if `c` is one.
    fn config_of(c: &RunConfig) -> Option<&Self::Config>;
    /// The same, mutable.
    fn config_of_mut(c: &mut RunConfig) -> Option<&mut Self::Config>;
    /// This family's method, if `m` is one.
    fn of(m: Method) -> Option<Self>;
}

impl RunConfig {
    /// Family `M`'s keys, if this is its config.
    pub fn of<M: InList>(&self) -> Option<&M::Config> {
        M::config_of(self)
    }

    /// The same, mutable (e.g. to shorten a run built from the paper's defaults in code).
    pub fn of_mut<M: InList>(&mut self) -> Option<&mut M::Config> {
        M::config_of_mut(self)
    }

    /// Training episodes.
    pub fn total_epi(&self) -> usize {
        config_dispatch!(self, c => c.total_epi())
    }

    /// Set the number of training episodes (e.g. a shortened run in a benchmark).
    pub fn set_total_epi(&mut self, episodes: usize) {
        config_dispatch!(self, c => c.set_total_epi(episodes))
    }

    /// Training episodes between checkpoints.
    pub fn checkpoint_freq(&self) -> usize {
        config_dispatch!(self, c => c.checkpoint_freq())
    }

    /// The discount of evaluation returns and exported policies (per primitive step).
    pub fn discount(&self) -> f64 {
        config_dispatch!(self, c => c.discount())
    }

    /// The flat table of keys `config.toml` records.
    pub fn to_table(&self) -> toml::Table {
        config_dispatch!(self, c => toml::Table::try_from(c))
            .expect("a config serializes to a table")
    }
}

impl<E: MacroEnv> AnyLoop<E> {
    /// Run until a training episode finishes or training is complete.
    pub fn advance(&mut self) -> Result<Advance, TrainError> {
        loop_dispatch!(self, l => l.advance())
    }
    /// The run's seed.
    pub fn seed(&self) -> u64 {
        loop_dispatch!(self, l => l.seed())
    }
    /// Completed training episodes.
    pub fn episodes(&self) -> u64 {
        loop_dispatch!(self, l => l.episodes())
    }
    /// Primitive steps taken by the training env(s).
    pub fn env_steps(&self) -> u64 {
        loop_dispatch!(self, l => l.env_steps())
    }
    /// Training iterations run.
    pub fn updates(&self) -> u64 {
        loop_dispatch!(self, l => l.updates())
    }
    /// Every evaluation so far, in order.
    pub fn evals(&self) -> &[EvalPoint] {
        loop_dispatch!(self, l => l.evals())
    }
    /// The family's own metrics columns.
    pub fn metric_columns(&self) -> &'static [&'static str] {
        loop_dispatch!(self, l => l.metric_columns())
    }
    /// A few words of training state for progress lines.
    pub fn progress(&self) -> String {
        loop_dispatch!(self, l => l.progress())
    }
    /// The nets the run saves as policy files.
    pub fn saved_nets(&self) -> SavedNets<'_> {
        loop_dispatch!(self, l => l.saved_nets())
    }
    /// Wall-clock seconds this run has trained, over all segments (the `wall_seconds` column).
    pub fn wall_seconds(&self) -> f64 {
        loop_dispatch!(self, l => l.wall_seconds())
    }
    /// Fold the running segment's time into the saved total (call before checkpointing).
    pub fn mark_time(&mut self) {
        loop_dispatch!(self, l => l.mark_time())
    }
    /// Whether training is complete.
    pub fn is_finished(&self) -> bool {
        loop_dispatch!(self, l => l.is_finished())
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The name given is not one of the methods.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown method `{0}`: expected one of {}", method_names())]
pub struct UnknownMethod(pub String);

/// Every method's name, comma-separated, for messages.
pub fn method_names() -> String {
    Method::all()
        .iter()
        .map(|m| m.name())
        .collect::<Vec<_>>()
        .join(", ")
}

impl FromStr for Method {
    type Err = UnknownMethod;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::all()
            .into_iter()
            .find(|m| m.name() == s.trim())
            .ok_or_else(|| UnknownMethod(s.to_string()))
    }
}

/// A method is written as its name in every file (`config.toml`, policy manifests,
/// checkpoint headers).
impl Serialize for Method {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Method {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_through_from_str_and_serde() {
        let all = Method::all();
        assert_eq!(all.len(), 18);
        for m in all {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.name()));
            assert_eq!(serde_json::from_str::<Method>(&json).unwrap(), m);
        }
        let err = "our3".parse::<Method>().unwrap_err().to_string();
        assert!(err.contains("our3") && err.contains("mac-iaisc"), "{err}");
    }

    #[test]
    fn every_family_lists_its_methods_once_and_names_are_unique() {
        let mut names: Vec<&str> = Method::all().iter().map(|m| m.name()).collect();
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n);
        for &family in Family::ALL {
            let methods = family.methods();
            assert!(!methods.is_empty(), "{family:?}");
            assert!(methods.iter().all(|m| m.family() == family));
        }
    }

    #[test]
    fn a_config_of_another_family_is_refused_naming_both_families() {
        let env = crate::envs::box_pushing::paper_spec(10);
        let our1: Method = "our1".parse().unwrap();
        let mac_iac: Method = "mac-iac".parse().unwrap();
        let c = our1.defaults(&env);
        let shape = crate::envs::EnvShape::of(&env).unwrap();
        assert!(our1.check(&c, &shape).is_ok());
        let (key, why) = mac_iac.check(&c, &shape).unwrap_err();
        assert_eq!(key, "config");
        assert!(
            why.contains("actor-critic") && why.contains("value"),
            "{why}"
        );
        let err = AnyLoop::new(
            &c,
            mac_iac,
            0,
            crate::experiment::run::train_run::run_rngs(0),
            || env.build(),
        )
        .unwrap_err();
        assert!(matches!(err, TrainError::WrongFamily { .. }), "{err}");
    }

    #[test]
    fn a_config_table_is_read_by_the_methods_family_not_by_its_keys() {
        let env = crate::envs::box_pushing::paper_spec(10);
        for m in Method::all() {
            let c = m.defaults(&env);
            assert_eq!(c.family(), m.family());
            assert_eq!(m.config_from_table(c.to_table()).unwrap(), c);
        }
        let our1: Method = "our1".parse().unwrap();
        let mac_iac: Method = "mac-iac".parse().unwrap();
        let err = our1
            .config_from_table(mac_iac.defaults(&env).to_table())
            .unwrap_err();
        assert!(err.contains("unknown field"), "{err}");
    }
}
