//! The runner worker's bookkeeping (`docs/ALGORITHMS.md` §1.2): macro-reward accumulators and the
//! episode being recorded, one record per primitive step.
//!
//! Per step, exactly as the reference worker:
//! `acc_id[i] = r` if agent i had just finished (last v_i = 1) else `acc_id[i] + r`;
//! `acc_joint = r` if some agent had just finished (last vj = 1) else `acc_joint + r`;
//! the record is `(last_obs, executed, acc_id, acc_joint, obs, done, v)` and `last_obs = obs`.
//! So a record with v_i = 1 carries agent i's undiscounted macro-reward r^c_i (quirk Q5), and a
//! record with vj = 1 the joint one since the previous step at which anyone finished.

use super::record::{Episode, Layout, RecordRef};
use super::ReplayError;
use crate::envs::{MacroEnv, StepOutcome};

pub use crate::envs::FirstRecordObs;

/// Accumulators and the growing episode of one training environment.
///
/// Use: after every `env.reset(..)` call [`Recorder::begin_from_env`]; after every `env.step(..)`
/// call [`Recorder::record_from_env`], which returns the finished episode when `done` (the caller
/// pushes it into the replay and resets the env). The raw forms take the values directly.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Recorder {
    layout: Layout,
    first_obs: FirstRecordObs,
    capacity_hint: usize,
    started: bool,
    /// [D] the joint observation before the next step.
    last_obs: Vec<f32>,
    /// [D] scratch for the joint observation after a step.
    next_obs: Vec<f32>,
    last_id_valid: Vec<bool>,
    last_joint_valid: bool,
    /// Accumulated in f64 as the reference does (Python floats), stored as f32.
    acc_id: Vec<f64>,
    acc_joint: f64,
    acc_id_f32: Vec<f32>,
    episode: Episode,
}

impl Recorder {
    /// A recorder for records of `layout`. `capacity_hint` (e.g. the horizon) sizes each new
    /// episode's columns so recording does not reallocate.
    pub fn new(layout: &Layout, first_obs: FirstRecordObs, capacity_hint: usize) -> Self {
        let (n, d) = (layout.n_agents(), layout.joint_obs_size());
        Self {
            layout: layout.clone(),
            first_obs,
            capacity_hint,
            started: false,
            last_obs: vec![0.0; d],
            next_obs: vec![0.0; d],
            last_id_valid: vec![true; n],
            last_joint_valid: true,
            acc_id: vec![0.0; n],
            acc_joint: 0.0,
            acc_id_f32: vec![0.0; n],
            episode: Episode::new(n, d, capacity_hint),
        }
    }

    /// Start an episode from the joint reset observation \[D\]: accumulators to 0, all agents
    /// "just finished" (`docs/ALGORITHMS.md` §1.2 state after reset). Drops any unfinished episode.
    pub fn begin(&mut self, reset_joint_obs: &[f32]) -> Result<(), ReplayError> {
        if reset_joint_obs.len() != self.last_obs.len() {
            return Err(ReplayError::WrongLength {
                what: "reset joint observation",
                expected: self.last_obs.len(),
                got: reset_joint_obs.len(),
            });
        }
        self.last_obs.copy_from_slice(reset_joint_obs);
        self.last_id_valid.fill(true);
        self.last_joint_valid = true;
        self.acc_id.fill(0.0);
        self.acc_joint = 0.0;
        if !self.episode.is_empty() {
            self.episode = self.fresh_episode();
        }
        self.started = true;
        Ok(())
    }

    /// [`Self::begin`] with the observations of an environment that was just reset.
    pub fn begin_from_env<E: MacroEnv + ?Sized>(&mut self, env: &E) -> Result<(), ReplayError> {
        let mut obs = std::mem::take(&mut self.next_obs);
        let result = self.check_env(env).and_then(|()| {
            env.write_joint_obs(&mut obs);
            self.begin(&obs)
        });
        self.next_obs = obs;
        result
    }

    /// Record one primitive step: `executed` \[N\], `next_joint_obs` \[D\], the step's `outcome`
    /// (team reward, episode over, truncated) and v \[N\]. The record's `done` is the terminal
    /// flag the targets mask with: true at a terminal step, false at a horizon cut the domain
    /// truncates (MacroMARL's domains), so the target bootstraps there. Returns the finished
    /// episode when the episode is over (and then expects [`Self::begin`] before the next step).
    pub fn record(
        &mut self,
        executed: &[usize],
        next_joint_obs: &[f32],
        outcome: StepOutcome,
        valid: &[bool],
    ) -> Result<Option<Episode>, ReplayError> {
        let reward = outcome.reward;
        if !self.started {
            return Err(ReplayError::EpisodeNotStarted);
        }
        let n = self.layout.n_agents();
        if executed.len() != n {
            return Err(ReplayError::WrongLength {
                what: "executed actions (one per agent)",
                expected: n,
                got: executed.len(),
            });
        }
        if valid.len() != n {
            return Err(ReplayError::WrongLength {
                what: "valid flags (one per agent)",
                expected: n,
                got: valid.len(),
            });
        }
        if next_joint_obs.len() != self.last_obs.len() {
            return Err(ReplayError::WrongLength {
                what: "next joint observation",
                expected: self.last_obs.len(),
                got: next_joint_obs.len(),
            });
        }
        for i in 0..n {
            self.acc_id[i] = if self.last_id_valid[i] {
                reward
            } else {
                self.acc_id[i] + reward
            };
            self.acc_id_f32[i] = self.acc_id[i] as f32;
        }
        self.last_id_valid.copy_from_slice(valid);
        self.acc_joint = if self.last_joint_valid {
            reward
        } else {
            self.acc_joint + reward
        };
        self.last_joint_valid = valid.iter().any(|&v| v);

        // `docs/ALGORITHMS.md` Q20: the first record may see the post-step observations of agents that finished.
        if self.episode.is_empty() && self.first_obs == FirstRecordObs::OverwrittenByFirstStep {
            for (i, &v) in valid.iter().enumerate() {
                if v {
                    let range = self.layout.obs_range(i);
                    self.last_obs[range.clone()].copy_from_slice(&next_joint_obs[range]);
                }
            }
        }
        self.episode.push(RecordRef {
            obs: &self.last_obs,
            executed,
            acc_id: &self.acc_id_f32,
            acc_joint: self.acc_joint as f32,
            next_obs: next_joint_obs,
            done: outcome.terminal(),
            valid,
        })?;
        self.last_obs.copy_from_slice(next_joint_obs);

        if outcome.done {
            self.started = false;
            let fresh = self.fresh_episode();
            Ok(Some(std::mem::replace(&mut self.episode, fresh)))
        } else {
            Ok(None)
        }
    }

    /// [`Self::record`] with the outputs of `env.step(..)`: `outcome` plus the env's executed
    /// actions, held observations and `mac_done` flags.
    pub fn record_from_env<E: MacroEnv + ?Sized>(
        &mut self,
        env: &E,
        outcome: StepOutcome,
    ) -> Result<Option<Episode>, ReplayError> {
        self.check_env(env)?;
        let mut obs = std::mem::take(&mut self.next_obs);
        env.write_joint_obs(&mut obs);
        let result = self.record(env.executed(), &obs, outcome, env.mac_done());
        self.next_obs = obs;
        result
    }

    /// Current per-agent accumulators (f64, as accumulated).
    pub fn acc_id(&self) -> &[f64] {
        &self.acc_id
    }
    /// Current joint accumulator.
    pub fn acc_joint(&self) -> f64 {
        self.acc_joint
    }
    /// The records of the episode so far.
    pub fn episode(&self) -> &Episode {
        &self.episode
    }
    /// The layout this recorder was built for.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    fn fresh_episode(&self) -> Episode {
        Episode::new(
            self.layout.n_agents(),
            self.layout.joint_obs_size(),
            self.capacity_hint,
        )
    }

    fn check_env<E: MacroEnv + ?Sized>(&self, env: &E) -> Result<(), ReplayError> {
        if env.obs_sizes() != self.layout.obs_sizes() || env.n_agents() != self.layout.n_agents() {
            return Err(ReplayError::LayoutMismatch {
                n_agents: env.n_agents(),
                joint_obs: env.joint_obs_size(),
                expected_agents: self.layout.n_agents(),
                expected_obs: self.layout.joint_obs_size(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::envs::{EnvError, EnvRng};

    /// A scripted 2-agent env with 1-float observations: step k returns the k-th scripted
    /// (executed, reward, mac_done, done); a finished agent's observation becomes 10 * k + agent,
    /// a busy agent's observation is held. Reset observation: [-1, -2]. It reports `first` as
    /// its [`MacroEnv::first_record_obs`].
    pub(crate) struct FakeEnv {
        pub(crate) first: FirstRecordObs,
        script: Vec<([usize; 2], f64, [bool; 2], bool)>,
        k: usize,
        obs: [[f32; 1]; 2],
        executed: [usize; 2],
        mac_done: [bool; 2],
    }

    impl FakeEnv {
        pub(crate) fn new(script: Vec<([usize; 2], f64, [bool; 2], bool)>) -> Self {
            Self {
                first: FirstRecordObs::Reset,
                script,
                k: 0,
                obs: [[-1.0], [-2.0]],
                executed: [0, 0],
                mac_done: [true, true],
            }
        }
    }

    impl MacroEnv for FakeEnv {
        fn n_agents(&self) -> usize {
            2
        }
        fn obs_sizes(&self) -> &[usize] {
            &[1, 1]
        }
        fn n_actions(&self) -> &[usize] {
            &[3, 3]
        }
        fn action_names(&self, _agent: usize) -> &'static [&'static str] {
            &["a", "b", "c"]
        }
        fn obs_names(&self, _agent: usize) -> Vec<String> {
            vec!["x".into()]
        }
        fn horizon(&self) -> usize {
            self.script.len()
        }
        fn reset(&mut self, _rng: &mut EnvRng) {
            self.k = 0;
            self.obs = [[-1.0], [-2.0]];
            self.mac_done = [true, true];
        }
        fn step(&mut self, _actions: &[usize], _rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
            let (executed, reward, mac_done, done) = self.script[self.k];
            self.k += 1;
            self.executed = executed;
            self.mac_done = mac_done;
            for (i, &fin) in mac_done.iter().enumerate() {
                if fin {
                    self.obs[i] = [(10 * self.k + i) as f32];
                }
            }
            Ok(StepOutcome {
                reward,
                done,
                truncated: false,
            })
        }
        fn obs(&self, agent: usize) -> &[f32] {
            &self.obs[agent]
        }
        fn executed(&self) -> &[usize] {
            &self.executed
        }
        fn mac_done(&self) -> &[bool] {
            &self.mac_done
        }
        fn t(&self) -> usize {
            self.k
        }
        fn render_ascii(&self) -> String {
            String::new()
        }
        fn first_record_obs(&self) -> FirstRecordObs {
            self.first
        }
    }

    pub(crate) fn script() -> Vec<([usize; 2], f64, [bool; 2], bool)> {
        vec![
            ([1, 2], -1.0, [false, false], false), // step 1: both busy
            ([1, 2], -1.0, [true, false], false),  // step 2: agent 0 finishes (2 steps, -2)
            ([0, 2], 5.0, [false, false], false),  // step 3
            ([0, 2], -1.0, [true, true], false),   // step 4: both finish (a0: 4, a1: 2)
            ([2, 1], 3.0, [true, false], true),    // step 5: a0 finishes, a1 truncated
        ]
    }

    fn run(first_obs: FirstRecordObs, script: Vec<([usize; 2], f64, [bool; 2], bool)>) -> Episode {
        let mut rng = <EnvRng as rand::SeedableRng>::seed_from_u64(0);
        let mut env = FakeEnv::new(script);
        let layout = Layout::of_env(&env).unwrap();
        let mut rec = Recorder::new(&layout, first_obs, env.horizon());
        env.reset(&mut rng);
        rec.begin_from_env(&env).unwrap();
        loop {
            let outcome = env.step(&[0, 0], &mut rng).unwrap();
            if let Some(ep) = rec.record_from_env(&env, outcome).unwrap() {
                return ep;
            }
        }
    }

    #[test]
    fn accumulators_sum_rewards_over_each_macro_action() {
        let ep = run(FirstRecordObs::Reset, script());
        assert_eq!(ep.len(), 5);
        let acc_id: Vec<[f32; 2]> = (0..5).map(|t| [ep.acc_id(t)[0], ep.acc_id(t)[1]]).collect();
        // agent 0: -1, -2 (finish), 5, 4 (finish), 3 (finish, new macro-action started at step 5)
        // agent 1: -1, -2, 3, 2 (finish), 3 (restarted after its finish at step 4; truncated)
        assert_eq!(
            acc_id,
            vec![
                [-1.0, -1.0],
                [-2.0, -2.0],
                [5.0, 3.0],
                [4.0, 2.0],
                [3.0, 3.0]
            ]
        );
        // joint: restarts after any finish: -1, -2 (vj), 5, 4 (vj), 3 (vj)
        let acc_joint: Vec<f32> = (0..5).map(|t| ep.acc_joint(t)).collect();
        assert_eq!(acc_joint, vec![-1.0, -2.0, 5.0, 4.0, 3.0]);
        assert!((0..4).all(|t| !ep.done(t)) && ep.done(4));
        assert_eq!(ep.executed(2), &[0, 2]);
        assert_eq!(
            (0..5).map(|t| ep.vj(t)).collect::<Vec<_>>(),
            [false, true, false, true, true]
        );
    }

    #[test]
    fn records_chain_observations_and_hold_busy_agents() {
        let ep = run(FirstRecordObs::Reset, script());
        assert_eq!(ep.obs(0), &[-1.0, -2.0]); // reset observation
        assert_eq!(ep.next_obs(0), &[-1.0, -2.0]); // nobody finished at step 1
        assert_eq!(ep.next_obs(1), &[20.0, -2.0]); // agent 0 finished at step 2
        for t in 1..5 {
            assert_eq!(ep.obs(t), ep.next_obs(t - 1));
        }
        assert_eq!(ep.next_obs(3), &[40.0, 41.0]);
    }

    #[test]
    fn first_record_obs_is_overwritten_only_under_the_warehouse_quirk() {
        let mut s = script();
        s[0].2 = [true, false]; // agent 0 finishes at step 1: obs becomes 10
        let faithful = run(FirstRecordObs::OverwrittenByFirstStep, s.clone());
        assert_eq!(faithful.obs(0), &[10.0, -2.0]);
        assert_eq!(faithful.obs(1), &[10.0, -2.0]);
        let fixed = run(FirstRecordObs::Reset, s);
        assert_eq!(fixed.obs(0), &[-1.0, -2.0]);
        // later records are unaffected
        assert_eq!(faithful.obs(2), fixed.obs(2));
    }

    #[test]
    fn recorder_restarts_cleanly_after_done() {
        let mut rng = <EnvRng as rand::SeedableRng>::seed_from_u64(0);
        let mut env = FakeEnv::new(script());
        let layout = Layout::of_env(&env).unwrap();
        let mut rec = Recorder::new(&layout, FirstRecordObs::Reset, 5);
        env.reset(&mut rng);
        rec.begin_from_env(&env).unwrap();
        let mut first = None;
        while first.is_none() {
            let outcome = env.step(&[0, 0], &mut rng).unwrap();
            first = rec.record_from_env(&env, outcome).unwrap();
        }
        // stepping on without begin is refused
        assert_eq!(
            rec.record(
                &[0, 0],
                &[0.0, 0.0],
                StepOutcome::running(1.0),
                &[true, true]
            ),
            Err(ReplayError::EpisodeNotStarted)
        );
        env.reset(&mut rng);
        rec.begin_from_env(&env).unwrap();
        assert_eq!(rec.acc_joint(), 0.0);
        let second = loop {
            let outcome = env.step(&[0, 0], &mut rng).unwrap();
            if let Some(ep) = rec.record_from_env(&env, outcome).unwrap() {
                break ep;
            }
        };
        assert_eq!(first.unwrap(), second);
    }

    #[test]
    fn a_truncated_end_finishes_the_episode_without_a_terminal_record() {
        let layout = Layout::new(&[1, 1], &[2, 2]).unwrap();
        let mut rec = Recorder::new(&layout, FirstRecordObs::Reset, 4);
        let step = |rec: &mut Recorder, outcome| {
            rec.record(&[0, 0], &[0.0, 0.0], outcome, &[true, true])
                .unwrap()
        };
        rec.begin(&[0.0, 0.0]).unwrap();
        assert!(step(&mut rec, StepOutcome::running(1.0)).is_none());
        let cut = step(&mut rec, StepOutcome::ended(1.0, false)).unwrap();
        assert_eq!((cut.len(), cut.done(1)), (2, false));
        rec.begin(&[0.0, 0.0]).unwrap();
        let terminal = step(&mut rec, StepOutcome::ended(1.0, true)).unwrap();
        assert!(terminal.done(0));
    }

    #[test]
    fn record_refuses_wrong_widths() {
        let layout = Layout::new(&[1, 1], &[2, 2]).unwrap();
        let mut rec = Recorder::new(&layout, FirstRecordObs::Reset, 4);
        assert!(rec.begin(&[0.0]).is_err());
        rec.begin(&[0.0, 0.0]).unwrap();
        assert!(rec
            .record(&[0, 0], &[0.0, 0.0], StepOutcome::running(1.0), &[true])
            .is_err());
        assert!(rec
            .record(&[0], &[0.0, 0.0], StepOutcome::running(1.0), &[true, true])
            .is_err());
    }
}
