//! `macdec.train`: the runs of an experiment trained by the CLI's runner
//! ([`macdec::experiment::run::train_all::train_all`]) in a thread of its own while the calling
//! thread, without the GIL, waits and polls for Ctrl-C; an interrupt raises the stop signal, the runs
//! save their checkpoints and stop, and `KeyboardInterrupt` is raised once they have.

use crate::guarded;
use macdec::algos::families::Method;
use macdec::experiment::definition::config::{Experiment, Overrides};
use macdec::experiment::definition::seeds::parse_seeds;
use macdec::experiment::run::runner::{RunStatus, RunnerOptions};
use macdec::experiment::run::stop::StopSignal;
use macdec::experiment::run::train_all::train_all;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// How often the waiting thread looks for Ctrl-C.
const POLL: Duration = Duration::from_millis(50);

/// The experiment of `config` (a path, or the JSON text of a dict in the TOML's shape) with the
/// methods, seeds and `key=value` overrides applied.
fn experiment(
    config: &str,
    is_path: bool,
    methods: Option<Vec<String>>,
    seeds: Option<&str>,
    set: Vec<String>,
) -> PyResult<Experiment> {
    let bad = |e: &dyn std::fmt::Display| PyValueError::new_err(e.to_string());
    let methods = methods
        .map(|names| {
            names
                .iter()
                .map(|n| n.trim().parse::<Method>())
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()
        .map_err(|e| bad(&e))?;
    let seeds = seeds.map(parse_seeds).transpose().map_err(|e| bad(&e))?;
    let overrides = Overrides {
        methods,
        seeds,
        set,
    };
    if is_path {
        let path = Path::new(config);
        return Experiment::load(path, &overrides)
            .map_err(|e| bad(&format!("loading {}: {e}", path.display())));
    }
    let value: toml::Value = serde_json::from_str(config)
        .map_err(|e| bad(&format!("the config dict cannot be written as TOML: {e}")))?;
    let text = toml::to_string(&value)
        .map_err(|e| bad(&format!("the config dict cannot be written as TOML: {e}")))?;
    Experiment::parse(&text, Path::new("<config dict>"), "experiment", &overrides)
        .map_err(|e| bad(&e))
}

/// Train every run of the experiment; returns `(run directory, status)` per run, status one of
/// `finished`, `skipped` (finished before), `busy` (another process trains it). Failed runs
/// raise RuntimeError naming them; Ctrl-C stops the runs (resumable) and raises
/// KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (config, is_path, methods, seeds, set, out, jobs, force, quiet))]
#[allow(clippy::too_many_arguments)]
pub fn train(
    py: Python<'_>,
    config: &str,
    is_path: bool,
    methods: Option<Vec<String>>,
    seeds: Option<String>,
    set: Vec<String>,
    out: PathBuf,
    jobs: Option<usize>,
    force: bool,
    quiet: bool,
) -> PyResult<Vec<(PathBuf, &'static str)>> {
    guarded(|| {
        let experiment = experiment(config, is_path, methods, seeds.as_deref(), set)?;
        let runs = experiment
            .runs()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let jobs = macdec::experiment::definition::limits::worker_threads(
            jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
            runs.len(),
        );
        experiment.write_shared_curves(&out).map_err(|e| {
            PyRuntimeError::new_err(format!(
                "recording the shared curves in {}: {e}",
                out.display()
            ))
        })?;
        let opts = RunnerOptions {
            out: out.clone(),
            jobs,
            force,
            quiet,
            tensorboard: None,
        };
        let stop = StopSignal::new();
        let worker = {
            let (runs, stop) = (runs.clone(), stop.clone());
            std::thread::Builder::new()
                .name("macdec-train".into())
                .spawn(move || train_all(&runs, &opts, force, &stop))
                .map_err(|e| {
                    PyRuntimeError::new_err(format!("starting the training thread: {e}"))
                })?
        };
        let mut interrupt = None;
        while !worker.is_finished() {
            py.allow_threads(|| std::thread::sleep(POLL));
            if let Err(e) = py.check_signals() {
                stop.stop();
                interrupt.get_or_insert(e);
            }
        }
        let statuses = py
            .allow_threads(|| worker.join())
            .map_err(|_| PyRuntimeError::new_err("the training thread panicked"))?;
        if let Some(e) = interrupt {
            return Err(e);
        }
        let mut failed = Vec::new();
        let mut result = Vec::with_capacity(runs.len());
        for (spec, status) in runs.iter().zip(&statuses) {
            let dir = spec.dir(&out);
            let label = match status {
                RunStatus::Finished { .. } => "finished",
                RunStatus::Skipped => "skipped",
                RunStatus::Busy => "busy",
                RunStatus::Stopped => "stopped",
                RunStatus::Failed(e) => {
                    failed.push(format!("{}: {e}", dir.display()));
                    "failed"
                }
            };
            result.push((dir, label));
        }
        if !failed.is_empty() {
            return Err(PyRuntimeError::new_err(format!(
                "{} of {} run(s) failed:\n{}",
                failed.len(),
                runs.len(),
                failed.join("\n")
            )));
        }
        Ok(result)
    })
}
