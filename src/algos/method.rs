//! The methods as small values naming only what their papers vary between them: for the ICRA
//! 2020 value methods (`docs/ALGORITHMS.md` §4.6 and 5) which nets exist, who picks the action
//! inside each target, how the training env(s) explore, and whether a loss is hysteretic; for
//! MacroMARL's actor-critic methods (`docs/MACROMARL.md` §2.7) whose actor acts and what the
//! critic sees ([`Method::actor_critic`]).

use crate::algos::value::schedule::HysteresisSchedule;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// One of the paper's learning methods, by its command-line name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Decentralized hysteretic double DRQN over Mac-CERTs (`docs/ALGORITHMS.md` §5.1).
    DecHddrqn,
    /// Centralized double DRQN with the conditional argmax (`docs/ALGORITHMS.md` §5.2).
    CenDdrqn,
    /// MacDec-MADDRQN, "Our-1": decentralized targets pick a* with the centralized net (Eq. 4).
    Our1,
    /// Our-1 with regular double-Q inside the decentralized targets (ablation, `docs/ALGORITHMS.md` §5.4).
    #[serde(rename = "our1-r")]
    Our1R,
    /// Parallel-MacDec-MADDRQN, "Our-2": separate centralized and decentralized envs (`docs/ALGORITHMS.md` §5.5).
    Our2,
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

/// The actor-critic methods, as a pattern (value-family `match`es list them in one arm).
macro_rules! actor_critic_methods {
    () => {
        Method::MacIac
            | Method::MacCac
            | Method::NaiveMacIacc
            | Method::NaiveMacIasc
            | Method::MacIaicc
            | Method::MacIaisc
    };
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

/// A method family: the learner type the training loop drives for a method (see
/// [`crate::algos::learner::Learner`]). Runs, checkpoints and policy files pick the learner by
/// matching on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    /// The ICRA 2020 Q-learning methods ([`crate::algos::value::learner::ValueLearner`]).
    Value,
    /// MacroMARL's actor-critic methods
    /// ([`crate::algos::actor_critic::learner::AcLearner`]).
    ActorCritic,
}

/// Who chooses a*_i inside agent i's decentralized target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecTargetAction {
    /// argmax of agent i's own online net on its next history (Dec-HDDRQN, Our-1-R).
    OwnDoubleQ,
    /// Agent i's component of the centralized conditional argmax (Our-1, Our-2; paper Eq. 4).
    CenCondArgmax,
}

/// How the training environment(s) pick actions (`docs/ALGORITHMS.md` §4.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Exploration {
    /// Each agent epsilon-greedy on its own net (`docs/ALGORITHMS.md` §4.2).
    Decentralized,
    /// Epsilon-greedy on the centralized net with the conditional argmax (`docs/ALGORITHMS.md` §4.3).
    Centralized,
    /// Our-2: a decentralized-exploring env and a centralized-exploring env in lockstep (5.5).
    Parallel,
}

impl Method {
    /// All methods: the ICRA paper's in the order it introduces them, then MacroMARL's.
    pub const ALL: [Method; 11] = [
        Method::DecHddrqn,
        Method::CenDdrqn,
        Method::Our1,
        Method::Our1R,
        Method::Our2,
        Method::MacIac,
        Method::MacCac,
        Method::NaiveMacIacc,
        Method::NaiveMacIasc,
        Method::MacIaicc,
        Method::MacIaisc,
    ];

    /// The family whose learner trains this method.
    pub fn family(self) -> Family {
        match self {
            Method::DecHddrqn | Method::CenDdrqn | Method::Our1 | Method::Our1R | Method::Our2 => {
                Family::Value
            }
            actor_critic_methods!() => Family::ActorCritic,
        }
    }

    /// An actor-critic method's actor and critic (`None` for the value methods): the one place
    /// the six differ (`docs/MACROMARL.md` §2.7).
    pub fn actor_critic(self) -> Option<AcDesign> {
        let design = |actor, critic, reference_alg| {
            Some(AcDesign {
                actor,
                critic,
                reference_alg,
            })
        };
        use AcActor::{Centralized, Decentralized};
        match self {
            Method::MacIac => design(Decentralized, AcCritic::OwnHistory, "MacIAC"),
            Method::MacCac => design(Centralized, AcCritic::JointHistory, "MacCAC"),
            Method::NaiveMacIacc => design(Decentralized, AcCritic::JointHistory, "NaiveMacIACC"),
            Method::NaiveMacIasc => design(Decentralized, AcCritic::JointState, "NaiveMacIASC"),
            Method::MacIaicc => design(Decentralized, AcCritic::AgentJointHistory, "MacIAICC"),
            Method::MacIaisc => design(Decentralized, AcCritic::AgentState, "MacIAISC"),
            Method::DecHddrqn | Method::CenDdrqn | Method::Our1 | Method::Our1R | Method::Our2 => {
                None
            }
        }
    }

    /// The command-line and directory name.
    pub fn name(self) -> &'static str {
        match self {
            Method::DecHddrqn => "dec-hddrqn",
            Method::CenDdrqn => "cen-ddrqn",
            Method::Our1 => "our1",
            Method::Our1R => "our1-r",
            Method::Our2 => "our2",
            Method::MacIac => "mac-iac",
            Method::MacCac => "mac-cac",
            Method::NaiveMacIacc => "naive-mac-iacc",
            Method::NaiveMacIasc => "naive-mac-iasc",
            Method::MacIaicc => "mac-iaicc",
            Method::MacIaisc => "mac-iaisc",
        }
    }

    /// The name in the paper's figure legends.
    pub fn legend(self) -> &'static str {
        match self {
            Method::DecHddrqn => "Dec-HDDRQN",
            Method::CenDdrqn => "Cen-DDRQN",
            Method::Our1 => "Our-1",
            Method::Our1R => "Our-1-R",
            Method::Our2 => "Our-2",
            Method::MacIac => "Mac-IAC",
            Method::MacCac => "Mac-CAC",
            Method::NaiveMacIacc => "Naive Mac-IACC",
            Method::NaiveMacIasc => "Naive Mac-IASC",
            Method::MacIaicc => "Mac-IAICC",
            Method::MacIaisc => "Mac-IAISC",
        }
    }

    /// Whether the method trains per-agent decentralized Q-nets.
    pub fn has_dec_nets(self) -> bool {
        match self {
            Method::DecHddrqn | Method::Our1 | Method::Our1R | Method::Our2 => true,
            Method::CenDdrqn => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }

    /// Whether the method trains the centralized Q-net.
    pub fn has_cen_net(self) -> bool {
        match self {
            Method::CenDdrqn | Method::Our1 | Method::Our1R | Method::Our2 => true,
            Method::DecHddrqn => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }

    /// Who picks a*_i in the decentralized targets (`None` for Cen-DDRQN, which has none).
    pub fn dec_target_action(self) -> Option<DecTargetAction> {
        match self {
            Method::DecHddrqn | Method::Our1R => Some(DecTargetAction::OwnDoubleQ),
            Method::Our1 | Method::Our2 => Some(DecTargetAction::CenCondArgmax),
            Method::CenDdrqn => None,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => None,
        }
    }

    /// Whether the centralized loss uses the hysteretic transform: only Cen-DDRQN's does (spec
    /// 5.2); Our-1/2's centralized step never applies h (`docs/ALGORITHMS.md` §5.3 Step A).
    pub fn cen_loss_is_hysteretic(self) -> bool {
        match self {
            Method::CenDdrqn => true,
            Method::DecHddrqn | Method::Our1 | Method::Our1R | Method::Our2 => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }

    /// Whether the decentralized losses use the hysteretic transform with the run's current h
    /// (`docs/ALGORITHMS.md` §5.1, 5.3 Step B). Every method with decentralized nets applies h there; only
    /// Dec-HDDRQN's paper schedule ([`Self::paper_hysteresis`]) moves it away from 1.
    pub fn dec_loss_is_hysteretic(self) -> bool {
        match self {
            Method::DecHddrqn | Method::Our1 | Method::Our1R | Method::Our2 => true,
            Method::CenDdrqn => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }

    /// The paper's hysteresis schedule end points `(init_h, end_h)` (`docs/ALGORITHMS.md` §5.6, 10): Dec-HDDRQN
    /// moves from 0.2 to 0.4; every other method keeps h = 1 (no hysteresis).
    pub fn paper_hysteresis(self) -> (f64, f64) {
        match self {
            Method::DecHddrqn => (0.2, 0.4),
            Method::CenDdrqn | Method::Our1 | Method::Our1R | Method::Our2 => (1.0, 1.0),
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => (1.0, 1.0),
        }
    }

    /// The paper's greedy episodes per evaluation (`docs/ALGORITHMS.md` §10): Dec-HDDRQN's code averages 20, the
    /// ICRA code evaluates once.
    pub fn paper_eval_num_epi(self) -> usize {
        match self {
            Method::DecHddrqn => 20,
            Method::CenDdrqn | Method::Our1 | Method::Our1R | Method::Our2 => 1,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => 1,
        }
    }

    /// The paper's `--cen_explore` (`docs/ALGORITHMS.md` §4.6, 10): Our-1 and Our-1-R explore centrally; the flag
    /// means nothing to the other methods and is off for them.
    pub fn paper_cen_explore(self) -> bool {
        match self {
            Method::Our1 | Method::Our1R => true,
            Method::DecHddrqn | Method::CenDdrqn | Method::Our2 => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }

    /// The exploration of the training env(s); `cen_explore` is Our-1's `--cen_explore` flag.
    pub fn exploration(self, cen_explore: bool) -> Exploration {
        match self {
            Method::DecHddrqn => Exploration::Decentralized,
            Method::CenDdrqn => Exploration::Centralized,
            Method::Our1 | Method::Our1R if cen_explore => Exploration::Centralized,
            Method::Our1 | Method::Our1R => Exploration::Decentralized,
            Method::Our2 => Exploration::Parallel,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => Exploration::Decentralized,
        }
    }

    /// Quirk Q12: whether a training env exploring with `exploration` still runs the
    /// decentralized selection each step (hidden states advance, draws are consumed) and
    /// discards its actions. Our-1 / Our-1-R do under centralized exploration.
    pub fn shadow_dec_selection(self, exploration: Exploration) -> bool {
        match self {
            Method::Our1 | Method::Our1R => exploration == Exploration::Centralized,
            Method::DecHddrqn | Method::CenDdrqn | Method::Our2 => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }

    /// The policy the paper evaluates (`docs/ALGORITHMS.md` §7.1): Cen-DDRQN acts centrally, all others by agent.
    pub fn evaluated_policy(self) -> EvaluatedPolicy {
        match self {
            Method::CenDdrqn => EvaluatedPolicy::Centralized,
            Method::DecHddrqn | Method::Our1 | Method::Our1R | Method::Our2 => {
                EvaluatedPolicy::Decentralized
            }
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => EvaluatedPolicy::Decentralized,
        }
    }

    /// Whether the decentralized batch comes from an env of its own, so the centralized a*
    /// selection for the decentralized targets must squeeze that batch jointly instead of reusing
    /// the centralized step's view (Our-2, `docs/ALGORITHMS.md` §5.5).
    pub fn dec_batch_is_separate(self) -> bool {
        match self {
            Method::Our2 => true,
            Method::DecHddrqn | Method::CenDdrqn | Method::Our1 | Method::Our1R => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }

    /// Whether the method needs the whole-episode replay (`sample_epi = true`): the reference's
    /// windowed path for Our-2 crashes (`docs/ALGORITHMS.md` Q10), so Our-2 stays episode-based.
    pub fn requires_episode_buffer(self) -> bool {
        match self {
            Method::Our2 => true,
            Method::DecHddrqn | Method::CenDdrqn | Method::Our1 | Method::Our1R => false,
            // Not a value method: nothing of this family applies.
            actor_critic_methods!() => false,
        }
    }
}

/// The run's hysteresis settings (`dynamic_h`, `init_h`, `end_h`, `h_stable_at`): the one place
/// the value of h is decided. Which losses apply h is [`Method::cen_loss_is_hysteretic`] and
/// [`Method::dec_loss_is_hysteretic`]; the paper's end points are [`Method::paper_hysteresis`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HysteresisRule {
    /// Follow the schedule (`docs/ALGORITHMS.md` §5.6); otherwise h = 1 - epsilon (the reference's fallback).
    pub dynamic: bool,
    /// h at episode 0.
    pub init_h: f64,
    /// h from `h_stable_at` episodes on.
    pub end_h: f64,
    /// Episodes over which h moves linearly from `init_h` to `end_h`.
    pub h_stable_at: f64,
}

impl HysteresisRule {
    /// h until the first training iteration: the schedule's start (1 if the schedule is invalid).
    pub fn initial(&self) -> f64 {
        HysteresisSchedule::new(self.init_h, self.end_h, self.h_stable_at)
            .map(|s| s.initial())
            .unwrap_or(1.0)
    }

    /// h at a training iteration after `episodes` episodes, with the exploration rate `epsilon`
    /// of the previous iteration (quirk Q8: h is recomputed before the step, epsilon after it).
    pub fn at(&self, episodes: f64, epsilon: f64) -> f64 {
        if self.dynamic {
            HysteresisSchedule::new(self.init_h, self.end_h, self.h_stable_at)
                .map(|s| s.at(episodes))
                .unwrap_or(1.0)
        } else {
            1.0 - epsilon
        }
    }
}

/// Which nets act in the evaluated (greedy) policy of a method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvaluatedPolicy {
    /// Each agent's own decentralized net.
    Decentralized,
    /// The centralized net with the conditional argmax.
    Centralized,
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The name given is not one of the five methods.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown method `{0}`: expected one of dec-hddrqn, cen-ddrqn, our1, our1-r, our2, mac-iac, mac-cac, naive-mac-iacc, naive-mac-iasc, mac-iaicc, mac-iaisc")]
pub struct UnknownMethod(pub String);

impl FromStr for Method {
    type Err = UnknownMethod;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s.trim())
            .ok_or_else(|| UnknownMethod(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exactly_the_actor_critic_methods_have_a_design_and_names_match_the_reference() {
        for m in Method::ALL {
            assert_eq!(
                m.actor_critic().is_some(),
                m.family() == Family::ActorCritic
            );
        }
        let algs: Vec<&str> = Method::ALL
            .iter()
            .filter_map(|m| m.actor_critic())
            .map(|d| d.reference_alg)
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
        for m in Method::ALL.iter().filter_map(|m| m.actor_critic()) {
            assert_eq!(m.actor == AcActor::Centralized, m.reference_alg == "MacCAC");
            let state = matches!(m.critic, AcCritic::JointState | AcCritic::AgentState);
            assert_eq!(state, m.reference_alg.ends_with("SC"));
        }
    }

    #[test]
    fn names_round_trip_through_from_str() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
        }
        assert!("our3".parse::<Method>().is_err());
    }

    #[test]
    fn our1_and_our1_r_differ_only_in_the_dec_target_action() {
        let (a, b) = (Method::Our1, Method::Our1R);
        assert_ne!(a.dec_target_action(), b.dec_target_action());
        assert_eq!(a.has_dec_nets(), b.has_dec_nets());
        assert_eq!(a.has_cen_net(), b.has_cen_net());
        assert_eq!(a.exploration(true), b.exploration(true));
        assert_eq!(a.cen_loss_is_hysteretic(), b.cen_loss_is_hysteretic());
        assert_eq!(a.dec_loss_is_hysteretic(), b.dec_loss_is_hysteretic());
        assert_eq!(a.paper_hysteresis(), b.paper_hysteresis());
        assert_eq!(a.evaluated_policy(), b.evaluated_policy());
        assert_eq!(
            a.shadow_dec_selection(Exploration::Centralized),
            b.shadow_dec_selection(Exploration::Centralized)
        );
    }

    #[test]
    fn hysteresis_follows_the_schedule_or_one_minus_epsilon() {
        let mut r = HysteresisRule {
            dynamic: true,
            init_h: 0.2,
            end_h: 0.4,
            h_stable_at: 100.0,
        };
        assert_eq!(r.initial(), 0.2);
        assert!((r.at(50.0, 0.7) - 0.3).abs() < 1e-12);
        assert_eq!(r.at(500.0, 0.7), 0.4);
        r.dynamic = false;
        assert!((r.at(50.0, 0.7) - 0.3).abs() < 1e-12);
        r.h_stable_at = 0.0;
        r.dynamic = true;
        assert_eq!((r.initial(), r.at(5.0, 0.5)), (1.0, 1.0));
    }

    #[test]
    fn only_dec_hddrqn_has_a_hysteresis_schedule_and_only_cen_ddrqn_acts_centrally() {
        for m in Method::ALL
            .into_iter()
            .filter(|m| m.family() == Family::Value)
        {
            assert_eq!(m.paper_hysteresis() != (1.0, 1.0), m == Method::DecHddrqn);
            assert_eq!(
                m.evaluated_policy() == EvaluatedPolicy::Centralized,
                !m.has_dec_nets()
            );
            assert_eq!(m.dec_loss_is_hysteretic(), m.has_dec_nets());
            assert!(!m.shadow_dec_selection(Exploration::Decentralized));
        }
        assert!(Method::Our1.shadow_dec_selection(Exploration::Centralized));
        assert!(!Method::CenDdrqn.shadow_dec_selection(Exploration::Centralized));
    }
}
