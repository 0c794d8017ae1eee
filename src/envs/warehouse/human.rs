//! The human in the workshop (`docs/WAREHOUSE.md` §4 "Human", section 8 step 7). Not an agent: it works
//! through `n_objs + 1` steps of fixed duration and needs tool k to leave work step k.

/// State of `AgentHuman` (`docs/WAREHOUSE.md` §4).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Human {
    /// Current work step, 0..=n_objs.
    pub step_k: usize,
    /// Time left in the current work step; keeps falling below 0 while waiting for a tool.
    pub htl: f64,
    /// The tool needed to leave the current step (stays n_objs - 1 on the last step).
    pub need: usize,
    /// Whether `need` has been delivered.
    pub obtained: bool,
    /// Set after the last step's advance; the human is never updated again.
    pub finished: bool,
}

impl Human {
    /// The human at reset: step 0, a full step of time, waiting for tool 0.
    pub fn new(step_duration: f64) -> Self {
        Self {
            step_k: 0,
            htl: step_duration,
            need: 0,
            obtained: false,
            finished: false,
        }
    }

    /// One primitive step of the human (`docs/WAREHOUSE.md` §8 step 7): count down, and move on once the
    /// time is up and the needed tool is there. `n_work_steps` = n_objs + 1.
    pub fn update(&mut self, step_duration: f64, n_work_steps: usize) {
        if self.finished {
            return;
        }
        self.htl -= 1.0;
        if self.htl <= 0.0 && self.obtained {
            self.advance(step_duration, n_work_steps);
        }
    }

    /// `AgentHuman.step`: the last work step ends the task; otherwise start the next step with a
    /// fresh duration and, unless it is the last one, a new tool request.
    fn advance(&mut self, step_duration: f64, n_work_steps: usize) {
        if self.step_k + 1 == n_work_steps {
            self.finished = true;
            return;
        }
        self.step_k += 1;
        self.htl = step_duration;
        if self.step_k + 1 < n_work_steps {
            self.need = self.step_k;
            self.obtained = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advances_only_when_time_is_up_and_tool_obtained() {
        let mut h = Human::new(18.0);
        for _ in 0..20 {
            h.update(18.0, 4);
        }
        assert_eq!((h.step_k, h.htl, h.obtained), (0, -2.0, false));
        h.obtained = true;
        h.update(18.0, 4);
        assert_eq!((h.step_k, h.htl, h.need, h.obtained), (1, 18.0, 1, false));
    }

    #[test]
    fn last_step_keeps_need_and_then_finishes() {
        let mut h = Human::new(18.0);
        for k in 1..=3 {
            h.obtained = true;
            for _ in 0..18 {
                h.update(18.0, 4);
            }
            assert_eq!(h.step_k, k);
        }
        // Step 3 has no request: need stays 2 and obtained stays true.
        assert_eq!((h.need, h.obtained, h.finished), (2, true, false));
        for _ in 0..18 {
            h.update(18.0, 4);
        }
        assert!(h.finished);
        assert_eq!(h.step_k, 3);
        let frozen = h.clone();
        h.update(18.0, 4);
        assert_eq!(h, frozen, "a finished human is never updated");
    }
}
