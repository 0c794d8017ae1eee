//! The value family as the list of families ([`crate::algos::families`]) sees it: its methods,
//! its config, its learner and its facts.

use crate::algos::family::{FamilyFacts, FamilyMethod};
use crate::algos::value::config::{self, ValueConfig};
use crate::algos::value::learner::ValueLearner;
use crate::algos::value::method::ValueMethod;
use crate::envs::{EnvShape, EnvSpec};

impl FamilyMethod for ValueMethod {
    type Config = ValueConfig;
    type Learner = ValueLearner;
    const FACTS: FamilyFacts = FamilyFacts {
        name: "value",
        description: "the ICRA 2020 macro-action Q-learning methods",
        quick_start: include_str!("quick_start.toml"),
        quick_start_name: "quickstart_bp10",
        list_keys: &[],
        evaluated_return: "the greedy discounted return",
    };
    const ALL: &'static [ValueMethod] = &[
        ValueMethod::DecHddrqn,
        ValueMethod::CenDdrqn,
        ValueMethod::Our1,
        ValueMethod::Our1R,
        ValueMethod::Our2,
    ];

    fn legend(self) -> &'static str {
        match self {
            ValueMethod::DecHddrqn => "Dec-HDDRQN",
            ValueMethod::CenDdrqn => "Cen-DDRQN",
            ValueMethod::Our1 => "Our-1",
            ValueMethod::Our1R => "Our-1-R",
            ValueMethod::Our2 => "Our-2",
        }
    }

    fn defaults(self, env: &EnvSpec) -> ValueConfig {
        config::paper_defaults(env, self)
    }

    fn check(self, c: &ValueConfig, shape: &EnvShape) -> Result<(), (&'static str, String)> {
        config::check(c, self, shape)
    }
}
