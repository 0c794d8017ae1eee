//! MacroMARL's actor-critic methods (`docs/MACROMARL.md` §2.7) as a small value naming only what
//! the paper varies between them: whose actor acts and what the critic sees ([`AcMethod::design`]).

use crate::algos::learner::MethodName;
use serde::{Deserialize, Serialize};

/// One of MacroMARL's actor-critic methods, by its command-line name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AcMethod {
    /// Mac-IAC: independent actors and history critics (MacroMARL's `MacIAC`).
    MacIac,
    /// Mac-CAC: one centralized actor over joint macro-actions and a joint critic (`MacCAC`).
    MacCac,
    /// Naive Mac-IACC: decentralized actors, one shared joint-history critic (`NaiveMacIACC`).
    NaiveMacIacc,
    /// Naive Mac-IACC with the shared critic on the global state (`NaiveMacIASC`).
    NaiveMacIasc,
    /// Mac-IAICC: decentralized actors, a joint-history critic per agent (`MacIAICC`).
    MacIaicc,
    /// Mac-IAICC with each agent's critic on the global state (`MacIAISC`).
    MacIaisc,
}

impl MethodName for AcMethod {
    fn name(self) -> &'static str {
        match self {
            AcMethod::MacIac => "mac-iac",
            AcMethod::MacCac => "mac-cac",
            AcMethod::NaiveMacIacc => "naive-mac-iacc",
            AcMethod::NaiveMacIasc => "naive-mac-iasc",
            AcMethod::MacIaicc => "mac-iaicc",
            AcMethod::MacIaisc => "mac-iaisc",
        }
    }
}

impl AcMethod {
    /// The method's actor and critic: the one place the six differ (`docs/MACROMARL.md` §2.7).
    pub fn design(self) -> AcDesign {
        let design = |actor, critic, reference_alg| AcDesign {
            actor,
            critic,
            reference_alg,
        };
        use AcActor::{Centralized, Decentralized};
        match self {
            AcMethod::MacIac => design(Decentralized, AcCritic::OwnHistory, "MacIAC"),
            AcMethod::MacCac => design(Centralized, AcCritic::JointHistory, "MacCAC"),
            AcMethod::NaiveMacIacc => design(Decentralized, AcCritic::JointHistory, "NaiveMacIACC"),
            AcMethod::NaiveMacIasc => design(Decentralized, AcCritic::JointState, "NaiveMacIASC"),
            AcMethod::MacIaicc => design(Decentralized, AcCritic::AgentJointHistory, "MacIAICC"),
            AcMethod::MacIaisc => design(Decentralized, AcCritic::AgentState, "MacIAISC"),
        }
    }
}

/// Who acts in an actor-critic method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AcActor {
    /// Each agent samples from its own actor on its own observation history.
    Decentralized,
    /// One actor over the joint observation samples a joint macro-action, conditioned on the
    /// busy agents' running ones (Mac-CAC).
    Centralized,
}

/// What an actor-critic method's critic sees and whose return it learns (`docs/MACROMARL.md` §2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AcCritic {
    /// Agent i's own critic on its own observation history, its own macro-rewards (Mac-IAC).
    OwnHistory,
    /// One critic on the joint observation history at joint macro-steps, the joint reward
    /// (Mac-CAC; Naive Mac-IACC, whose agents take the joint advantage where they finished).
    JointHistory,
    /// One critic on the global state at joint macro-steps (Naive Mac-IASC).
    JointState,
    /// A critic per agent on the joint observation history, agent i's rewards and durations
    /// (Mac-IAICC).
    AgentJointHistory,
    /// A critic per agent on the global state at agent i's macro-action starts (Mac-IAISC).
    AgentState,
}

/// An actor-critic method's design: its actor and its critic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AcDesign {
    /// Who acts.
    pub actor: AcActor,
    /// What the critics see and whose return they learn.
    pub critic: AcCritic,
    /// The name of the reference's class (`--alg`), which keys its published settings.
    pub reference_alg: &'static str,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::family::FamilyMethod;

    #[test]
    fn designs_match_the_reference_classes() {
        let algs: Vec<&str> = AcMethod::ALL
            .iter()
            .map(|m| m.design().reference_alg)
            .collect();
        assert_eq!(
            algs,
            [
                "MacIAC",
                "MacCAC",
                "NaiveMacIACC",
                "NaiveMacIASC",
                "MacIAICC",
                "MacIAISC"
            ]
        );
        // Only Mac-CAC acts centrally; the state critics are the -sc variants.
        for d in AcMethod::ALL.iter().map(|m| m.design()) {
            assert_eq!(d.actor == AcActor::Centralized, d.reference_alg == "MacCAC");
            let state = matches!(d.critic, AcCritic::JointState | AcCritic::AgentState);
            assert_eq!(state, d.reference_alg.ends_with("SC"));
        }
    }

    #[test]
    fn serde_names_are_the_command_line_names() {
        for &m in AcMethod::ALL {
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.name()));
        }
    }
}
