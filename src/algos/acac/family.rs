//! ACAC's family as the list of families ([`crate::algos::families`]) sees it.

use crate::algos::acac::config::{self, AcacConfig};
use crate::algos::acac::learner::AcacLearner;
use crate::algos::acac::method::AcacMethod;
use crate::algos::family::{FamilyFacts, FamilyMethod};
use crate::envs::{EnvShape, EnvSpec};

impl FamilyMethod for AcacMethod {
    type Config = AcacConfig;
    type Learner = AcacLearner;
    const FACTS: FamilyFacts = FamilyFacts {
        name: "acac",
        description: "ACAC's agent-centric actor-critic methods (ICML 2025)",
        quick_start: include_str!("quick_start.toml"),
        quick_start_name: "quickstart_acac_bp6",
        list_keys: &config::LIST_KEYS,
        evaluated_return: "the sampled policy's undiscounted return (mean over agents' rewards)",
    };
    const ALL: &'static [AcacMethod] = &[
        AcacMethod::Acac,
        AcacMethod::AcacVanilla,
        AcacMethod::AcacMicroGae,
    ];

    fn legend(self) -> &'static str {
        match self {
            AcacMethod::Acac => "ACAC",
            AcacMethod::AcacVanilla => "ACAC-Vanilla",
            AcacMethod::AcacMicroGae => "ACAC-Micro-GAE",
        }
    }

    fn defaults(self, env: &EnvSpec) -> AcacConfig {
        config::published_defaults(env, self)
    }

    fn check(self, c: &AcacConfig, shape: &EnvShape) -> Result<(), (&'static str, String)> {
        config::check(c, self, shape)
    }
}
