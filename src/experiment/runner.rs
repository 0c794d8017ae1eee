//! Runs every (method, variant, seed) of an experiment as its own job, in parallel with rayon.
//!
//! Parallelism is across runs only, never inside one run's arithmetic, so `--jobs` never changes
//! a number. A run that fails (bad numbers, I/O) reports its error and the others carry on; a
//! finished run is skipped unless `force` is set.

use crate::experiment::config::RunSpec;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The marker a run writes when its last metrics row is on disk.
pub const FINISHED_MARKER: &str = "finished";

/// How to run a batch of runs.
#[derive(Debug, Clone)]
pub struct RunnerOptions {
    /// Root of the results tree (`results/` by default).
    pub out: PathBuf,
    /// Worker threads; each runs one training run at a time.
    pub jobs: usize,
    /// Recompute finished runs instead of skipping them.
    pub force: bool,
    /// No progress bars (logs, CI); one line per finished run instead.
    pub quiet: bool,
}

/// What became of one run.
#[derive(Debug)]
pub enum RunStatus {
    Finished { seconds: f64 },
    Skipped,
    Failed(String),
}

/// A progress handle a run updates as episodes complete.
#[derive(Clone)]
pub struct Progress {
    bar: ProgressBar,
    total: ProgressBar,
    last: Arc<std::sync::atomic::AtomicU64>,
}

impl Progress {
    /// A handle that draws nothing (for tests and library callers).
    pub fn hidden() -> Self {
        Progress {
            bar: ProgressBar::hidden(),
            total: ProgressBar::hidden(),
            last: Arc::default(),
        }
    }

    /// Report that `episodes` training episodes are complete, with a short status message.
    pub fn update(&self, episodes: u64, message: impl Into<std::borrow::Cow<'static, str>>) {
        use std::sync::atomic::Ordering;
        let before = self.last.swap(episodes, Ordering::Relaxed);
        self.total.inc(episodes.saturating_sub(before));
        self.bar.set_position(episodes);
        self.bar.set_message(message);
    }
}

/// Run `runs` with `run_one`, `jobs` at a time. Returns each run's status in input order.
pub fn run_all<F>(runs: &[RunSpec], opts: &RunnerOptions, run_one: F) -> Vec<RunStatus>
where
    F: Fn(&RunSpec, &Path, &Progress) -> Result<(), String> + Sync,
{
    let multi = MultiProgress::with_draw_target(if opts.quiet {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    });
    let todo: Vec<bool> = runs
        .iter()
        .map(|r| opts.force || !r.dir(&opts.out).join(FINISHED_MARKER).exists())
        .collect();
    let total_episodes: u64 = runs
        .iter()
        .zip(&todo)
        .filter(|(_, &t)| t)
        .map(|(r, _)| r.config.total_epi as u64)
        .sum();
    let total = multi.add(ProgressBar::new(total_episodes));
    total.set_style(
        ProgressStyle::with_template(
            "total {bar:30} {pos}/{len} episodes, {elapsed} elapsed, ETA {eta}",
        )
        .expect("valid template"),
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.max(1))
        .build()
        .expect("a rayon pool with at least one thread");
    let statuses = pool.install(|| {
        runs.par_iter()
            .zip(todo.par_iter())
            .map(|(spec, &todo)| {
                if !todo {
                    return RunStatus::Skipped;
                }
                let dir = spec.dir(&opts.out);
                let bar =
                    multi.insert_before(&total, ProgressBar::new(spec.config.total_epi as u64));
                bar.set_style(
                    ProgressStyle::with_template("{prefix:32} {bar:20} {pos}/{len} {msg}")
                        .expect("valid template"),
                );
                bar.set_prefix(format!("{}/seed-{}", spec.curve_name(), spec.seed));
                let progress = Progress {
                    bar: bar.clone(),
                    total: total.clone(),
                    last: Arc::default(),
                };
                let start = std::time::Instant::now();
                let result = run_one(spec, &dir, &progress);
                bar.finish_and_clear();
                multi.remove(&bar);
                let seconds = start.elapsed().as_secs_f64();
                let name = format!(
                    "{}/{}/seed-{}",
                    spec.experiment,
                    spec.curve_name(),
                    spec.seed
                );
                match result {
                    Ok(()) => {
                        if opts.quiet {
                            eprintln!("finished {name} in {seconds:.1} s");
                        }
                        RunStatus::Finished { seconds }
                    }
                    Err(e) => {
                        let _ = multi.println(format!("FAILED {name}: {e}"));
                        if opts.quiet {
                            eprintln!("FAILED {name}: {e}");
                        }
                        RunStatus::Failed(e)
                    }
                }
            })
            .collect()
    });
    total.finish_and_clear();
    statuses
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::config::{Experiment, Overrides};

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
        };
        let runs = runs(4);
        let work = |spec: &RunSpec, dir: &Path, _: &Progress| {
            if spec.seed == 1 {
                return Err("boom".to_string());
            }
            std::fs::create_dir_all(dir).unwrap();
            std::fs::write(dir.join(FINISHED_MARKER), "").unwrap();
            Ok(())
        };
        let first = run_all(&runs, &opts, work);
        assert!(matches!(first[1], RunStatus::Failed(ref e) if e == "boom"));
        assert!(first
            .iter()
            .enumerate()
            .all(|(i, s)| i == 1 || matches!(s, RunStatus::Finished { .. })));
        let second = run_all(&runs, &opts, work);
        assert!(matches!(second[0], RunStatus::Skipped));
        assert!(matches!(second[1], RunStatus::Failed(_)));
    }
}
