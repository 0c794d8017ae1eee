//! Why a policy directory could not be written or read: one error for every reader and writer
//! of the format (training's `policy/`, export, import, eval, robot, deploy, render). Messages
//! name the file (or the directory, when the description is missing) and what was expected.

use super::architecture::WeightsError;
use super::format::{FORMAT, FORMAT_VERSION, POLICY_FILE};
use std::path::{Path, PathBuf};

/// Why a policy directory could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum PolicyError {
    /// A training run directory without `policy/` (older build, or no checkpoint yet).
    #[error("{dir}: the run has no policy/{POLICY_FILE}: it was trained by a macdec from before policy files (rerun its `macdec train` command), or has not reached its first checkpoint")]
    MissingRun {
        /// The run directory.
        dir: PathBuf,
    },
    /// A directory that holds no policy description.
    #[error("{dir}: has no {POLICY_FILE} (nor manifest.json, the name exports had before format_version 2): not a policy directory")]
    Missing {
        /// The directory that was read.
        dir: PathBuf,
    },
    /// A directory to be replaced by a policy directory holds something else.
    #[error("{dir}: holds {file}, which is not part of a policy directory; choose an empty or new --out directory")]
    NotAPolicyDir {
        /// The directory.
        dir: PathBuf,
        /// The first entry that is not a policy directory's regular file.
        file: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error, as text.
        message: String,
    },
    /// The policy description is not valid JSON of the expected shape.
    #[error("{path}: not a valid policy description: {message}")]
    Parse {
        /// The description file.
        path: PathBuf,
        /// The parser's reason.
        message: String,
    },
    /// The description's `format` names another format.
    #[error("{path}: format is `{found}`, expected `{FORMAT}`")]
    Format {
        /// The description file.
        path: PathBuf,
        /// The `format` it holds.
        found: String,
    },
    /// The description's `format_version` is newer (or older) than this build reads.
    #[error("{path}: format_version {found} is not one this build reads (1 to {FORMAT_VERSION}); a newer one needs a newer macdec")]
    Version {
        /// The description file.
        path: PathBuf,
        /// The `format_version` it holds.
        found: u64,
    },
    /// A key holds a value the format does not allow.
    #[error("{path}: `{key}`: {reason}")]
    Invalid {
        /// The description file.
        path: PathBuf,
        /// The offending key.
        key: String,
        /// What was wrong and what was expected.
        reason: String,
    },
    /// The described domain could not be built from its config.
    #[error("{path}: the domain cannot be built: {message}")]
    Env {
        /// The description file.
        path: PathBuf,
        /// The domain's reason.
        message: String,
    },
    /// The description lists a different number of agents than the domain has.
    #[error("{path}: lists {got} agents, the {env} domain has {expected}")]
    AgentCount {
        /// The description file.
        path: PathBuf,
        /// The domain's name.
        env: String,
        /// Agents the domain has.
        expected: usize,
        /// Agents the description lists.
        got: usize,
    },
    /// Agents are not listed in index order.
    #[error(
        "{path}: agents[{position}] has index {index}; agents must be listed in order 0, 1, ..."
    )]
    AgentIndex {
        /// The description file.
        path: PathBuf,
        /// Position in the `agents` list.
        position: usize,
        /// Index found at that position.
        index: usize,
    },
    /// An agent's net does not fit the domain (observation or action count).
    #[error("{path}: agent {agent}: `{field}` is {got}, the domain has {expected}")]
    Layout {
        /// The description file.
        path: PathBuf,
        /// Agent index.
        agent: usize,
        /// The mismatched key, e.g. `obs_dim`.
        field: &'static str,
        /// What the domain has.
        expected: String,
        /// What the description says.
        got: String,
    },
    /// A weights file's SHA-256 differs from the one recorded in the description.
    #[error("{path}: SHA-256 is {got}, {POLICY_FILE} says {expected}; the file is corrupt or from another policy")]
    Checksum {
        /// The weights file.
        path: PathBuf,
        /// Hex digest the description records.
        expected: String,
        /// Hex digest of the file on disk.
        got: String,
    },
    /// A weights file does not hold the tensors its net entry declares.
    #[error("{path}: does not match its net entry: {source}")]
    Weights {
        /// The weights file.
        path: PathBuf,
        /// What was missing or misshapen.
        #[source]
        source: WeightsError,
    },
    /// An agent index beyond the policy's agents.
    #[error("agent {agent} is out of range: the policy has agents 0..{n_agents}")]
    AgentOutOfRange {
        /// Agent index asked for.
        agent: usize,
        /// Agents the policy has.
        n_agents: usize,
    },
    /// The policy has no net of this agent's own: it acts only through a centralized net (or
    /// holds none for the agent), so no robot can serve the agent.
    #[error("{path}: agent {agent} has no decentralized net in this policy (method {method}){}", acts_centrally(*.centralized))]
    NoAgentNet {
        /// The description file.
        path: PathBuf,
        /// Agent index asked for.
        agent: usize,
        /// The policy's method name.
        method: String,
        /// What the policy's centralized net is (`centralized Q-net`, `centralized actor`), if
        /// it has one.
        centralized: Option<&'static str>,
    },
    /// A centralized net was asked of a policy without one.
    #[error("the policy has no centralized net (method {method})")]
    NoCentralNet {
        /// The policy's method name.
        method: String,
    },
    /// Sampling was asked of a Q-net policy, which only acts greedily.
    #[error("{whose} is a Q-net: sampling (--sample) needs an actor policy, whose scores are log-probabilities; Q-net policies act greedily")]
    NotAnActor {
        /// Whose net it is: `agent 0's net`, `the centralized net`.
        whose: String,
    },
}

/// Why a policy with only a centralized net cannot be served agent by agent, or nothing.
fn acts_centrally(centralized: Option<&'static str>) -> String {
    match centralized {
        Some(net) => format!(
            ": it acts only through its {net}, which reads every agent's observation and picks the team's joint macro-action, so no robot can serve one agent of it; run it centrally with `macdec eval --policy DIR`"
        ),
        None => String::new(),
    }
}

impl PolicyError {
    pub(crate) fn io(path: &Path, e: impl std::fmt::Display) -> PolicyError {
        PolicyError::Io {
            path: path.to_path_buf(),
            message: e.to_string(),
        }
    }

    pub(crate) fn invalid(
        path: &Path,
        key: impl Into<String>,
        reason: impl Into<String>,
    ) -> PolicyError {
        PolicyError::Invalid {
            path: path.to_path_buf(),
            key: key.into(),
            reason: reason.into(),
        }
    }
}
