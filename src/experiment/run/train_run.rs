//! One training run on disk: its directory, config, checkpoints, metrics and resume.
//!
//! Layout of `<results>/<experiment>/<curve>/seed-<k>/`: `config.toml` (the resolved config plus
//! method and seed), `metrics.csv` (see [`crate::experiment::run::metrics`]), `checkpoint.bin` (the
//! whole trainer: nets, Adam moments, replay, RNG states, counters; for resuming only),
//! `policy/` (the nets as safetensors plus `policy.json`, written with every checkpoint; see
//! [`crate::policy_files`]), `finished` once done, and `.lock`, which the training
//! process holds locked.
//! Every file is written atomically; a killed run resumes from its last checkpoint and ends with
//! the metrics an uninterrupted run would have written.

use crate::algos::families::AnyLoop;
use crate::algos::families::Method;
use crate::algos::training_loop::{Advance, RunRngs, TrainError};
use crate::experiment::definition::config::RunSpec;
use crate::experiment::definition::run_settings::RunSettings;
use crate::experiment::definition::seeds::{stream, Role};
use crate::experiment::run::checkpoint::{self, CheckpointIdentity};
use crate::experiment::run::metrics::{self, METRICS_FILE};
use crate::experiment::run::progress::{Progress, RunEnd};
use crate::experiment::run::provenance::Provenance;
use crate::experiment::run::results_tree::{self, CHECKPOINT, CONFIG, FINISHED, LOCK};
use crate::experiment::run::stop::StopSignal;
use crate::experiment::run::tensorboard::RunEvents;
use crate::files::atomic::{remove_stale_temp_files, write_atomic};
use crate::files::bounded_read::{
    read_in_tree, read_text_in_tree, MAX_CHECKPOINT_BYTES, MAX_TEXT_BYTES,
};
use crate::files::links::{
    check_real_dirs, create_real_dirs, explain_no_follow, open_options_no_follow,
};
use crate::policy_files::{write_policy_files, AgentLayout, PolicyError, RunInfo};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What a run directory's `config.toml` holds: who ran and with which hyperparameters.
///
/// Reading one checks it as `train` checks a config ([`RunManifest::check`]), so a tampered file
/// is refused by every reader (resume, `audit`, checkpoint loading) before anything is sized by it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RecordedManifest")]
pub struct RunManifest {
    /// The experiment's name.
    pub experiment: String,
    /// The method trained.
    pub method: Method,
    /// The sweep point (`key=value,...`), empty without a sweep.
    pub variant: String,
    /// The run's seed.
    pub seed: u64,
    /// The domain and hyperparameters, written as one table.
    pub config: RunSettings,
    /// The build and machine that started the run (absent in runs from before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
}

/// `config.toml` as parsed, before [`RunManifest::check`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RecordedManifest {
    experiment: String,
    method: Method,
    variant: String,
    seed: u64,
    /// Read as the method's family's keys once `method` is known.
    config: toml::Table,
    #[serde(default)]
    provenance: Option<Provenance>,
}

impl TryFrom<RecordedManifest> for RunManifest {
    type Error = String;

    fn try_from(r: RecordedManifest) -> Result<Self, String> {
        let manifest = RunManifest {
            experiment: r.experiment,
            method: r.method,
            variant: r.variant,
            seed: r.seed,
            config: RunSettings::from_table(r.method, r.config)?,
            provenance: r.provenance,
        };
        manifest
            .check()
            .map_err(|(key, why)| format!("`{key}`: {why} (train refuses this config)"))?;
        Ok(manifest)
    }
}

impl RunManifest {
    /// The checks `train` makes before it runs a config: every key in range for the method
    /// ([`crate::experiment::definition::config::validate`]) and the seed at most
    /// [`MAX_SEED`](crate::experiment::definition::limits::MAX_SEED). Returns the key and why.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if self.seed > crate::experiment::definition::limits::MAX_SEED {
            return Err((
                "seed",
                format!(
                    "must be at most {}, got {}",
                    crate::experiment::definition::limits::MAX_SEED,
                    self.seed
                ),
            ));
        }
        crate::experiment::definition::config::validate(
            &self.config.config,
            self.method,
            &self.config.env,
        )
    }

    /// The manifest of `spec` as run by this build on this machine.
    pub fn for_spec(spec: &RunSpec) -> Self {
        RunManifest {
            experiment: spec.experiment.clone(),
            method: spec.method,
            variant: spec.variant.clone(),
            seed: spec.seed,
            config: RunSettings {
                env: spec.env.clone(),
                config: spec.config.clone(),
            },
            provenance: Some(Provenance::current()),
        }
    }

    /// Whether two manifests describe the same run (provenance aside: a run may resume on
    /// another build or machine).
    pub fn same_run(&self, other: &RunManifest) -> bool {
        self.experiment == other.experiment
            && self.method == other.method
            && self.variant == other.variant
            && self.seed == other.seed
            && self.config == other.config
    }

    /// The identity keys (config keys by name, then `experiment`, `method`, `variant`, `seed`)
    /// whose values differ, each as `key (on disk X, requested Y)`. Provenance is not compared.
    pub fn differences(&self, requested: &RunManifest) -> Vec<String> {
        let table = |m: &RunManifest| {
            let mut t = toml::Table::try_from(m).expect("a manifest serializes to a table");
            t.remove("provenance");
            let config = match t.remove("config") {
                Some(toml::Value::Table(c)) => c,
                _ => toml::Table::new(),
            };
            (t, config)
        };
        let (a_top, a_cfg) = table(self);
        let (b_top, b_cfg) = table(requested);
        let mut out = Vec::new();
        for (a, b) in [(&a_cfg, &b_cfg), (&a_top, &b_top)] {
            let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
            for key in keys {
                let show =
                    |v: Option<&toml::Value>| v.map_or("absent".to_string(), |v| v.to_string());
                if a.get(key) != b.get(key) {
                    out.push(format!(
                        "{key} (on disk {}, requested {})",
                        show(a.get(key)),
                        show(b.get(key))
                    ));
                }
            }
        }
        out
    }
}

/// What a run directory already holds, checked against the run asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Existing {
    /// Nothing (or a directory without `config.toml`): the run starts fresh.
    Nothing,
    /// The same run, unfinished: it resumes.
    Unfinished,
    /// The same run, finished: nothing to do.
    Finished,
}

/// Check what `dir` holds against `spec` without changing anything. A different run (any
/// identity key differs, provenance aside), an unreadable `config.toml`, or a `finished` marker
/// without a config is an error naming the problem and pointing at `--force`.
pub fn existing_run(spec: &RunSpec, dir: &Path) -> Result<Existing, RunError> {
    let config_path = dir.join(CONFIG);
    let finished = results_tree::is_finished(dir);
    if std::fs::symlink_metadata(&config_path).is_err() {
        if finished {
            return Err(RunError::UnreadableRun {
                path: config_path,
                message: "the run is marked finished but has no config.toml".into(),
            });
        }
        return Ok(Existing::Nothing);
    }
    let text = read_text_in_tree(&config_path, MAX_TEXT_BYTES).map_err(|e| io(&config_path, e))?;
    let existing: RunManifest = toml::from_str(&text).map_err(|e| RunError::UnreadableRun {
        path: config_path.clone(),
        message: e.message().to_string(),
    })?;
    let requested = RunManifest::for_spec(spec);
    if !existing.same_run(&requested) {
        return Err(RunError::ConfigMismatch {
            dir: dir.to_path_buf(),
            keys: existing.differences(&requested).join(", "),
        });
    }
    Ok(if finished {
        Existing::Finished
    } else {
        Existing::Unfinished
    })
}

/// Take the run's lock, creating its directory: two processes training one run (a campaign
/// started twice, a Slurm task beside a local run) would interleave their checkpoints and
/// metrics. The lock is the operating system's, so a killed process never leaves it held; the
/// file itself stays (it is empty). Every directory from the results root down to the run is
/// created or accepted only as a real directory, and checked again once the lock is held, so a
/// link swapped in by someone else who can write to a shared tree is refused rather than followed
/// out of the results root.
fn lock_run_dir(spec: &RunSpec, dir: &Path) -> Result<std::fs::File, RunError> {
    let root = results_root_of(spec, dir);
    let not_real = |e: std::io::Error| {
        io(
            dir,
            format!("{e}; a run directory and the directories above it must be real directories"),
        )
    };
    // Refuses a link or a file at the run directory itself too.
    create_real_dirs(root, dir).map_err(not_real)?;
    let path = dir.join(LOCK);
    // Never through a link planted at `.lock`: creating or truncating its target elsewhere.
    let file = open_options_no_follow()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&path)
        .map_err(|e| io(&path, explain_no_follow(&path, e)))?;
    match file.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            return Err(RunError::Busy {
                dir: dir.to_path_buf(),
            })
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(io(&path, e)),
    }
    check_real_dirs(root, dir).map_err(not_real)?;
    Ok(file)
}

/// The results root `dir` was made from (`<root>/<experiment>/<curve>/seed-<k>`), or its parent
/// when it is not a run directory of that layout (an audit's scratch run).
fn results_root_of<'a>(spec: &RunSpec, dir: &'a Path) -> &'a Path {
    let relative = spec.dir(Path::new(""));
    let depth = if dir.ends_with(&relative) {
        relative.components().count()
    } else {
        1
    };
    dir.ancestors().nth(depth).unwrap_or(Path::new(""))
}

/// How long a process that finds a run locked waits for the holder's `config.toml`: the holder
/// writes it right after taking the lock.
const HOLDER_CONFIG_WAIT: std::time::Duration = std::time::Duration::from_secs(5);

/// The run in `dir` is locked by another process: if that process trains this very run, leave it
/// to it ([`RunEnd::Busy`], or [`RunEnd::AlreadyFinished`]); if it trains a different one, this
/// run cannot be trained there, which is an error naming the keys that differ (exiting 0 would
/// claim a run that is never trained).
fn held_elsewhere(spec: &RunSpec, dir: &Path) -> Result<RunEnd, RunError> {
    let start = std::time::Instant::now();
    loop {
        match existing_run(spec, dir) {
            Ok(Existing::Finished) => return Ok(RunEnd::AlreadyFinished),
            Ok(Existing::Unfinished) => return Ok(RunEnd::Busy),
            Ok(Existing::Nothing) if start.elapsed() >= HOLDER_CONFIG_WAIT => {
                return Ok(RunEnd::Busy)
            }
            Ok(Existing::Nothing) => std::thread::sleep(std::time::Duration::from_millis(50)),
            Err(RunError::ConfigMismatch { dir, keys }) => {
                return Err(RunError::BusyWithOtherRun { dir, keys })
            }
            Err(e) => return Err(e),
        }
    }
}

/// Empty a locked run directory for `--force`, keeping only the lock file (the run is ours).
/// Entries are removed without following symlinks, so nothing outside the directory is touched.
fn clear_run_dir(dir: &Path) -> Result<(), RunError> {
    for entry in std::fs::read_dir(dir).map_err(|e| io(dir, e))? {
        let path = entry.map_err(|e| io(dir, e))?.path();
        if path.file_name() == Some(std::ffi::OsStr::new(LOCK)) {
            continue;
        }
        let meta = std::fs::symlink_metadata(&path).map_err(|e| io(&path, e))?;
        if meta.is_dir() {
            std::fs::remove_dir_all(&path)
        } else {
            std::fs::remove_file(&path)
        }
        .map_err(|e| io(&path, e))?;
    }
    Ok(())
}

/// Why a run could not proceed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The directory holds a run with another config.
    #[error("{dir}: holds a different run (differs in {keys}); rerun with --force to replace it")]
    ConfigMismatch {
        /// The run directory.
        dir: PathBuf,
        /// The keys that differ, comma-separated.
        keys: String,
    },
    /// The existing run's files cannot be read back.
    #[error("{path}: {message}; rerun with --force to replace the run")]
    UnreadableRun {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error, as text.
        message: String,
    },
    /// Another process holds the run's lock.
    #[error("{dir}: another macdec process is training this run (it holds {dir}/.lock); wait for it or stop it")]
    Busy {
        /// The run directory.
        dir: PathBuf,
    },
    /// Another process holds the run's lock and trains a different run there.
    #[error("{dir}: another macdec process is training a different run here (differs in {keys}); this run was not trained: use another --out, or stop that process and rerun with --force")]
    BusyWithOtherRun {
        /// The run directory.
        dir: PathBuf,
        /// The keys whose values differ, comma-separated.
        keys: String,
    },
    /// The checkpoint does not fit the run (or is damaged).
    #[error("{path}: refused checkpoint: {message} (or rerun with --force)")]
    BadCheckpoint {
        /// The checkpoint file.
        path: PathBuf,
        /// Why it was refused.
        message: String,
    },
    /// Training ran its whole budget without one update: the schedule (`train_freq`,
    /// `start_train`) left no room for one within `total_epi`, so the nets are the initial ones.
    #[error("{dir}: training ended after {episodes} episodes ({env_steps} primitive steps) without a single update: train_freq or start_train leaves no room for one within total_epi; the run is not marked finished")]
    NoUpdate {
        /// The run directory.
        dir: PathBuf,
        /// Training episodes completed.
        episodes: u64,
        /// Primitive steps taken by the training environments.
        env_steps: u64,
    },
    /// Training itself failed.
    #[error(transparent)]
    Train(#[from] TrainError),
    #[error(transparent)]
    /// Boxed: the policy-file error is large, and a run error travels through every job.
    PolicyFiles(#[from] Box<PolicyError>),
    /// The run's TensorBoard log (`--tensorboard`) could not be written.
    #[error("TensorBoard log: {0}")]
    TensorBoard(String),
}

/// A TensorBoard log error (its message names the file).
fn tensorboard_error(e: std::io::Error) -> RunError {
    RunError::TensorBoard(e.to_string())
}

fn io(path: &Path, e: impl std::fmt::Display) -> RunError {
    RunError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The per-role random streams of a run (`docs/ALGORITHMS.md` §8: one generator per role from the seed).
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

/// The checkpoint identity of the run a `config.toml` describes.
fn identity_of(m: &RunManifest) -> CheckpointIdentity {
    CheckpointIdentity::new(&m.experiment, m.method, &m.variant, m.seed, &m.config)
}

/// Read a checkpoint file's bytes: a regular file only (a FIFO, a device or a link is refused),
/// of bounded size.
fn read_checkpoint_bytes(path: &Path) -> Result<Vec<u8>, RunError> {
    read_in_tree(path, MAX_CHECKPOINT_BYTES).map_err(|e| RunError::BadCheckpoint {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// Load a run's trainer from its checkpoint, verified (format, checksum, exact length) and, when
/// the run's `config.toml` sits beside it, checked to be that run's.
pub fn load_checkpoint(path: &Path) -> Result<AnyLoop, RunError> {
    let expected = match path.parent().map(|d| d.join(CONFIG)) {
        Some(config) if std::fs::symlink_metadata(&config).is_ok() => {
            let text = read_text_in_tree(&config, MAX_TEXT_BYTES).map_err(|e| io(&config, e))?;
            let m: RunManifest = toml::from_str(&text).map_err(|e| RunError::UnreadableRun {
                path: config.clone(),
                message: e.message().to_string(),
            })?;
            Some(identity_of(&m))
        }
        _ => None,
    };
    load_checkpoint_of(path, expected.as_ref())
}

fn load_checkpoint_of(
    path: &Path,
    expected: Option<&CheckpointIdentity>,
) -> Result<AnyLoop, RunError> {
    let bytes = read_checkpoint_bytes(path)?;
    checkpoint::decode(&bytes, expected).map_err(|e| RunError::BadCheckpoint {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn save_checkpoint(
    path: &Path,
    identity: &CheckpointIdentity,
    trainer: &mut AnyLoop,
) -> Result<(), RunError> {
    trainer.mark_time();
    let bytes = checkpoint::encode(identity, trainer).map_err(|e| io(path, e))?;
    write_atomic(path, &bytes).map_err(|e| io(path, e))
}

/// Write the trainer's nets as the run's policy files (see [`crate::policy_files`]): the list its
/// learner hands over, whatever the family. A learner that hands over none leaves the run
/// without a `policy/` directory, and the commands that read one say it is missing.
fn save_policy_files(dir: &Path, spec: &RunSpec, trainer: &AnyLoop) -> Result<(), RunError> {
    let nets = trainer.saved_nets();
    if nets.is_empty() {
        return Ok(());
    }
    let config = trainer.config();
    let run = RunInfo {
        experiment: spec.experiment.clone(),
        method: trainer.method().name().to_string(),
        variant: spec.variant.clone(),
        seed: trainer.seed(),
        episodes_trained: trainer.episodes(),
        config: serde_json::to_value(RunSettings {
            env: spec.env.clone(),
            config: config.clone(),
        })
        .map_err(|e| io(dir, e))?,
    };
    // The layout robots and `render` check the nets against; building the domain draws nothing.
    let domain = spec.env.build().map_err(|e| io(dir, e))?;
    write_policy_files(
        dir,
        spec.env.clone().into(),
        AgentLayout::of_domain(&domain),
        config.discount(),
        run,
        &nets,
    )
    .map_err(Box::new)?;
    Ok(())
}

fn save_metrics(dir: &Path, trainer: &AnyLoop) -> Result<(), RunError> {
    let path = dir.join(METRICS_FILE);
    metrics::write(&path, trainer.metric_columns(), trainer.evals()).map_err(|e| io(&path, e))
}

/// Train one run to completion in `dir`, resuming from its checkpoint if there is one.
/// With `force`, an existing run in `dir` is discarded first. A run another process is training
/// is left to it (`RunEnd::Busy`), except with `force`, where it is an error: what was asked
/// for, replacing the run, cannot be done.
pub fn train_run(
    spec: &RunSpec,
    dir: &Path,
    progress: &Progress,
    force: bool,
) -> Result<RunEnd, RunError> {
    train_run_until(spec, dir, progress, force, &StopSignal::new(), None)
}

/// [`train_run`] that also ends when `stop` is raised: after the training episode during which
/// it was raised, the run saves its metrics, checkpoint and policy files as at a checkpoint and
/// returns [`RunEnd::Stopped`]; training it again resumes from there and ends with the metrics
/// an uninterrupted run writes (wall-clock column aside). With `tensorboard`, a run that trains
/// also logs each evaluation below that root as it happens ([`RunEvents`]); a run skipped or
/// left to another process logs nothing.
pub fn train_run_until(
    spec: &RunSpec,
    dir: &Path,
    progress: &Progress,
    force: bool,
    stop: &StopSignal,
    tensorboard: Option<&Path>,
) -> Result<RunEnd, RunError> {
    // Held until this function returns, whatever the outcome.
    let _lock = match lock_run_dir(spec, dir) {
        Err(RunError::Busy { .. }) if !force => return held_elsewhere(spec, dir),
        lock => lock?,
    };
    if force {
        clear_run_dir(dir)?;
    }
    let existing = existing_run(spec, dir)?;
    if existing == Existing::Finished {
        return Ok(RunEnd::AlreadyFinished);
    }
    // Temp files of writers killed mid-write (this run's earlier processes) would pile up.
    remove_stale_temp_files(dir).map_err(|e| io(dir, e))?;
    let config_path = dir.join(CONFIG);
    if existing == Existing::Nothing {
        let manifest = RunManifest::for_spec(spec);
        let text = toml::to_string(&manifest).map_err(|e| io(&config_path, e))?;
        write_atomic(&config_path, text.as_bytes()).map_err(|e| io(&config_path, e))?;
    }
    let checkpoint = dir.join(CHECKPOINT);
    let identity = identity_of(&RunManifest::for_spec(spec));
    let mut trainer = if std::fs::symlink_metadata(&checkpoint).is_ok() {
        load_checkpoint_of(&checkpoint, Some(&identity))?
    } else {
        let env = spec.env.clone();
        AnyLoop::new(
            &spec.config,
            spec.method,
            spec.seed,
            run_rngs(spec.seed),
            || env.build(),
        )?
    };
    let mut events = tensorboard
        .map(|root| {
            RunEvents::open(
                root,
                spec,
                trainer.metric_columns(),
                trainer.evals(),
                trainer.wall_seconds(),
            )
        })
        .transpose()
        .map_err(tensorboard_error)?;
    while let Advance::Episode { checkpoint_due } = trainer.advance()? {
        if let Some(events) = &mut events {
            events.log_new(trainer.evals()).map_err(tensorboard_error)?;
        }
        progress.update(
            trainer.episodes(),
            format!(
                "{} return {:.2}",
                trainer.progress(),
                trainer.evals().last().map_or(f64::NAN, |e| e.eval_return)
            ),
        );
        let stopping = stop.is_stopped();
        if checkpoint_due || stopping {
            save_metrics(dir, &trainer)?;
            save_checkpoint(&checkpoint, &identity, &mut trainer)?;
            save_policy_files(dir, spec, &trainer)?;
        }
        if stopping {
            return Ok(RunEnd::Stopped);
        }
    }
    if let Some(events) = &mut events {
        events.log_new(trainer.evals()).map_err(tensorboard_error)?;
    }
    save_metrics(dir, &trainer)?;
    save_checkpoint(&checkpoint, &identity, &mut trainer)?;
    save_policy_files(dir, spec, &trainer)?;
    // A budget spent without one update is no trained run (an exit status 0 here would hide
    // it); the config checks refuse what is certain, this catches the rest (short episodes).
    if trainer.updates() == 0 {
        return Err(RunError::NoUpdate {
            dir: dir.to_path_buf(),
            episodes: trainer.episodes(),
            env_steps: trainer.env_steps(),
        });
    }
    let marker = dir.join(FINISHED);
    write_atomic(&marker, b"").map_err(|e| io(&marker, e))?;
    Ok(RunEnd::Trained)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::definition::config::{Experiment, Overrides};

    fn spec() -> RunSpec {
        let e = Experiment::parse("", Path::new("e.toml"), "e", &Overrides::default()).unwrap();
        e.runs().unwrap().remove(0)
    }

    #[test]
    fn the_results_root_is_found_from_the_run_layout() {
        let spec = spec();
        let root = Path::new("/data/results");
        assert_eq!(results_root_of(&spec, &spec.dir(root)), root);
        assert_eq!(
            results_root_of(&spec, &spec.dir(Path::new(""))),
            Path::new("")
        );
        assert_eq!(
            results_root_of(&spec, Path::new("/tmp/scratch/run")),
            Path::new("/tmp/scratch")
        );
    }

    #[test]
    fn the_lock_refuses_a_link_anywhere_below_the_results_root() {
        let t = tempfile::tempdir().unwrap();
        let spec = spec();
        let root = t.path().join("results");
        let dir = spec.dir(&root);
        let outside = t.path().join("outside");
        std::fs::create_dir_all(&outside).unwrap();
        // The curve directory is a link out of the tree: nothing is created through it.
        let curve = dir.parent().unwrap();
        std::fs::create_dir_all(curve.parent().unwrap()).unwrap();
        std::os::unix::fs::symlink(&outside, curve).unwrap();
        let err = lock_run_dir(&spec, &dir).unwrap_err().to_string();
        assert!(err.contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read_dir(&outside).unwrap().count(), 0);
        // A real tree locks, and a second lock of the same run is busy.
        std::fs::remove_file(curve).unwrap();
        let _held = lock_run_dir(&spec, &dir).unwrap();
        assert!(matches!(
            lock_run_dir(&spec, &dir),
            Err(RunError::Busy { .. })
        ));
    }
}
