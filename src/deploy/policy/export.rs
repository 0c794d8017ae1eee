//! `macdec export`: turn a trained run directory into a policy directory for robots (issue 7):
//! the run's `policy/` files (issue 11; written with every checkpoint) in the same format,
//! holding each agent's decentralized net only (a Q-net or an actor, as `agent-<i>.safetensors`)
//! beside the layout,
//! domain and run. Reads nothing of the trainer: no checkpoint, no learner types. [`export_nets`] writes
//! the same directory from plain nets and any [`MacroEnv`], for domains defined outside this
//! binary (the library's `TrainedPolicy::export`).

use crate::envs::MacroEnv;
use crate::nn::ActingNet;
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
    /// The run's policy acts only through a centralized net (Cen-DDRQN's Q-net, Mac-CAC's
    /// actor), which no single robot can run.
    #[error("{dir}: the run trained {method}, which has no decentralized nets to put on robots{}", centralized_only(*.centralized))]
    NotDecentralized {
        /// The run directory.
        dir: PathBuf,
        /// The method's name.
        method: String,
        /// What its centralized net is (`centralized Q-net`, `centralized actor`), if it has one.
        centralized: Option<&'static str>,
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

/// What a run whose policy is one centralized net can do instead of an export.
fn centralized_only(centralized: Option<&'static str>) -> String {
    match centralized {
        Some(net) => format!(
            ": its policy is its {net}, which reads every agent's observation and picks the team's joint macro-action, so no robot can run it; evaluate it centrally (`macdec eval --policy RUN/policy`, `macdec render --run RUN`)"
        ),
        None => String::new(),
    }
}

/// Export the run in `run_dir` (its `policy/` files of any format version, see
/// [`crate::policy_files`]; never its checkpoint) to the policy directory `out`: the same
/// format, holding only each agent's decentralized net (a Q-net, or an actor-critic run's
/// actor), its bytes copied as verified. The nets are exported as the last checkpoint wrote
/// them: a run still training exports its current nets (`episodes_trained` says how far it
/// got).
pub fn export_run(run_dir: &Path, out: &Path) -> Result<Manifest, ExportError> {
    let dir = run_dir.join(POLICY_DIR);
    if std::fs::symlink_metadata(dir.join(POLICY_FILE)).is_err() {
        return Err(PolicyError::MissingRun {
            dir: run_dir.to_path_buf(),
        }
        .into());
    }
    // A run still training replaces its policy files at each checkpoint: a read that straddled
    // a replacement (the description of one, weights of the next) is read again, whole.
    let mut attempts = 0;
    let (m, files) = loop {
        let m = Manifest::read(&dir)?;
        match agent_net_files(run_dir, &dir, &m) {
            Ok(files) => break (m, files),
            Err(e) => {
                attempts += 1;
                let replaced = Manifest::read(&dir).is_ok_and(|now| now != m);
                if !replaced || attempts >= 10 {
                    return Err(e);
                }
            }
        }
    };
    write_files(out, m.env, m.agents, m.discount, m.run, files)
}

/// Each agent's decentralized net of the policy `m` in `dir`, read and verified.
fn agent_net_files(run_dir: &Path, dir: &Path, m: &Manifest) -> Result<Vec<NetFile>, ExportError> {
    let mut files = Vec::with_capacity(m.agents.len());
    for agent in 0..m.agents.len() {
        let verified = match m.verify_agent(dir, agent) {
            Ok(v) => v,
            Err(PolicyError::NoAgentNet { centralized, .. }) => {
                return Err(ExportError::NotDecentralized {
                    dir: run_dir.to_path_buf(),
                    method: m.run.method.clone(),
                    centralized,
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
    Ok(files)
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
    nets: &[&ActingNet],
) -> Result<Manifest, ExportError> {
    if nets.is_empty() {
        return Err(ExportError::NotDecentralized {
            dir: out.to_path_buf(),
            method: run.method,
            centralized: None,
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
        .map(|(i, n)| NetFile::acting(NetRole::Dec, Some(i), weights_file_name(i), n))
        .collect();
    write_files(out, env, agents, discount, run, files)
}

/// Write the policy directory `out` (agent i's net as `agent-<i>.safetensors`), replacing an
/// earlier export there whole ([`Manifest::write_new`]).
fn write_files(
    out: &Path,
    env: PolicyEnv,
    agents: Vec<AgentLayout>,
    discount: f64,
    run: RunInfo,
    files: Vec<NetFile>,
) -> Result<Manifest, ExportError> {
    Ok(Manifest::write_new(
        out,
        env,
        agents,
        discount,
        NetRole::Dec,
        run,
        &files,
    )?)
}
