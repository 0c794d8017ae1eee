//! The actor-critic family as the list of families ([`crate::algos::families`]) sees it: its
//! methods, its config, its learner and its facts.

use crate::algos::actor_critic::config::{self, AcConfig};
use crate::algos::actor_critic::learner::AcLearner;
use crate::algos::actor_critic::method::AcMethod;
use crate::algos::family::{FamilyFacts, FamilyMethod};
use crate::envs::{EnvShape, EnvSpec};

impl FamilyMethod for AcMethod {
    type Config = AcConfig;
    type Learner = AcLearner;
    const FACTS: FamilyFacts = FamilyFacts {
        name: "actor-critic",
        description: "MacroMARL's macro-action actor-critic methods",
        quick_start: include_str!("quick_start.toml"),
        quick_start_name: "quickstart_bp6",
        list_keys: &config::LIST_KEYS,
        evaluated_return: "the discounted return of sampled actions",
    };
    const ALL: &'static [AcMethod] = &[
        AcMethod::MacIac,
        AcMethod::MacCac,
        AcMethod::NaiveMacIacc,
        AcMethod::NaiveMacIasc,
        AcMethod::MacIaicc,
        AcMethod::MacIaisc,
    ];

    fn legend(self) -> &'static str {
        match self {
            AcMethod::MacIac => "Mac-IAC",
            AcMethod::MacCac => "Mac-CAC",
            AcMethod::NaiveMacIacc => "Naive Mac-IACC",
            AcMethod::NaiveMacIasc => "Naive Mac-IASC",
            AcMethod::MacIaicc => "Mac-IAICC",
            AcMethod::MacIaisc => "Mac-IAISC",
        }
    }

    fn defaults(self, env: &EnvSpec) -> AcConfig {
        config::published_defaults(env, self)
    }

    fn check(self, c: &AcConfig, shape: &EnvShape) -> Result<(), (&'static str, String)> {
        config::check(c, self, shape)
    }
}
