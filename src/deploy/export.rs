//! `macdec export`: turn a trained run directory into a policy directory (issue 7): each
//! agent's decentralized Q-net from the run's last checkpoint as a safetensors file, and the
//! manifest naming the domain, layout, architecture and run.

use crate::deploy::architecture::Architecture;
use crate::deploy::manifest::{Manifest, ManifestError, RunInfo};
use crate::experiment::train_run::{load_checkpoint, RunError, RunManifest, CHECKPOINT, CONFIG};
use crate::nn::safetensors_io::to_safetensors_bytes;
use std::path::{Path, PathBuf};

/// Why a run could not be exported.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("{path}: {message}")]
    RunConfig { path: PathBuf, message: String },
    #[error(transparent)]
    Checkpoint(#[from] RunError),
    #[error("{dir}: the run trained {method}, which has no decentralized Q-nets to put on robots (export a dec-hddrqn, our1, our1-r or our2 run)")]
    NotDecentralized { dir: PathBuf, method: &'static str },
    #[error("{dir}: agent {agent}'s net has sizes {found}, the run config says {expected}")]
    NetSize {
        dir: PathBuf,
        agent: usize,
        found: String,
        expected: String,
    },
    #[error(transparent)]
    Manifest(#[from] ManifestError),
}

/// Export the run in `run_dir` (its `config.toml` and `checkpoint.bin`) to the policy directory
/// `out`. The checkpoint's nets are exported as they are: a run still training exports its
/// current nets (`episodes_trained` in the manifest says how far it got).
pub fn export_run(run_dir: &Path, out: &Path) -> Result<Manifest, ExportError> {
    let config_path = run_dir.join(CONFIG);
    let run_config = |message: String| ExportError::RunConfig {
        path: config_path.clone(),
        message,
    };
    let text = std::fs::read_to_string(&config_path).map_err(|e| run_config(e.to_string()))?;
    let run: RunManifest = toml::from_str(&text).map_err(|e| run_config(e.to_string()))?;
    let trainer = load_checkpoint(&run_dir.join(CHECKPOINT))?;
    let method = trainer.method();
    let nets = trainer.dec_policies();
    if nets.is_empty() {
        return Err(ExportError::NotDecentralized {
            dir: run_dir.to_path_buf(),
            method: method.name(),
        });
    }
    let config = trainer.config();
    let (mlp, hidden) = (config.dec_mlp_layer_size, config.dec_rnn_h_size);
    for (agent, net) in nets.iter().enumerate() {
        let cfg = net.config();
        if (cfg.mlp, cfg.hidden) != (mlp, hidden) {
            return Err(ExportError::NetSize {
                dir: run_dir.to_path_buf(),
                agent,
                found: format!("M = {}, H = {}", cfg.mlp, cfg.hidden),
                expected: format!("M = {mlp}, H = {hidden}"),
            });
        }
    }
    let weights: Vec<Vec<u8>> = nets
        .iter()
        .map(|n| to_safetensors_bytes(&n.params))
        .collect();
    let info = RunInfo {
        experiment: run.experiment,
        method: method.name().to_string(),
        variant: run.variant,
        seed: trainer.seed(),
        episodes_trained: trainer.episodes(),
        config: serde_json::to_value(config).map_err(|e| run_config(e.to_string()))?,
    };
    Ok(Manifest::write_policy(
        out,
        crate::algos::trainer::env_spec(config),
        config.discount,
        Architecture::ddrqn(mlp, hidden),
        info,
        &weights,
    )?)
}
