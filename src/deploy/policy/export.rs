//! `macdec export`: turn a trained run directory into a policy directory (issue 7): each
//! agent's decentralized Q-net from the run's policy files (issue 11; written with every
//! checkpoint) as a safetensors file, and the manifest naming the domain, layout, architecture
//! and run. Reads nothing of the trainer: no checkpoint, no learner types. [`export_nets`] writes
//! the same directory from plain nets and any [`MacroEnv`], for domains defined outside this
//! binary (the library's `TrainedPolicy::export`).

use crate::deploy::architecture::Architecture;
use crate::deploy::manifest::{Manifest, ManifestError, RunInfo, MANIFEST_FILE};
use crate::deploy::policy_env::PolicyEnv;
use crate::envs::MacroEnv;
use crate::experiment::policy_files::{read_description, NetRole, PolicyFilesError};
use crate::nn::safetensors_io::to_safetensors_bytes;
use crate::nn::QNet;
use std::path::{Path, PathBuf};

/// Why a run could not be exported.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error(transparent)]
    PolicyFiles(#[from] PolicyFilesError),
    #[error("{dir}: the run trained {method}, which has no decentralized Q-nets to put on robots (export a dec-hddrqn, our1, our1-r or our2 run)")]
    NotDecentralized { dir: PathBuf, method: String },
    #[error("{dir}: agent {agent}'s net has sizes {found}, expected {expected}")]
    NetSize {
        dir: PathBuf,
        agent: usize,
        found: String,
        expected: String,
    },
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    #[error("{dir}: holds {file}, which is not part of a policy export; choose an empty or new --out directory")]
    NotAPolicyDir { dir: PathBuf, file: String },
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{dir}: {got} decentralized net(s) for a domain of {expected} agent(s)")]
    NetCount {
        dir: PathBuf,
        expected: usize,
        got: usize,
    },
}

/// Whether `name` is a file an export writes (or its atomic-write temp file).
fn is_export_file(name: &str) -> bool {
    let name = name.strip_prefix('.').unwrap_or(name);
    let base = name.split(".safetensors").next().unwrap_or(name);
    name == MANIFEST_FILE
        || name.starts_with(&format!("{MANIFEST_FILE}."))
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

/// Export the run in `run_dir` (its `policy/` files, see [`crate::experiment::policy_files`];
/// never its checkpoint) to the policy directory `out`. The nets are exported as the last
/// checkpoint wrote them: a run still training exports its current nets (`episodes_trained` in
/// the manifest says how far it got).
pub fn export_run(run_dir: &Path, out: &Path) -> Result<Manifest, ExportError> {
    let previous = previous_export_files(out)?;
    let description = read_description(run_dir)?;
    let run = &description.run;
    let dec: Vec<_> = description
        .nets
        .iter()
        .filter(|n| n.role == NetRole::Dec)
        .collect();
    if dec.is_empty() {
        return Err(ExportError::NotDecentralized {
            dir: run_dir.to_path_buf(),
            method: run.method.clone(),
        });
    }
    let (mlp, hidden) = (dec[0].sizes.mlp, dec[0].sizes.hidden);
    let mut weights = Vec::with_capacity(dec.len());
    for (agent, entry) in dec.iter().enumerate() {
        if (entry.sizes.mlp, entry.sizes.hidden) != (mlp, hidden) {
            return Err(ExportError::NetSize {
                dir: run_dir.to_path_buf(),
                agent,
                found: format!("M = {}, H = {}", entry.sizes.mlp, entry.sizes.hidden),
                expected: format!("M = {mlp}, H = {hidden} (agent 0's)"),
            });
        }
        // nn's loader checks the checksum and every tensor; the export writes the checked net.
        let net = description.load_net(run_dir, entry)?;
        weights.push(to_safetensors_bytes(&net.params));
    }
    let info = RunInfo {
        experiment: run.experiment.clone(),
        method: run.method.clone(),
        variant: run.variant.clone(),
        seed: run.seed,
        episodes_trained: run.episodes_trained,
        config: run.config.clone(),
    };
    let domain = run
        .env
        .build()
        .map_err(|e| ManifestError::Env(e.to_string()))?;
    write_export(
        out,
        previous,
        run.env.clone().into(),
        &domain,
        run.discount,
        Architecture::ddrqn(mlp, hidden),
        info,
        &weights,
    )
}

/// Write agent i's decentralized net `nets[i]` of a policy trained on `domain` (any
/// [`MacroEnv`]; its layout goes into the manifest) to the policy directory `out`, naming the
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
    let (mlp, hidden) = (nets[0].config().mlp, nets[0].config().hidden);
    for (agent, net) in nets.iter().enumerate() {
        let c = net.config();
        if (c.mlp, c.hidden) != (mlp, hidden) {
            return Err(ExportError::NetSize {
                dir: out.to_path_buf(),
                agent,
                found: format!("M = {}, H = {}", c.mlp, c.hidden),
                expected: format!("M = {mlp}, H = {hidden} (agent 0's)"),
            });
        }
    }
    let weights: Vec<Vec<u8>> = nets
        .iter()
        .map(|n| to_safetensors_bytes(&n.params))
        .collect();
    write_export(
        out,
        previous,
        env,
        domain,
        discount,
        Architecture::ddrqn(mlp, hidden),
        run,
        &weights,
    )
}

/// Write the policy directory and remove what an earlier export there (`previous`) left that
/// the new manifest no longer names.
#[allow(clippy::too_many_arguments)]
fn write_export(
    out: &Path,
    previous: Vec<PathBuf>,
    env: PolicyEnv,
    domain: &impl MacroEnv,
    discount: f64,
    architecture: Architecture,
    run: RunInfo,
    weights: &[Vec<u8>],
) -> Result<Manifest, ExportError> {
    let manifest =
        Manifest::write_policy_for(out, env, domain, discount, architecture, run, weights)?;
    // An earlier export with more agents would leave weight files the manifest no longer names.
    let current: Vec<PathBuf> = std::iter::once(out.join(MANIFEST_FILE))
        .chain(manifest.agents.iter().map(|a| out.join(&a.weights)))
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
            "manifest.json",
            "agent-0.safetensors",
            "agent-2.safetensors",
        ] {
            std::fs::write(dir.path().join(f), b"x").unwrap();
        }
        assert_eq!(previous_export_files(dir.path()).unwrap().len(), 3);
        std::fs::write(dir.path().join("notes.txt"), b"mine").unwrap();
        let err = previous_export_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("notes.txt"), "{err}");
        assert!(is_export_file(".agent-1.safetensors.123.tmp"));
        assert!(!is_export_file("agent-x.safetensors"));
    }
}
