//! The value family's methods (ICRA 2020, `docs/ALGORITHMS.md` §4.6 and 5) as a small value
//! naming only what the paper varies between them: which nets exist, who picks the action inside
//! each target, how the training env(s) explore, and whether a loss is hysteretic.

use crate::algos::learner::MethodName;
use crate::algos::value::schedule::HysteresisSchedule;
use serde::{Deserialize, Serialize};

/// One of the ICRA paper's methods, by its command-line name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ValueMethod {
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

impl MethodName for ValueMethod {
    fn name(self) -> &'static str {
        match self {
            ValueMethod::DecHddrqn => "dec-hddrqn",
            ValueMethod::CenDdrqn => "cen-ddrqn",
            ValueMethod::Our1 => "our1",
            ValueMethod::Our1R => "our1-r",
            ValueMethod::Our2 => "our2",
        }
    }
}

impl ValueMethod {
    /// Whether the method trains per-agent decentralized Q-nets.
    pub fn has_dec_nets(self) -> bool {
        match self {
            ValueMethod::DecHddrqn | ValueMethod::Our1 | ValueMethod::Our1R | ValueMethod::Our2 => {
                true
            }
            ValueMethod::CenDdrqn => false,
        }
    }

    /// Whether the method trains the centralized Q-net.
    pub fn has_cen_net(self) -> bool {
        match self {
            ValueMethod::CenDdrqn | ValueMethod::Our1 | ValueMethod::Our1R | ValueMethod::Our2 => {
                true
            }
            ValueMethod::DecHddrqn => false,
        }
    }

    /// Who picks a*_i in the decentralized targets (`None` for Cen-DDRQN, which has none).
    pub fn dec_target_action(self) -> Option<DecTargetAction> {
        match self {
            ValueMethod::DecHddrqn | ValueMethod::Our1R => Some(DecTargetAction::OwnDoubleQ),
            ValueMethod::Our1 | ValueMethod::Our2 => Some(DecTargetAction::CenCondArgmax),
            ValueMethod::CenDdrqn => None,
        }
    }

    /// Whether the centralized loss uses the hysteretic transform: only Cen-DDRQN's does (spec
    /// 5.2); Our-1/2's centralized step never applies h (`docs/ALGORITHMS.md` §5.3 Step A).
    pub fn cen_loss_is_hysteretic(self) -> bool {
        match self {
            ValueMethod::CenDdrqn => true,
            ValueMethod::DecHddrqn | ValueMethod::Our1 | ValueMethod::Our1R | ValueMethod::Our2 => {
                false
            }
        }
    }

    /// Whether the decentralized losses use the hysteretic transform with the run's current h
    /// (`docs/ALGORITHMS.md` §5.1, 5.3 Step B). Every method with decentralized nets applies h there; only
    /// Dec-HDDRQN's paper schedule ([`Self::paper_hysteresis`]) moves it away from 1.
    pub fn dec_loss_is_hysteretic(self) -> bool {
        match self {
            ValueMethod::DecHddrqn | ValueMethod::Our1 | ValueMethod::Our1R | ValueMethod::Our2 => {
                true
            }
            ValueMethod::CenDdrqn => false,
        }
    }

    /// The paper's hysteresis schedule end points `(init_h, end_h)` (`docs/ALGORITHMS.md` §5.6, 10): Dec-HDDRQN
    /// moves from 0.2 to 0.4; every other method keeps h = 1 (no hysteresis).
    pub fn paper_hysteresis(self) -> (f64, f64) {
        match self {
            ValueMethod::DecHddrqn => (0.2, 0.4),
            ValueMethod::CenDdrqn | ValueMethod::Our1 | ValueMethod::Our1R | ValueMethod::Our2 => {
                (1.0, 1.0)
            }
        }
    }

    /// The paper's greedy episodes per evaluation (`docs/ALGORITHMS.md` §10): Dec-HDDRQN's code averages 20, the
    /// ICRA code evaluates once.
    pub fn paper_eval_num_epi(self) -> usize {
        match self {
            ValueMethod::DecHddrqn => 20,
            ValueMethod::CenDdrqn | ValueMethod::Our1 | ValueMethod::Our1R | ValueMethod::Our2 => 1,
        }
    }

    /// The paper's `--cen_explore` (`docs/ALGORITHMS.md` §4.6, 10): Our-1 and Our-1-R explore centrally; the flag
    /// means nothing to the other methods and is off for them.
    pub fn paper_cen_explore(self) -> bool {
        match self {
            ValueMethod::Our1 | ValueMethod::Our1R => true,
            ValueMethod::DecHddrqn | ValueMethod::CenDdrqn | ValueMethod::Our2 => false,
        }
    }

    /// The exploration of the training env(s); `cen_explore` is Our-1's `--cen_explore` flag.
    pub fn exploration(self, cen_explore: bool) -> Exploration {
        match self {
            ValueMethod::DecHddrqn => Exploration::Decentralized,
            ValueMethod::CenDdrqn => Exploration::Centralized,
            ValueMethod::Our1 | ValueMethod::Our1R if cen_explore => Exploration::Centralized,
            ValueMethod::Our1 | ValueMethod::Our1R => Exploration::Decentralized,
            ValueMethod::Our2 => Exploration::Parallel,
        }
    }

    /// Quirk Q12: whether a training env exploring with `exploration` still runs the
    /// decentralized selection each step (hidden states advance, draws are consumed) and
    /// discards its actions. Our-1 / Our-1-R do under centralized exploration.
    pub fn shadow_dec_selection(self, exploration: Exploration) -> bool {
        match self {
            ValueMethod::Our1 | ValueMethod::Our1R => exploration == Exploration::Centralized,
            ValueMethod::DecHddrqn | ValueMethod::CenDdrqn | ValueMethod::Our2 => false,
        }
    }

    /// The policy the paper evaluates (`docs/ALGORITHMS.md` §7.1): Cen-DDRQN acts centrally, all others by agent.
    pub fn evaluated_policy(self) -> EvaluatedPolicy {
        match self {
            ValueMethod::CenDdrqn => EvaluatedPolicy::Centralized,
            ValueMethod::DecHddrqn | ValueMethod::Our1 | ValueMethod::Our1R | ValueMethod::Our2 => {
                EvaluatedPolicy::Decentralized
            }
        }
    }

    /// Whether the decentralized batch comes from an env of its own, so the centralized a*
    /// selection for the decentralized targets must squeeze that batch jointly instead of reusing
    /// the centralized step's view (Our-2, `docs/ALGORITHMS.md` §5.5).
    pub fn dec_batch_is_separate(self) -> bool {
        match self {
            ValueMethod::Our2 => true,
            ValueMethod::DecHddrqn
            | ValueMethod::CenDdrqn
            | ValueMethod::Our1
            | ValueMethod::Our1R => false,
        }
    }

    /// Whether the method needs the whole-episode replay (`sample_epi = true`): the reference's
    /// windowed path for Our-2 crashes (`docs/ALGORITHMS.md` Q10), so Our-2 stays episode-based.
    pub fn requires_episode_buffer(self) -> bool {
        match self {
            ValueMethod::Our2 => true,
            ValueMethod::DecHddrqn
            | ValueMethod::CenDdrqn
            | ValueMethod::Our1
            | ValueMethod::Our1R => false,
        }
    }
}

/// The run's hysteresis settings (`dynamic_h`, `init_h`, `end_h`, `h_stable_at`): the one place
/// the value of h is decided. Which losses apply h is [`ValueMethod::cen_loss_is_hysteretic`] and
/// [`ValueMethod::dec_loss_is_hysteretic`]; the paper's end points are [`ValueMethod::paper_hysteresis`].
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::family::FamilyMethod;

    #[test]
    fn our1_and_our1_r_differ_only_in_the_dec_target_action() {
        let (a, b) = (ValueMethod::Our1, ValueMethod::Our1R);
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
        for &m in ValueMethod::ALL {
            assert_eq!(
                m.paper_hysteresis() != (1.0, 1.0),
                m == ValueMethod::DecHddrqn
            );
            assert_eq!(
                m.evaluated_policy() == EvaluatedPolicy::Centralized,
                !m.has_dec_nets()
            );
            assert_eq!(m.dec_loss_is_hysteretic(), m.has_dec_nets());
            assert!(!m.shadow_dec_selection(Exploration::Decentralized));
        }
        assert!(ValueMethod::Our1.shadow_dec_selection(Exploration::Centralized));
        assert!(!ValueMethod::CenDdrqn.shadow_dec_selection(Exploration::Centralized));
    }

    #[test]
    fn serde_names_are_the_command_line_names() {
        for &m in ValueMethod::ALL {
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.name()));
        }
    }
}
