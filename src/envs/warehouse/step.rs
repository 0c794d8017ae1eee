//! One primitive step of the whole domain, in the reference's exact order (`docs/WAREHOUSE.md` §8, Q14):
//! Turtlebot 0, Turtlebot 1, Fetch, done flags, termination test, human, observations.

use super::fetch::FetchAction;
use super::observe::{write_fetch_obs, write_turtlebot_obs};
use super::turtlebot::TbAction;
use super::{Warehouse, N_ACTIONS, N_AGENTS};
use crate::envs::{EnvError, EnvRng, StepOutcome};

impl Warehouse {
    /// Check the input, then run one step. An error leaves the state untouched.
    pub(super) fn step_checked(
        &mut self,
        actions: &[usize],
        rng: &mut EnvRng,
    ) -> Result<StepOutcome, EnvError> {
        if self.over {
            return Err(EnvError::EpisodeOver);
        }
        if actions.len() != N_AGENTS {
            return Err(EnvError::WrongActionCount {
                expected: N_AGENTS,
                got: actions.len(),
            });
        }
        // Only free agents' values are used (busy ones are ignored, `docs/WAREHOUSE.md` §3); the
        // reference's negative-index acceptance (Q11) is rejected like any out-of-range value.
        for agent in 0..N_AGENTS {
            let free = match agent {
                0 | 1 => self.tbs[agent].done,
                _ => self.fetch.done,
            };
            if free && actions[agent] >= N_ACTIONS[agent] {
                return Err(EnvError::ActionOutOfRange {
                    agent,
                    action: actions[agent],
                    n_actions: N_ACTIONS[agent],
                });
            }
        }
        Ok(self.step_unchecked(actions, rng))
    }

    /// `docs/WAREHOUSE.md` §8 steps 1-9 on validated input.
    fn step_unchecked(&mut self, actions: &[usize], rng: &mut EnvRng) -> StepOutcome {
        let mut r = -1.0;
        self.count += 1;

        // Turtlebot 0 then 1: the order of their noise draws and of deliveries.
        for ((tb, &passed), executed) in self.tbs.iter_mut().zip(actions).zip(&mut self.executed) {
            let a = match (tb.done, tb.cur) {
                (false, Some(cur)) => cur,
                _ => TbAction::ALL[passed],
            };
            r += tb.step(a, &self.tb_dyn, &mut self.human, rng);
            *executed = a as usize;
        }

        let fa = match (self.fetch.done, self.fetch.cur) {
            (false, Some(cur)) => cur,
            _ => FetchAction::from_index(actions[2]).expect("checked in step_checked"),
        };
        r += self.fetch.step(fa, &self.fetch_dyn, &mut self.tbs);
        self.executed[2] = fa.index();

        self.mac_done = [self.tbs[0].done, self.tbs[1].done, self.fetch.done];
        // Termination sees the human before its update (Q14): the last needed tool delivered.
        let n_work_steps = self.params.n_objs + 1;
        let terminal = self.human.step_k == n_work_steps - 2 && self.human.obtained;
        self.human
            .update(self.params.human_speed_per_step, n_work_steps);

        for i in 0..2 {
            if self.mac_done[i] {
                write_turtlebot_obs(&mut self.obs_tb[i], &self.tbs[i], &self.human, &self.fetch);
            }
        }
        if self.mac_done[2] {
            write_fetch_obs(&mut self.obs_fetch, &self.fetch, &self.tbs);
        }

        // Horizon by equality (Q2); the error on a further step makes "past H" unreachable.
        let done = terminal || self.count == self.params.terminate_step;
        self.over = done;
        self.last_reward = r;
        // The horizon cut is terminal, as the ICRA reference treats it (Q7).
        StepOutcome {
            reward: r,
            done,
            truncated: false,
        }
    }
}
