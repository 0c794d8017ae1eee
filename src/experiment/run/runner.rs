//! Runs every (method, variant, seed) of an experiment as its own job, `--jobs` at a time.
//!
//! Parallelism is across runs only, never inside one run's arithmetic, so `--jobs` never changes
//! a number. A run that fails (bad numbers, I/O, even a panic) reports its error and the others
//! carry on. A finished run is skipped unless `force` is set, but only if its `config.toml`
//! describes the run asked for (provenance aside); a different run in its directory fails that
//! run, naming the keys that differ.

use crate::experiment::definition::config::RunSpec;
use crate::experiment::run::progress::{Heartbeat, Progress, RunEnd};
use crate::experiment::run::results_tree;
use crate::experiment::run::train_run::{existing_run, Existing};
use crate::experiment::run::work_queue::run_in_order;
use crate::files::links::check_real_dirs;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How to run a batch of runs.
#[derive(Debug, Clone)]
pub struct RunnerOptions {
    /// Root of the results tree (`results/` by default).
    pub out: PathBuf,
    /// Worker threads; each runs one training run at a time (never more than there are runs).
    pub jobs: usize,
    /// Recompute finished runs instead of skipping them.
    pub force: bool,
    /// No progress bars (logs, CI); one line per finished run instead. Without a terminal
    /// on stderr that is the default anyway, with a line every
    /// [`HEARTBEAT`](crate::experiment::run::progress::HEARTBEAT) per run besides.
    pub quiet: bool,
    /// Root of the live TensorBoard logs, if any ([`crate::experiment::run::tensorboard`]):
    /// each run that trains logs its evaluations below it as they happen. Not part of any run's
    /// identity.
    pub tensorboard: Option<std::path::PathBuf>,
}

/// What became of one run.
#[derive(Debug)]
pub enum RunStatus {
    /// Trained to the end by this invocation (possibly resumed from a checkpoint).
    Finished {
        /// Wall-clock time this invocation spent on it.
        seconds: f64,
    },
    /// Already finished; nothing to do.
    Skipped,
    /// Being trained by another process.
    Busy,
    /// Stopped early on request, resumable ([`RunEnd::Stopped`]).
    Stopped,
    /// Stopped by an error; holds its message.
    Failed(String),
}

/// `experiment/curve/seed-k`, as progress lines name a run.
fn run_name(spec: &RunSpec) -> String {
    format!(
        "{}/{}",
        spec.experiment,
        results_tree::run_label(&spec.curve_name(), spec.seed)
    )
}

/// Run `runs` with `run_one`, `jobs` at a time, each worker taking the next run (lowest seed
/// first) as soon as it is free. Returns each run's status in input order.
pub fn run_all<F>(runs: &[RunSpec], opts: &RunnerOptions, run_one: F) -> Vec<RunStatus>
where
    F: Fn(&RunSpec, &Path, &Progress) -> Result<RunEnd, String> + Sync,
{
    // Without a terminal, bars would draw nothing: print lines instead, as --quiet does, plus a
    // heartbeat per run (a log of a long batch shows it is alive).
    let bars = !opts.quiet && std::io::IsTerminal::is_terminal(&std::io::stderr());
    let heartbeat = !opts.quiet && !bars;
    let multi = MultiProgress::with_draw_target(if bars {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    });
    // What to do with each run: `Ok(true)` train, `Ok(false)` skip (finished, same identity),
    // `Err` fail at once (another run's results are in its directory).
    let todo: Vec<Result<bool, String>> = runs
        .iter()
        .map(|r| {
            let dir = r.dir(&opts.out);
            // Anyone who can write to a shared results tree could link a run's directory, or one
            // above it, elsewhere: nothing below --out is created, read or emptied through one.
            check_real_dirs(&opts.out, &dir).map_err(|e| e.to_string())?;
            if opts.force {
                return Ok(true);
            }
            match existing_run(r, &dir) {
                Ok(Existing::Finished) => Ok(false),
                Ok(_) => Ok(true),
                Err(e) => Err(e.to_string()),
            }
        })
        .collect();
    let total_episodes: u64 = runs
        .iter()
        .zip(&todo)
        .filter(|(_, t)| matches!(t, Ok(true)))
        .map(|(r, _)| r.config.total_epi() as u64)
        .sum();
    let total = multi.add(ProgressBar::new(total_episodes));
    total.set_style(
        ProgressStyle::with_template(
            "total {bar:30} {pos}/{len} episodes, {elapsed} elapsed, ETA {eta}",
        )
        .expect("valid template"),
    );
    // A line about one run: above the progress bars, or on stderr when they are hidden.
    let say = |line: String| {
        if bars {
            let _ = multi.println(&line);
        } else {
            eprintln!("{line}");
        }
    };
    // Failures of identity are reported at once; the runs to train go through one queue in seed
    // order, so an interrupted batch leaves every curve with about the same seeds finished.
    let mut statuses: Vec<Option<RunStatus>> = runs
        .iter()
        .zip(&todo)
        .map(|(spec, todo)| match todo {
            Ok(true) => None,
            Ok(false) => Some(RunStatus::Skipped),
            Err(e) => {
                say(format!("FAILED {}: {e}", run_name(spec)));
                Some(RunStatus::Failed(e.clone()))
            }
        })
        .collect();
    let mut order: Vec<usize> = (0..runs.len()).filter(|&i| statuses[i].is_none()).collect();
    order.sort_by_key(|&i| runs[i].seed);
    let trained = run_in_order(&order, opts.jobs, |i| {
        let spec = &runs[i];
        let name = run_name(spec);
        let dir = spec.dir(&opts.out);
        let bar = multi.insert_before(&total, ProgressBar::new(spec.config.total_epi() as u64));
        bar.set_style(
            ProgressStyle::with_template("{prefix:32} {bar:20} {pos}/{len} {msg}")
                .expect("valid template"),
        );
        bar.set_prefix(results_tree::run_label(&spec.curve_name(), spec.seed));
        let progress = Progress {
            bar: bar.clone(),
            total: total.clone(),
            last: Arc::default(),
            heartbeat: heartbeat.then(|| {
                Arc::new(Heartbeat {
                    name: name.clone(),
                    total_epi: spec.config.total_epi() as u64,
                    last: std::sync::Mutex::new(std::time::Instant::now()),
                })
            }),
        };
        let start = std::time::Instant::now();
        // A panic is a bug, but it fails this run only, not its neighbours.
        // The run checks its directories again as it creates them and takes its lock
        // (`train_run`); it creates them only when it trains, so a stopped batch leaves none.
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            run_one(spec, &dir, &progress)
        }))
        .unwrap_or_else(|panic| {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown".into());
            Err(format!("internal error (panic: {what})"))
        });
        bar.finish_and_clear();
        multi.remove(&bar);
        let seconds = start.elapsed().as_secs_f64();
        match result {
            Ok(RunEnd::Trained) => {
                if !bars {
                    eprintln!("finished {name} in {seconds:.1} s");
                }
                RunStatus::Finished { seconds }
            }
            Ok(RunEnd::AlreadyFinished) => RunStatus::Skipped,
            Ok(RunEnd::Busy) => {
                say(format!("left {name} to the other process training it"));
                RunStatus::Busy
            }
            Ok(RunEnd::Stopped) => {
                say(format!("stopped {name} (resumable)"));
                RunStatus::Stopped
            }
            Err(e) => {
                say(format!("FAILED {name}: {e}"));
                RunStatus::Failed(e)
            }
        }
    });
    for (i, status) in order.into_iter().zip(trained) {
        statuses[i] = Some(status);
    }
    let statuses = statuses
        .into_iter()
        .map(|s| s.expect("every run was skipped, failed or trained"))
        .collect();
    total.finish_and_clear();
    statuses
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::definition::config::{Experiment, Overrides};

    fn runs(n: usize) -> Vec<RunSpec> {
        let o = Overrides {
            seeds: Some((0..n as u64).collect()),
            ..Default::default()
        };
        Experiment::parse("methods = [\"our1\"]", Path::new("t.toml"), "t", &o)
            .unwrap()
            .runs()
            .unwrap()
    }

    #[test]
    fn a_failing_run_does_not_stop_the_others_and_finished_runs_are_skipped() {
        let dir = tempfile::tempdir().unwrap();
        let opts = RunnerOptions {
            out: dir.path().to_path_buf(),
            jobs: 2,
            force: false,
            quiet: true,
            tensorboard: None,
        };
        let runs = runs(4);
        let work = |spec: &RunSpec, dir: &Path, _: &Progress| {
            if spec.seed == 1 {
                return Err("boom".to_string());
            }
            if spec.seed == 2 {
                panic!("kaboom");
            }
            finish(spec, dir);
            Ok(RunEnd::Trained)
        };
        let first = run_all(&runs, &opts, work);
        assert!(matches!(first[1], RunStatus::Failed(ref e) if e == "boom"));
        assert!(matches!(first[2], RunStatus::Failed(ref e) if e.contains("kaboom")));
        assert!(first
            .iter()
            .enumerate()
            .all(|(i, s)| i == 1 || i == 2 || matches!(s, RunStatus::Finished { .. })));
        let second = run_all(&runs, &opts, work);
        assert!(matches!(second[0], RunStatus::Skipped));
        assert!(matches!(second[1], RunStatus::Failed(_)));
    }

    #[test]
    fn runs_start_in_seed_order_across_methods() {
        let dir = tempfile::tempdir().unwrap();
        let opts = RunnerOptions {
            out: dir.path().to_path_buf(),
            jobs: 1,
            force: false,
            quiet: true,
            tensorboard: None,
        };
        let o = Overrides {
            seeds: Some(vec![0, 1]),
            ..Default::default()
        };
        let runs = Experiment::parse(
            "methods = [\"our1\", \"cen-ddrqn\"]",
            Path::new("t.toml"),
            "t",
            &o,
        )
        .unwrap()
        .runs()
        .unwrap();
        let started = std::sync::Mutex::new(Vec::new());
        run_all(&runs, &opts, |spec, dir, _| {
            started
                .lock()
                .unwrap()
                .push(format!("{}/{}", spec.curve_name(), spec.seed));
            finish(spec, dir);
            Ok(RunEnd::Trained)
        });
        assert_eq!(
            *started.lock().unwrap(),
            ["our1/0", "cen-ddrqn/0", "our1/1", "cen-ddrqn/1"]
        );
    }

    /// What a finished run leaves: its config.toml and the marker.
    fn finish(spec: &RunSpec, dir: &Path) {
        use crate::experiment::run::results_tree::{CONFIG, FINISHED};
        use crate::experiment::run::train_run::RunManifest;
        std::fs::create_dir_all(dir).unwrap();
        let text = toml::to_string(&RunManifest::for_spec(spec)).unwrap();
        std::fs::write(dir.join(CONFIG), text).unwrap();
        std::fs::write(dir.join(FINISHED), "").unwrap();
    }

    #[test]
    fn a_finished_run_of_another_config_is_refused_naming_the_keys_but_provenance_is_ignored() {
        use crate::experiment::run::results_tree::CONFIG;
        let dir = tempfile::tempdir().unwrap();
        let opts = RunnerOptions {
            out: dir.path().to_path_buf(),
            jobs: 1,
            force: false,
            quiet: true,
            tensorboard: None,
        };
        let runs = runs(1);
        let ran = std::sync::atomic::AtomicUsize::new(0);
        let work = |spec: &RunSpec, dir: &Path, _: &Progress| {
            ran.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            finish(spec, dir);
            Ok(RunEnd::Trained)
        };
        run_all(&runs, &opts, work);
        let config = runs[0].dir(dir.path()).join(CONFIG);
        let text = std::fs::read_to_string(&config).unwrap();

        // Another build and machine: still the same run, skipped.
        let other_build = text.replace(
            &format!("git_commit = \"{}\"", env!("MACDEC_GIT_COMMIT")),
            "git_commit = \"0000000\"",
        );
        assert_ne!(other_build, text);
        std::fs::write(&config, other_build).unwrap();
        assert!(matches!(run_all(&runs, &opts, work)[0], RunStatus::Skipped));

        // An edited hyperparameter: refused, naming the key, nothing run.
        let edited = text.replace("trace_len = 15", "trace_len = 10");
        assert_ne!(edited, text);
        std::fs::write(&config, edited).unwrap();
        let before = ran.load(std::sync::atomic::Ordering::Relaxed);
        let status = run_all(&runs, &opts, work);
        assert!(
            matches!(&status[0], RunStatus::Failed(e) if e.contains("trace_len (on disk 10, requested 15)") && e.contains("--force")),
            "{status:?}"
        );
        assert_eq!(ran.load(std::sync::atomic::Ordering::Relaxed), before);

        // Garbage in config.toml: refused too.
        std::fs::write(&config, "not toml [").unwrap();
        assert!(matches!(
            run_all(&runs, &opts, work)[0],
            RunStatus::Failed(_)
        ));
        // --force recomputes.
        let forced = RunnerOptions {
            force: true,
            ..opts.clone()
        };
        assert!(matches!(
            run_all(&runs, &forced, work)[0],
            RunStatus::Finished { .. }
        ));
    }
}
