//! The Fetch's primitive step (`docs/WAREHOUSE.md` §6): search tools into a two-slot staging area and pass
//! them to a Turtlebot waiting at the table.

use super::params::N_TOOLS;
use super::turtlebot::{TbAction, Turtlebot};

/// Fetch macro-actions (`docs/WAREHOUSE.md` §3). Index 0 Wait, 1..=2 Pass to Turtlebot 0/1, 3..=5 Search.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FetchAction {
    /// Wait-M: one step.
    Wait,
    /// Pass-to-M(j): hand the first staged tool to Turtlebot j.
    Pass(usize),
    /// Search-Tool(i): find tool i and stage it.
    Search(usize),
}

impl FetchAction {
    /// The action with macro-action index `i`, if in range (0..6).
    pub fn from_index(i: usize) -> Option<Self> {
        match i {
            0 => Some(Self::Wait),
            1 | 2 => Some(Self::Pass(i - 1)),
            3..=5 => Some(Self::Search(i - 3)),
            _ => None,
        }
    }

    /// The macro-action index (inverse of [`Self::from_index`]).
    pub fn index(self) -> usize {
        match self {
            Self::Wait => 0,
            Self::Pass(j) => 1 + j,
            Self::Search(i) => 3 + i,
        }
    }
}

/// Durations and limits of the Fetch's actions, copied from the parameters once.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct FetchDynamics {
    /// Pass duration (4).
    pub pass_steps: f64,
    /// Search duration (6).
    pub search_steps: f64,
    /// How often each tool can be found per episode (1, quirk Q7).
    pub n_each_obj: usize,
}

impl FetchDynamics {
    fn duration(&self, a: FetchAction) -> f64 {
        match a {
            FetchAction::Wait => 1.0,
            FetchAction::Pass(_) => self.pass_steps,
            FetchAction::Search(_) => self.search_steps,
        }
    }
}

/// State of `AgentFetch_v4` (`docs/WAREHOUSE.md` §4).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Fetch {
    /// Current macro-action; None before the first step.
    pub cur: Option<FetchAction>,
    /// Whether the current macro-action finished (true at reset: free).
    pub done: bool,
    /// Countdown of the current action (f64 as in the reference).
    pub tl: f64,
    /// Staged tools, FIFO, `staging[..n_staged]`.
    pub staging: [usize; 2],
    /// Number of staged tools (0..=2).
    pub n_staged: usize,
    /// How often each tool was found this episode (never decreases).
    pub found_count: [usize; N_TOOLS],
    /// Staging signal: `[0,0]` empty, `[1,0]` one tool, `[0,1]` two (section 6 update rules).
    pub ready: [f64; 2],
    /// Set when a Pass starts without a Turtlebot waiting at the table; checked at its end.
    pub serving_failed: bool,
}

impl Default for Fetch {
    fn default() -> Self {
        Self {
            cur: None,
            done: true,
            tl: 0.0,
            staging: [0; 2],
            n_staged: 0,
            found_count: [0; N_TOOLS],
            ready: [0.0; 2],
            serving_failed: false,
        }
    }
}

impl Fetch {
    /// The staged tools, first to be passed first.
    pub fn staged(&self) -> &[usize] {
        &self.staging[..self.n_staged]
    }

    /// One primitive step (`docs/WAREHOUSE.md` §6). `a` is used only when the Fetch is free. The
    /// Turtlebots have already moved this step. Returns the step's reward (0 or -10).
    pub fn step(&mut self, a: FetchAction, dyn_: &FetchDynamics, tbs: &mut [Turtlebot; 2]) -> f64 {
        self.tl -= 1.0;
        if self.tl > 0.0 {
            return 0.0;
        }
        if self.done {
            self.start(a, dyn_, tbs);
            return 0.0;
        }
        let mut rew = 0.0;
        match self.cur {
            Some(FetchAction::Pass(j)) => rew = self.finish_pass(&mut tbs[j]),
            Some(FetchAction::Search(i)) => self.finish_search(i, dyn_.n_each_obj),
            // A Wait is done when it starts, so it never completes here; `cur` is set whenever
            // `done` is false.
            Some(FetchAction::Wait) | None => {}
        }
        self.done = true;
        rew
    }

    /// Start `a` (`docs/WAREHOUSE.md` §6 step 3). A Pass is doomed from the start if its Turtlebot is not
    /// at the table or has not waited at least one step (Q6).
    fn start(&mut self, a: FetchAction, dyn_: &FetchDynamics, tbs: &[Turtlebot; 2]) {
        self.cur = Some(a);
        self.tl = dyn_.duration(a) - 1.0;
        self.done = a == FetchAction::Wait;
        if let FetchAction::Pass(j) = a {
            let tb = &tbs[j];
            if tb.loc != Some(TbAction::GetTool as usize) || tb.tl > -1.0 {
                self.serving_failed = true;
            }
        }
    }

    /// End of a Pass: hand over the first staged tool (if any) to a Turtlebot still waiting with
    /// Get-Tool, ending its macro-action; otherwise -10. An empty staging area still ends the
    /// Turtlebot's Get-Tool (Q5).
    fn finish_pass(&mut self, tb: &mut Turtlebot) -> f64 {
        let ok = !self.serving_failed && tb.tl < 0.0 && tb.cur == Some(TbAction::GetTool);
        self.serving_failed = false;
        if !ok {
            return -10.0;
        }
        if self.n_staged > 0 {
            let tool = self.staging[0];
            self.staging[0] = self.staging[1];
            self.n_staged -= 1;
            tb.basket[tool] += 1.0;
        }
        tb.done = true;
        tb.tl = 0.0;
        self.ready = if self.n_staged == 1 {
            [1.0, 0.0]
        } else {
            [0.0, 0.0]
        };
        0.0
    }

    /// End of a Search: stage tool `i` unless the area is full or it was already found (Q7).
    fn finish_search(&mut self, i: usize, n_each_obj: usize) {
        if self.n_staged < 2 && self.found_count[i] < n_each_obj {
            self.found_count[i] += 1;
            self.staging[self.n_staged] = i;
            self.n_staged += 1;
            self.ready = if self.n_staged == 2 {
                [0.0, 1.0]
            } else {
                [1.0, 0.0]
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn action_indices_round_trip() {
        for i in 0..6 {
            assert_eq!(FetchAction::from_index(i).unwrap().index(), i);
        }
        assert_eq!(FetchAction::from_index(6), None);
        assert_eq!(FetchAction::from_index(2), Some(FetchAction::Pass(1)));
        assert_eq!(FetchAction::from_index(5), Some(FetchAction::Search(2)));
    }
}
