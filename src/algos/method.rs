//! The five methods as small values naming only what the paper varies between them
//! (spec `algorithms.md` 4.6 and 5): which nets exist, who picks the action inside each target,
//! how the training env(s) explore, and whether a loss is hysteretic.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// One of the paper's learning methods, by its command-line name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Decentralized hysteretic double DRQN over Mac-CERTs (spec 5.1).
    DecHddrqn,
    /// Centralized double DRQN with the conditional argmax (spec 5.2).
    CenDdrqn,
    /// MacDec-MADDRQN, "Our-1": decentralized targets pick a* with the centralized net (Eq. 4).
    Our1,
    /// Our-1 with regular double-Q inside the decentralized targets (ablation, spec 5.4).
    #[serde(rename = "our1-r")]
    Our1R,
    /// Parallel-MacDec-MADDRQN, "Our-2": separate centralized and decentralized envs (spec 5.5).
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

/// How the training environment(s) pick actions (spec 4.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Exploration {
    /// Each agent epsilon-greedy on its own net (spec 4.2).
    Decentralized,
    /// Epsilon-greedy on the centralized net with the conditional argmax (spec 4.3).
    Centralized,
    /// Our-2: a decentralized-exploring env and a centralized-exploring env in lockstep (5.5).
    Parallel,
}

impl Method {
    /// All methods, in the order the paper introduces them.
    pub const ALL: [Method; 5] = [
        Method::DecHddrqn,
        Method::CenDdrqn,
        Method::Our1,
        Method::Our1R,
        Method::Our2,
    ];

    /// The command-line and directory name.
    pub fn name(self) -> &'static str {
        match self {
            Method::DecHddrqn => "dec-hddrqn",
            Method::CenDdrqn => "cen-ddrqn",
            Method::Our1 => "our1",
            Method::Our1R => "our1-r",
            Method::Our2 => "our2",
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
        }
    }

    /// Whether the method trains per-agent decentralized Q-nets.
    pub fn has_dec_nets(self) -> bool {
        self != Method::CenDdrqn
    }

    /// Whether the method trains the centralized Q-net.
    pub fn has_cen_net(self) -> bool {
        self != Method::DecHddrqn
    }

    /// Who picks a*_i in the decentralized targets (`None` for Cen-DDRQN, which has none).
    pub fn dec_target_action(self) -> Option<DecTargetAction> {
        match self {
            Method::DecHddrqn | Method::Our1R => Some(DecTargetAction::OwnDoubleQ),
            Method::Our1 | Method::Our2 => Some(DecTargetAction::CenCondArgmax),
            Method::CenDdrqn => None,
        }
    }

    /// Whether the centralized loss uses the hysteretic transform: only Cen-DDRQN's does (spec
    /// 5.2); Our-1/2's centralized step never applies h (spec 5.3 Step A).
    pub fn cen_loss_is_hysteretic(self) -> bool {
        self == Method::CenDdrqn
    }

    /// The exploration of the training env(s); `cen_explore` is Our-1's `--cen_explore` flag.
    pub fn exploration(self, cen_explore: bool) -> Exploration {
        match self {
            Method::DecHddrqn => Exploration::Decentralized,
            Method::CenDdrqn => Exploration::Centralized,
            Method::Our1 | Method::Our1R if cen_explore => Exploration::Centralized,
            Method::Our1 | Method::Our1R => Exploration::Decentralized,
            Method::Our2 => Exploration::Parallel,
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The name given is not one of the five methods.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown method `{0}`: expected one of dec-hddrqn, cen-ddrqn, our1, our1-r, our2")]
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
    }
}
