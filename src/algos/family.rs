//! What a method family's folder hands to the rest of macdec: its methods (one enum, the
//! [`FamilyMethod`] trait), its typed config ([`FamilyConfig`]) and a few facts for messages and
//! quick starts ([`FamilyFacts`]). The one list of families ([`crate::algos::families`]) builds
//! [`crate::algos::families::Method`], [`crate::algos::families::RunConfig`] and
//! [`crate::algos::families::AnyLoop`] from these, so nothing outside a family's folder matches on
//! one of its methods. (The config trait, [`FamilyConfig`], is the loop's: `algos::learner`.)

use crate::algos::learner::{FamilyConfig, Learner, MethodName};
use crate::envs::{EnvShape, EnvSpec};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt::Debug;
use std::hash::Hash;

/// A family's facts the command line and messages use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FamilyFacts {
    /// The family's name in messages and `config.toml` comments (`value`, `actor-critic`).
    pub name: &'static str,
    /// Who the methods are, in a few words (`the ICRA 2020 Q-learning methods`).
    pub description: &'static str,
    /// The embedded experiment `macdec train --methods <this family's methods>` runs without
    /// `--config`: a short run on a small domain that learns something visible.
    pub quick_start: &'static str,
    /// The quick start's experiment name (its results directory).
    pub quick_start_name: &'static str,
    /// Config keys whose value is a list by nature (one setting, not a sweep axis).
    pub list_keys: &'static [&'static str],
    /// What its `eval_return` measures, in plot captions (`the greedy discounted return`).
    pub evaluated_return: &'static str,
}

/// One family's methods: a small enum (the `--methods` names) and everything the rest of macdec
/// may ask of a method. Where methods of a family differ in training, the family's own code
/// matches on this enum; nothing outside the folder does.
pub trait FamilyMethod:
    MethodName + Eq + Ord + Hash + Debug + Send + Sync + Serialize + DeserializeOwned + 'static
{
    /// The family's resolved keys.
    type Config: FamilyConfig;
    /// The family's learner, which the one training loop drives.
    type Learner: Learner<Method = Self, Config = Self::Config>;
    /// The family's facts.
    const FACTS: FamilyFacts;
    /// Every method of the family, in the order its papers introduce them.
    const ALL: &'static [Self];

    /// The name in the papers' figure legends (`Our-1`, `Mac-IAC`).
    fn legend(self) -> &'static str;
    /// The papers' settings for this method on `env`, before the user's keys.
    ///
    /// Panics if a domain's published settings name a key the family does not have or give it
    /// the wrong type: they are code, checked for every built-in domain by the family's tests.
    fn defaults(self, env: &EnvSpec) -> Self::Config;
    /// Range checks types cannot express, for a domain of this shape (horizon, observation and
    /// macro-action counts): the offending key and why. Every size the run allocates by is
    /// bounded here, with all its factors (a centralized net's joint input and output widths
    /// included), before anything is allocated.
    fn check(self, config: &Self::Config, shape: &EnvShape) -> Result<(), (&'static str, String)>;
}
