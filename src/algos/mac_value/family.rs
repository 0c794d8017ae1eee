//! MacroMARL's value-based family as the list of families ([`crate::algos::families`]) sees it.

use crate::algos::family::{FamilyFacts, FamilyMethod};
use crate::algos::mac_value::config::{self, MacValueConfig};
use crate::algos::mac_value::learner::MacValueLearner;
use crate::algos::mac_value::method::MacValueMethod;
use crate::envs::{EnvShape, EnvSpec};

impl FamilyMethod for MacValueMethod {
    type Config = MacValueConfig;
    type Learner = MacValueLearner;
    const FACTS: FamilyFacts = FamilyFacts {
        name: "macromarl-value",
        description: "MacroMARL's value-based macro-action methods (CoRL 2019)",
        quick_start: include_str!("quick_start.toml"),
        quick_start_name: "quickstart_mac_value_bp8",
        list_keys: &config::LIST_KEYS,
        evaluated_return: "the greedy discounted return",
    };
    const ALL: &'static [MacValueMethod] = &[
        MacValueMethod::MacDecQ,
        MacValueMethod::MacCenQ,
        MacValueMethod::MacDecDdrqn,
        MacValueMethod::ParallelMacDecDdrqn,
    ];

    fn legend(self) -> &'static str {
        match self {
            MacValueMethod::MacDecQ => "MacDec-Q",
            MacValueMethod::MacCenQ => "MacCen-Q",
            MacValueMethod::MacDecDdrqn => "MacDec-DDRQN",
            MacValueMethod::ParallelMacDecDdrqn => "Parallel-MacDec-DDRQN",
        }
    }

    fn defaults(self, env: &EnvSpec) -> MacValueConfig {
        config::published_defaults(env, self)
    }

    fn check(self, c: &MacValueConfig, shape: &EnvShape) -> Result<(), (&'static str, String)> {
        config::check(c, self, shape)
    }
}
