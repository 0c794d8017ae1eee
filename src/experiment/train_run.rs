//! One training run on disk: its directory, config, checkpoints, metrics and resume.
//!
//! Layout of `<results>/<experiment>/<curve>/seed-<k>/`: `config.toml` (the resolved config plus
//! method and seed), `metrics.csv` (see [`crate::experiment::metrics`]), `checkpoint.bin` (the
//! whole trainer: nets, Adam moments, replay, RNG states, counters) and `finished` once done.
//! Every file is written atomically; a killed run resumes from its last checkpoint and ends with
//! the metrics an uninterrupted run would have written.

use crate::algos::hyper::RunConfig;
use crate::algos::method::Method;
use crate::algos::trainer::{Advance, RunRngs, TrainError, Trainer};
use crate::experiment::atomic::write_atomic;
use crate::experiment::config::RunSpec;
use crate::experiment::metrics::{self, METRICS_FILE};
use crate::experiment::provenance::Provenance;
use crate::experiment::runner::{Progress, FINISHED_MARKER};
use crate::experiment::seeds::{stream, Role};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The checkpoint file of a run.
pub const CHECKPOINT: &str = "checkpoint.bin";
/// The resolved config of a run.
pub const CONFIG: &str = "config.toml";

/// What a run directory's `config.toml` holds: who ran and with which hyperparameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunManifest {
    pub experiment: String,
    pub method: Method,
    pub variant: String,
    pub seed: u64,
    pub config: RunConfig,
    /// The build and machine that started the run (absent in runs from before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
}

impl RunManifest {
    /// Whether two manifests describe the same run (provenance aside: a run may resume on
    /// another build or machine).
    pub fn same_run(&self, other: &RunManifest) -> bool {
        self.experiment == other.experiment
            && self.method == other.method
            && self.variant == other.variant
            && self.seed == other.seed
            && self.config == other.config
    }
}

/// Why a run could not proceed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{dir}: holds a run with a different config; rerun with --force to replace it")]
    ConfigMismatch { dir: PathBuf },
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{path}: unreadable checkpoint ({message}); delete it or rerun with --force")]
    BadCheckpoint { path: PathBuf, message: String },
    #[error(transparent)]
    Train(#[from] TrainError),
}

fn io(path: &Path, e: impl std::fmt::Display) -> RunError {
    RunError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The per-role random streams of a run (spec 8: one generator per role from the seed).
pub fn run_rngs(seed: u64) -> RunRngs {
    RunRngs {
        init: stream(seed, Role::Init),
        explore: stream(seed, Role::Explore),
        replay: stream(seed, Role::Replay),
        env: stream(seed, Role::Env),
        cen_env: stream(seed, Role::CenEnv),
        eval_env: stream(seed, Role::EvalEnv),
    }
}

/// Load a run's trainer from its checkpoint.
pub fn load_checkpoint(path: &Path) -> Result<Trainer, RunError> {
    let bytes = std::fs::read(path).map_err(|e| io(path, e))?;
    bincode::deserialize(&bytes).map_err(|e| RunError::BadCheckpoint {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn save_checkpoint(path: &Path, trainer: &mut Trainer) -> Result<(), RunError> {
    trainer.mark_time();
    let bytes = bincode::serialize(trainer).map_err(|e| io(path, e))?;
    write_atomic(path, &bytes).map_err(|e| io(path, e))
}

fn save_metrics(dir: &Path, trainer: &Trainer) -> Result<(), RunError> {
    let rows = trainer.evals();
    let path = dir.join(METRICS_FILE);
    metrics::write(&path, rows).map_err(|e| io(&path, e))
}

/// Train one run to completion in `dir`, resuming from its checkpoint if there is one.
/// With `force`, an existing run in `dir` is discarded first.
pub fn train_run(
    spec: &RunSpec,
    dir: &Path,
    progress: &Progress,
    force: bool,
) -> Result<(), RunError> {
    if force && dir.exists() {
        std::fs::remove_dir_all(dir).map_err(|e| io(dir, e))?;
    }
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let manifest = RunManifest {
        experiment: spec.experiment.clone(),
        method: spec.method,
        variant: spec.variant.clone(),
        seed: spec.seed,
        config: spec.config.clone(),
        provenance: Some(Provenance::current()),
    };
    let config_path = dir.join(CONFIG);
    if config_path.exists() {
        let text = std::fs::read_to_string(&config_path).map_err(|e| io(&config_path, e))?;
        let existing: Result<RunManifest, _> = toml::from_str(&text);
        if !existing.is_ok_and(|m| m.same_run(&manifest)) {
            return Err(RunError::ConfigMismatch {
                dir: dir.to_path_buf(),
            });
        }
    } else {
        let text = toml::to_string(&manifest).map_err(|e| io(&config_path, e))?;
        write_atomic(&config_path, text.as_bytes()).map_err(|e| io(&config_path, e))?;
    }
    let checkpoint = dir.join(CHECKPOINT);
    let mut trainer = if checkpoint.exists() {
        load_checkpoint(&checkpoint)?
    } else {
        Trainer::new(
            spec.config.clone(),
            spec.method,
            spec.seed,
            run_rngs(spec.seed),
        )?
    };
    while let Advance::Episode { checkpoint_due } = trainer.advance()? {
        progress.update(
            trainer.episodes(),
            format!(
                "eps {:.3} return {:.2}",
                trainer.epsilon(),
                trainer.evals().last().map_or(f64::NAN, |e| e.eval_return)
            ),
        );
        if checkpoint_due {
            save_metrics(dir, &trainer)?;
            save_checkpoint(&checkpoint, &mut trainer)?;
        }
    }
    save_metrics(dir, &trainer)?;
    save_checkpoint(&checkpoint, &mut trainer)?;
    let marker = dir.join(FINISHED_MARKER);
    write_atomic(&marker, b"").map_err(|e| io(&marker, e))?;
    Ok(())
}
