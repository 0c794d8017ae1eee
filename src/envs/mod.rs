//! Macro-action multi-agent domains: the ICRA paper's Box Pushing and Warehouse Tool Delivery,
//! and MacroMARL's (`bp_ma_v0`, the Warehouse A-E of `osd`, `overcooked`), each in its folder and
//! listed once in [`built_in`].
//!
//! All follow the references' step contract (`docs/ALGORITHMS.md` §1.1): an agent picks a new
//! macro-action only when its previous one finished; the value passed for a busy agent is ignored;
//! the executed macro-actions, the held macro-observations, one shared team reward, the episode-done
//! flag and the per-agent macro-action-done flags come back from every primitive step.
//!
//! Stepping allocates nothing: observations live in buffers owned by the environment and are read
//! through [`MacroEnv::obs`].

use rand_chacha::ChaCha8Rng;

pub mod acac;
pub mod bench;
pub mod box_pushing;
pub mod bp_ma_v0;
pub mod built_in;
pub mod custom_env;
pub mod domain;
pub mod macromarl;
pub mod osd;
pub mod overcooked;
pub mod overcooked_acac;
pub mod overcooked_large;
pub mod registry;
pub mod replay;
pub mod shape;
pub mod spec;
pub mod warehouse;

pub use built_in::AnyEnv;
pub use domain::Domain;
pub use shape::EnvShape;
pub use spec::EnvSpec;

/// The random stream an environment draws from (Warehouse's optional movement noise). Owned by the
/// caller, so a checkpoint can save it and a run derives it from its seed (`docs/ALGORITHMS.md` §8).
pub type EnvRng = ChaCha8Rng;

/// Why an environment refused its input. Messages name the offending value and the allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EnvError {
    /// A free agent was given a macro-action it does not have.
    #[error("agent {agent}: macro-action {action} is out of range 0..{n_actions}")]
    ActionOutOfRange {
        /// The agent.
        agent: usize,
        /// The index given.
        action: usize,
        /// Macro-actions the agent has.
        n_actions: usize,
    },
    /// The joint action has the wrong number of entries.
    #[error("expected one action per agent ({expected}), got {got}")]
    WrongActionCount {
        /// Agents in the domain.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// `step` after the episode ended, without a `reset`.
    #[error("step called after the episode ended; call reset first")]
    EpisodeOver,
    /// A parameter out of its range.
    #[error("invalid environment parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// Its range, or why the value is refused.
        reason: String,
    },
    /// A domain config key that is unknown or has a bad value.
    #[error("invalid domain key `{key}`: {reason}")]
    InvalidKey {
        /// The key, as written.
        key: String,
        /// Why it is refused.
        reason: String,
    },
}

/// What one primitive step returns besides the observations (read them with [`MacroEnv::obs`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// The shared team reward of this primitive step (f64 so sums match the reference bit for bit).
    pub reward: f64,
    /// Episode over: a terminal state or the horizon.
    pub done: bool,
    /// The episode was cut by the horizon in a state that is not terminal, so a learner should
    /// bootstrap from it (MacroMARL's runner). Only meaningful with `done`. The ICRA domains
    /// never set it: their reference treats the horizon cut as terminal (quirk Q7), so each
    /// domain says which way its reference goes.
    pub truncated: bool,
}

impl StepOutcome {
    /// A step that did not end the episode.
    pub fn running(reward: f64) -> Self {
        Self {
            reward,
            done: false,
            truncated: false,
        }
    }

    /// A step after which the episode is over: `terminal` (a real terminal state, or a
    /// horizon the domain's reference treats as one) or else cut by the horizon (truncated).
    pub fn ended(reward: f64, terminal: bool) -> Self {
        Self {
            reward,
            done: true,
            truncated: !terminal,
        }
    }

    /// The episode ended in a terminal state (not a time-limit cut).
    pub fn terminal(&self) -> bool {
        self.done && !self.truncated
    }
}

/// What the first record of an episode holds as its "before" observation (quirk Q20).
///
/// The reference Warehouse env hands out its own held-observation list from `reset()` and the
/// first `step()` overwrites the entries of the agents that finished in that step (warehouse.md
/// Q10); the worker builds the first record after the step, so those agents' entries of the first
/// record's `obs` are their post-step observations. Box Pushing rebinds its list instead, so its
/// first record holds the true reset observation.
///
/// Under the paper's settings the two choices give the same numbers: only the Fetch can finish at
/// step 1 (Wait), and its observation after that step equals its reset observation (no tool
/// staged, no Turtlebot beside the table yet). The switch keeps the port exact anyway.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum FirstRecordObs {
    /// The observation returned by reset (Box Pushing; the fixed behaviour for Warehouse).
    #[default]
    Reset,
    /// Agents that finished at step 1 show their post-step observation (Warehouse, faithful).
    OverwrittenByFirstStep,
}

/// A macro-action multi-agent domain with the reference's step contract.
///
/// This is the public trait a new domain implements to be trained by every method
/// ([`crate::train`]): the step contract below plus what the learner and the plots need to know
/// about the domain. Nothing else in the crate matches on a domain's name to learn these.
///
/// # The contract
///
/// - **Time.** An episode is a sequence of primitive steps. [`Self::reset`] starts one (t = 0,
///   every agent free, [`Self::mac_done`] all true, [`Self::executed`] unspecified);
///   [`Self::step`] advances it by exactly one primitive step and [`Self::t`] counts them.
/// - **Macro-actions.** Agent i is *free* when its previous macro-action finished (after reset,
///   every agent is). At each step the caller passes one action per agent; the entry of a free
///   agent starts that macro-action (an out-of-range one is [`EnvError::ActionOutOfRange`] and
///   the step changes nothing), the entry of a busy agent is ignored and may hold any value. A
///   macro-action may last one step or many; its duration is the domain's business.
/// - **After a step**, [`Self::executed`]`[i]` is the macro-action agent i ran during it (the
///   one it started now, or the one it keeps running), and [`Self::mac_done`]`[i]` says whether
///   that macro-action *ended at this step*: agent i is then free at the next step
///   ([`Self::is_free`]). Learners build their macro-level transitions from exactly these flags:
///   a macro-action starts at the step after a `mac_done` of its agent and ends at the next one.
/// - **Observations are held.** [`Self::obs`]`(i)` is agent i's macro-observation: it must
///   change only at steps where `mac_done[i]` is true (and at reset), because agent i perceives
///   only when its macro-action ends; in between it keeps the observation it last received.
///   What a decentralized policy sees is exactly this slice, so nothing else of the state may
///   leak into it. Sizes are fixed ([`Self::obs_sizes`]).
/// - **Reward** ([`StepOutcome::reward`]) is one shared team reward per primitive step; the
///   learners sum it over a macro-action themselves.
/// - **Episode end.** [`StepOutcome::done`] is true on the step the episode ends: a terminal
///   state, or the horizon ([`Self::horizon`] primitive steps, which the domain enforces). A
///   horizon cut sets [`StepOutcome::truncated`] where the domain's reference bootstraps from it
///   (MacroMARL's domains); the ICRA domains treat it as terminal (quirk Q7). At `done`, every agent's
///   macro-action counts as ended for its final transition only if `mac_done` says so; an
///   unfinished one is dropped by the learners (`docs/ALGORITHMS.md` Q6). After `done`, [`Self::step`] is
///   [`EnvError::EpisodeOver`] until [`Self::reset`].
/// - **Randomness** comes only from the `rng` passed in, so a run is reproducible from its seed
///   and a checkpoint can hold the stream. A domain that draws nothing should say so through
///   [`Self::deterministic`].
/// - **Stepping should not allocate**: observations live in buffers the domain owns.
///
/// The optional methods: [`Self::first_record_obs`] says what the first record of an episode
/// holds as its "before" observation ([`FirstRecordObs::Reset`], the observation reset handed
/// out, for any domain whose first step does not rewrite that list in place);
/// [`Self::deterministic`] (default true) lets evaluation run one greedy episode instead of
/// `eval_num_epi`, so it must be false if any step draws from the rng;
/// [`Self::optimal_return`] is the best return under a per-step discount where it is known (the
/// plots' optimal line); [`Self::describe`] titles figures; [`Self::draw`] is the picture
/// `macdec render` animates. A domain implementing this trait correctly needs nothing else from
/// `src/` to train with every method; to get the whole command line (configs, runs, plots,
/// export, ...) it also implements [`domain::Domain`].
pub trait MacroEnv {
    /// Number of agents (Box Pushing 2, Warehouse 3, Overcooked 2 or 3).
    fn n_agents(&self) -> usize;
    /// Size of each agent's macro-observation, in agent order.
    fn obs_sizes(&self) -> &[usize];
    /// Number of macro-actions of each agent, in agent order.
    fn n_actions(&self) -> &[usize];
    /// Names of agent `agent`'s macro-actions, indexed by action. Panics if `agent` is out of range.
    fn action_names(&self, agent: usize) -> &'static [&'static str];
    /// Names of the elements of agent `agent`'s observation, in layout order (for exported
    /// policies and replays). Panics if `agent` is out of range.
    fn obs_names(&self, agent: usize) -> Vec<String>;
    /// The horizon in primitive steps.
    fn horizon(&self) -> usize;

    /// Start a new episode; every agent is free afterwards.
    fn reset(&mut self, rng: &mut EnvRng);
    /// One primitive step. `actions[i]` is used only if agent i is free (see [`Self::is_free`]);
    /// a busy agent's entry is ignored and may hold any value.
    fn step(&mut self, actions: &[usize], rng: &mut EnvRng) -> Result<StepOutcome, EnvError>;

    /// Agent `agent`'s current (held) macro-observation. Panics if `agent` is out of range.
    fn obs(&self, agent: usize) -> &[f32];
    /// The macro-action each agent executed in the last step.
    fn executed(&self) -> &[usize];
    /// Whether each agent's macro-action finished in the last step (all true after reset).
    fn mac_done(&self) -> &[bool];
    /// Whether agent `agent` picks a new macro-action at the next step.
    fn is_free(&self, agent: usize) -> bool {
        self.mac_done()[agent]
    }
    /// Primitive steps taken since reset.
    fn t(&self) -> usize;

    /// A human-readable picture of the state, for debugging and `--verbose` replays.
    fn render_ascii(&self) -> String;

    /// What the recorder stores as the first record's "before" observation (quirk Q20). Most
    /// domains hand out a fresh reset observation: [`FirstRecordObs::Reset`].
    fn first_record_obs(&self) -> FirstRecordObs {
        FirstRecordObs::Reset
    }
    /// Whether a greedy episode from reset always gives the same return (no randomness in the
    /// dynamics), so an evaluation runs one episode instead of `eval_num_epi`.
    fn deterministic(&self) -> bool {
        true
    }
    /// The best achievable return under `discount` (per primitive step, as evaluation discounts)
    /// when it is known; the plots draw it as the optimal line. `None` draws no line.
    fn optimal_return(&self, discount: f64) -> Option<f64> {
        let _ = discount;
        None
    }
    /// A short description for figure titles, e.g. "Box Pushing 10x10, horizon 100".
    fn describe(&self) -> String {
        format!("{} agents, horizon {}", self.n_agents(), self.horizon())
    }
    /// A picture of the current state for `macdec render` (which adds the status bar below
    /// it), drawn with [`crate::draw`]; `None` (the default) when the domain draws none.
    fn draw(&self) -> Option<crate::draw::Picture> {
        None
    }

    /// Length of the global state vector ([`Self::write_state`]), the input of centralized
    /// state critics (MacroMARL's `get_state()`); 0 (the default) when the domain has none.
    fn state_size(&self) -> usize {
        0
    }
    /// Write the current global state into `out`, which must have length [`Self::state_size`]
    /// (the default writes nothing, for a domain without a state).
    fn write_state(&self, out: &mut [f32]) {
        assert!(out.is_empty(), "this domain has no global state");
    }

    /// Total joint observation size (sum of the agents' sizes), the centralized nets' input.
    fn joint_obs_size(&self) -> usize {
        self.obs_sizes().iter().sum()
    }
    /// Number of joint macro-actions (product of the agents' counts), the centralized nets' output.
    fn n_joint_actions(&self) -> usize {
        self.n_actions().iter().product()
    }
    /// Write the joint observation (agents' observations concatenated in agent order) into `out`,
    /// which must have length [`Self::joint_obs_size`] (panics otherwise).
    fn write_joint_obs(&self, out: &mut [f32]) {
        let mut at = 0;
        for agent in 0..self.n_agents() {
            let o = self.obs(agent);
            out[at..at + o.len()].copy_from_slice(o);
            at += o.len();
        }
        assert_eq!(
            at,
            out.len(),
            "joint observation buffer has the wrong length"
        );
    }
}
