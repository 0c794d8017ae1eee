//! ACAC's three training algorithms (`scripts/acac_main.py --alg_name`) as a small value naming
//! what differs between them.

use crate::algos::learner::MethodName;
use serde::{Deserialize, Serialize};

/// One of ACAC's algorithms, by its command-line name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AcacMethod {
    /// Agent-Centric Actor-Critic (`acac`): per-agent GRU actors, the attention critic over the
    /// agents' own macro-observation histories, macro-level GAE, PPO (`learner_acac.py`).
    Acac,
    /// The ablation without the agent-centric parts (`acac_vanilla`, `learner_acac_vanilla.py`).
    AcacVanilla,
    /// ACAC with GAE per primitive step instead of per joint macro-step (`acac_micro_gae`,
    /// `learner_acac_micro_gae.py`).
    AcacMicroGae,
}

impl MethodName for AcacMethod {
    fn name(self) -> &'static str {
        match self {
            AcacMethod::Acac => "acac",
            AcacMethod::AcacVanilla => "acac-vanilla",
            AcacMethod::AcacMicroGae => "acac-micro-gae",
        }
    }
}

impl AcacMethod {
    /// The reference's `--alg_name`, which names its `scripts/params/alg/<alg>.json`.
    pub fn reference_alg(self) -> &'static str {
        match self {
            AcacMethod::Acac => "acac",
            AcacMethod::AcacVanilla => "acac_vanilla",
            AcacMethod::AcacMicroGae => "acac_micro_gae",
        }
    }
}
