//! MacroMARL's value-based methods as a small value naming what differs between them: whose
//! Q-nets learn and act (`docs/MACROMARL.md` §8).

use crate::algos::learner::MethodName;
use serde::{Deserialize, Serialize};

/// One of MacroMARL's value-based methods, by its command-line name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MacValueMethod {
    /// MacDec-Q: a hysteretic double DRQN per agent on its own squeezed experience (`MacDecQ`).
    MacDecQ,
    /// MacCen-Q: one DRQN on the joint observation over joint macro-actions, squeezed where any
    /// agent finished, with the conditional argmax (`MacCenQ`).
    MacCenQ,
    /// MacDec-DDRQN (ICRA 2020's MacDec-MADDRQN as MacroMARL ships it, `MacDecDDRQN`): MacDec-Q's
    /// decentralized nets, whose double-Q targets take a' from a centralized net trained beside
    /// them as MacCen-Q (without hysteresis). No published script.
    MacDecDdrqn,
    /// Parallel-MacDec-DDRQN (`ParallelMacDecDDRQN`): MacDec-DDRQN with two sets of environments
    /// and two memories, one explored by the centralized net (trains it) and one by the agents'
    /// nets (trains them, counts the episodes). No published script.
    ParallelMacDecDdrqn,
}

impl MethodName for MacValueMethod {
    fn name(self) -> &'static str {
        match self {
            MacValueMethod::MacDecQ => "mac-dec-q",
            MacValueMethod::MacCenQ => "mac-cen-q",
            MacValueMethod::MacDecDdrqn => "mac-dec-ddrqn",
            MacValueMethod::ParallelMacDecDdrqn => "parallel-mac-dec-ddrqn",
        }
    }
}

/// Who learns and acts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum QNets {
    /// One Q-net per agent on its own observation history.
    Decentralized,
    /// One Q-net on the joint observation history over joint macro-actions.
    Centralized,
    /// One Q-net per agent, which act, and a centralized one that picks their targets' actions.
    DecWithCen,
}

impl MacValueMethod {
    /// The method's nets: the one place the methods differ.
    pub fn nets(self) -> QNets {
        match self {
            MacValueMethod::MacDecQ => QNets::Decentralized,
            MacValueMethod::MacCenQ => QNets::Centralized,
            MacValueMethod::MacDecDdrqn | MacValueMethod::ParallelMacDecDdrqn => QNets::DecWithCen,
        }
    }

    /// The reference's `--alg`, which keys its published settings.
    pub fn reference_alg(self) -> &'static str {
        match self {
            MacValueMethod::MacDecQ => "MacDecQ",
            MacValueMethod::MacCenQ => "MacCenQ",
            MacValueMethod::MacDecDdrqn => "MacDecDDRQN",
            MacValueMethod::ParallelMacDecDdrqn => "ParallelMacDecDDRQN",
        }
    }

    /// Whether the centralized net explores environments of its own into a memory of its own.
    pub fn parallel(self) -> bool {
        self == MacValueMethod::ParallelMacDecDdrqn
    }
}
