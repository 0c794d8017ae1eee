//! `macdec export`: turn a trained run directory into a policy directory for robots (issue 7):
//! the run's `policy/` files (issue 11; written with every checkpoint) in the same format,
//! holding each agent's decentralized net only (a Q-net or an actor, as `agent-<i>.safetensors`)
//! beside the layout,
//! domain and run. Reads nothing of the trainer: no checkpoint, no learner types. [`export_nets`] writes
//! the same directory from plain nets and any [`MacroEnv`], for domains defined outside this
//! binary (the library's `TrainedPolicy::export`).

use crate::envs::MacroEnv;
use crate::nn::QNet;
use crate::policy_files::legacy::MANIFEST_FILE_V1;
use crate::policy_files::{
    weights_file_name, AgentLayout, Manifest, NetFile, NetRole, PolicyEnv, PolicyError, RunInfo,
    POLICY_DIR, POLICY_FILE,
};
use std::path::{Path, PathBuf};

/// Why a run could not be exported.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// Reading the run's policy or writing the export failed.
    #[error(transparent)]
    Policy(#[from] PolicyError),
    /// The run's method has only centralized nets (e.g. Cen-DDRQN), which no single robot can run.
    #[error("{dir}: the run trained {method}, which has no decentralized nets to put on robots (export a dec-hddrqn, our1, our1-r, our2 run or a decentralized actor-critic run)")]
    NotDecentralized {
        /// The run directory.
        dir: PathBuf,
        /// The method's name.
        method: String,
    },
    /// The output directory holds a file an export does not write.
    #[error("{dir}: holds {file}, which is not part of a policy export; choose an empty or new --out directory")]
    NotAPolicyDir {
        /// The output directory.
        dir: PathBuf,
        /// The first such file.
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
    /// The run has a different number of decentralized nets than the domain has agents.
    #[error("{dir}: {got} decentralized net(s) for a domain of {expected} agent(s)")]
    NetCount {
        /// The run directory.
        dir: PathBuf,
        /// Agents in the domain.
        expected: usize,
        /// Decentralized nets found.
        got: usize,
    },
}

/// Whether `name` is a file an export writes or wrote before format_version 2 (or its
/// atomic-write temp file).
fn is_export_file(name: &str) -> bool {
    let name = name.strip_prefix('.').unwrap_or(name);
    let base = name.split(".safetensors").next().unwrap_or(name);
    [POLICY_FILE, MANIFEST_FILE_V1]
        .iter()
        .any(|f| name == *f || name.starts_with(&format!("{f}.")))
        || (base.starts_with("agent-")
            && base[6..].chars().all(|c| c.is_ascii_digit())
            && name.contains(".safetensors"))
}

/// Check that `out` is new, empty, or an earlier export (only its files), so exporting over it
/// never mixes with or deletes someone else's files. Returns the earlier export's files.
fn previous_export_files(out: &Path) -> Result<Vec<PathBuf>, ExportError> {
    let io = |e: std::io::Error| ExportError::Io {
        path: out.to_path_buf(),
        message: e.to_string(),
    };
    let entries = match std::fs::read_dir(out) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        other => other.map_err(io)?,
    };
    let mut files = Vec::new();
    for entry in entries {
        let entry = entry.map_err(io)?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if !is_export_file(&name) || !entry.file_type().map_err(io)?.is_file() {
            return Err(ExportError::NotAPolicyDir {
                dir: out.to_path_buf(),
                file: name,
            });
        }
        files.push(entry.path());
    }
    Ok(files)
}

/// Export the run in `run_dir` (its `policy/` files of any format version, see
/// [`crate::policy_files`]; never its checkpoint) to the policy directory `out`: the same
/// format, holding only each agent's decentralized net (a Q-net, or an actor-critic run's
/// actor), its bytes copied as verified. The nets are exported as the last checkpoint wrote
/// them: a run still training exports its current nets (`episodes_trained` says how far it
/// got).
pub fn export_run(run_dir: &Path, out: &Path) -> Result<Manifest, ExportError> {
    let previous = previous_export_files(out)?;
    let dir = run_dir.join(POLICY_DIR);
    if !dir.join(POLICY_FILE).exists() {
        return Err(PolicyError::MissingRun {
            dir: run_dir.to_path_buf(),
        }
        .into());
    }
    let m = Manifest::read(&dir)?;
    let mut files = Vec::with_capacity(m.agents.len());
    for agent in 0..m.agents.len() {
        let verified = match m.verify_agent(&dir, agent) {
            Ok(v) => v,
            Err(PolicyError::NoAgentNet { .. }) => {
                return Err(ExportError::NotDecentralized {
                    dir: run_dir.to_path_buf(),
                    method: m.run.method,
                })
            }
            Err(e) => return Err(e.into()),
        };
        // The weights must build the net their entry describes, whatever its kind.
        m.agent_acting_net(&verified)?;
        let entry = &m.nets[m.agent_net(agent)?];
        files.push(NetFile {
            kind: entry.kind,
            role: NetRole::Dec,
            agent: Some(agent),
            file: weights_file_name(agent),
            input: entry.input,
            output: entry.output,
            architecture: entry.architecture.clone(),
            bytes: verified.weights,
        });
    }
    write_files(out, previous, m.env, m.agents, m.discount, m.run, files)
}

/// Write agent i's decentralized net `nets[i]` of a policy trained on `domain` (any
/// [`MacroEnv`]; its layout goes into `policy.json`) to the policy directory `out`, naming the
/// domain `env` (built-in, or [`PolicyEnv::custom`]). `out` must be new, empty or an earlier
/// export, as for [`export_run`].
pub fn export_nets(
    out: &Path,
    env: PolicyEnv,
    domain: &impl MacroEnv,
    discount: f64,
    run: RunInfo,
    nets: &[&QNet],
) -> Result<Manifest, ExportError> {
    let previous = previous_export_files(out)?;
    if nets.is_empty() {
        return Err(ExportError::NotDecentralized {
            dir: out.to_path_buf(),
            method: run.method,
        });
    }
    if nets.len() != domain.n_agents() {
        return Err(ExportError::NetCount {
            dir: out.to_path_buf(),
            expected: domain.n_agents(),
            got: nets.len(),
        });
    }
    let agents = AgentLayout::of_domain(domain);
    let files: Vec<NetFile> = nets
        .iter()
        .enumerate()
        .map(|(i, n)| NetFile::qnet(NetRole::Dec, Some(i), weights_file_name(i), n))
        .collect();
    write_files(out, previous, env, agents, discount, run, files)
}

/// Write the policy directory (agent i's net as `agent-<i>.safetensors`) and remove what an
/// earlier export there (`previous`) left that the new description no longer names.
fn write_files(
    out: &Path,
    previous: Vec<PathBuf>,
    env: PolicyEnv,
    agents: Vec<AgentLayout>,
    discount: f64,
    run: RunInfo,
    files: Vec<NetFile>,
) -> Result<Manifest, ExportError> {
    let manifest = Manifest::write_new(out, env, agents, discount, NetRole::Dec, run, &files)?;
    // An earlier export with more agents, or of format_version 1 (manifest.json), would leave
    // files the new description no longer names.
    let current: Vec<PathBuf> = std::iter::once(out.join(POLICY_FILE))
        .chain(manifest.nets.iter().map(|n| out.join(&n.file)))
        .collect();
    for stale in previous.iter().filter(|p| !current.contains(p)) {
        std::fs::remove_file(stale).map_err(|e| ExportError::Io {
            path: stale.clone(),
            message: e.to_string(),
        })?;
    }
    Ok(manifest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_new_empty_or_earlier_export_directories_are_written_over() {
        let dir = tempfile::tempdir().unwrap();
        assert!(previous_export_files(&dir.path().join("new"))
            .unwrap()
            .is_empty());
        assert!(previous_export_files(dir.path()).unwrap().is_empty());
        for f in [
            "policy.json",
            "manifest.json",
            "agent-0.safetensors",
            "agent-2.safetensors",
        ] {
            std::fs::write(dir.path().join(f), b"x").unwrap();
        }
        assert_eq!(previous_export_files(dir.path()).unwrap().len(), 4);
        std::fs::write(dir.path().join("notes.txt"), b"mine").unwrap();
        let err = previous_export_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("notes.txt"), "{err}");
        assert!(is_export_file(".agent-1.safetensors.123.tmp"));
        assert!(!is_export_file("agent-x.safetensors"));
    }
}
