//! A human at a work area (`AgentHuman` of the `core_*_room.py` files, `std = None`): four work
//! steps of fixed length; leaving step k < 3 needs tool k.

use super::layout::{N_OBJS, N_WORK_STEPS};

/// One human's progress.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Human {
    /// Steps each work step takes (`expected_timecost_per_task_step`).
    pub speeds: [f64; N_WORK_STEPS],
    /// Current work step (`cur_step`).
    pub cur_step: usize,
    /// Steps left in it (`cur_step_time_left`); negative while waiting for a tool.
    pub time_left: f64,
    /// The tool needed to leave the current step (`next_request_obj_idx`).
    pub need: usize,
    /// That tool was delivered (`next_requested_obj_obtained`).
    pub obtained: bool,
    /// The whole task is done (`whole_task_finished`); the human no longer counts down.
    pub finished: bool,
}

impl Human {
    /// A human at the start of its task.
    pub fn new(speeds: [f64; N_WORK_STEPS]) -> Self {
        Human {
            speeds,
            cur_step: 0,
            time_left: speeds[0],
            need: 0,
            obtained: false,
            finished: false,
        }
    }

    /// `AgentHuman.step`: leave the current work step (called once its time ran out and its
    /// tool is there). After the last tool the human keeps `obtained` set and works the last
    /// step; leaving that one finishes the task.
    fn advance(&mut self) {
        if self.cur_step + 1 == N_WORK_STEPS {
            self.finished = true;
            return;
        }
        self.cur_step += 1;
        self.time_left = self.speeds[self.cur_step];
        if self.cur_step < N_OBJS {
            self.need = self.cur_step;
            self.obtained = false;
        }
    }

    /// One primitive step of the env's human loop: count down, and move on when possible.
    pub fn tick(&mut self) {
        if self.finished {
            return;
        }
        self.time_left -= 1.0;
        if self.time_left <= 0.0 && self.obtained {
            self.advance();
        }
    }

    /// Whether this human just got its third tool (the env's `finish_serve_humans` test).
    pub fn served(&self) -> bool {
        self.cur_step == N_WORK_STEPS - 2 && self.obtained
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_human_waits_for_each_tool_then_finishes_the_last_step() {
        let mut h = Human::new([2.0, 1.0, 1.0, 3.0]);
        h.tick();
        h.tick();
        assert_eq!((h.cur_step, h.time_left), (0, 0.0), "waits for tool 0");
        h.tick();
        assert_eq!(h.time_left, -1.0);
        h.obtained = true;
        h.tick();
        assert_eq!(
            (h.cur_step, h.need, h.obtained, h.time_left),
            (1, 1, false, 1.0)
        );
        for tool in 1..3 {
            h.obtained = true;
            h.tick();
            assert_eq!(h.cur_step, tool + 1);
        }
        assert!(h.obtained, "the last step needs no tool");
        for _ in 0..3 {
            h.tick();
        }
        assert!(h.finished);
        h.tick();
        assert_eq!(h.time_left, 0.0, "a finished human no longer counts down");
    }
}
