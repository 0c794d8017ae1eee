//! Why a policy directory could not be written or read: one error for every reader and writer
//! of the format (training's `policy/`, export, import, eval, robot, deploy, render). Messages
//! name the file (or the directory, when the description is missing) and what was expected.

use super::architecture::WeightsError;
use super::format::{FORMAT, FORMAT_VERSION, POLICY_FILE};
use std::path::{Path, PathBuf};

/// Why a policy directory could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum PolicyError {
    #[error("{dir}: the run has no policy/{POLICY_FILE} (it was trained by a macdec from before policy files, or has not reached its first checkpoint); rerun its `macdec train` command with a build that writes them")]
    MissingRun { dir: PathBuf },
    #[error("{dir}: has no {POLICY_FILE} (nor manifest.json, the name exports had before format_version 2): not a policy directory")]
    Missing { dir: PathBuf },
    #[error("{dir}: holds {file}, which is not part of a policy directory; choose an empty or new --out directory")]
    NotAPolicyDir { dir: PathBuf, file: String },
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{path}: not a valid policy description: {message}")]
    Parse { path: PathBuf, message: String },
    #[error("{path}: format is `{found}`, expected `{FORMAT}`")]
    Format { path: PathBuf, found: String },
    #[error("{path}: format_version {found} is not one this build reads (1 to {FORMAT_VERSION}); a newer one needs a newer macdec")]
    Version { path: PathBuf, found: u64 },
    #[error("{path}: `{key}`: {reason}")]
    Invalid {
        path: PathBuf,
        key: String,
        reason: String,
    },
    #[error("{path}: the domain cannot be built: {message}")]
    Env { path: PathBuf, message: String },
    #[error("{path}: lists {got} agents, the {env} domain has {expected}")]
    AgentCount {
        path: PathBuf,
        env: String,
        expected: usize,
        got: usize,
    },
    #[error(
        "{path}: agents[{position}] has index {index}; agents must be listed in order 0, 1, ..."
    )]
    AgentIndex {
        path: PathBuf,
        position: usize,
        index: usize,
    },
    #[error("{path}: agent {agent}: `{field}` is {got}, the domain has {expected}")]
    Layout {
        path: PathBuf,
        agent: usize,
        field: &'static str,
        expected: String,
        got: String,
    },
    #[error("{path}: SHA-256 is {got}, {POLICY_FILE} says {expected}; the file is corrupt or from another policy")]
    Checksum {
        path: PathBuf,
        expected: String,
        got: String,
    },
    #[error("{path}: does not match its net entry: {source}")]
    Weights {
        path: PathBuf,
        #[source]
        source: WeightsError,
    },
    #[error("agent {agent} is out of range: the policy has agents 0..{n_agents}")]
    AgentOutOfRange { agent: usize, n_agents: usize },
    #[error("{path}: agent {agent} has no decentralized Q-net in this policy (method {method})")]
    NoAgentNet {
        path: PathBuf,
        agent: usize,
        method: String,
    },
    #[error("agent {agent}'s net is a Q-net: sampling (--sample) needs an actor policy, whose scores are log-probabilities; Q-net policies act greedily")]
    NotAnActor { agent: usize },
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
