//! Train every run of an experiment: what `macdec train` and the Python package's
//! `macdec.train` both call, so the two write the same files. Runs go through the parallel
//! [`runner`](super::runner) ([`run_all`]), each with [`train_run_until`]; a raised
//! [`StopSignal`] starts no new run and stops the running ones at their next episode boundary,
//! resumable.

use super::progress::RunEnd;
use super::runner::{run_all, RunStatus, RunnerOptions};
use super::stop::StopSignal;
use super::train_run::train_run_until;
use crate::experiment::definition::config::RunSpec;

/// Train `runs` as `opts` says (`force` recomputes finished runs), stopping early when `stop` is
/// raised. Returns each run's status in input order: a run not started before the stop is
/// [`RunStatus::Stopped`] too.
pub fn train_all(
    runs: &[RunSpec],
    opts: &RunnerOptions,
    force: bool,
    stop: &StopSignal,
) -> Vec<RunStatus> {
    run_all(runs, opts, |spec, dir, progress| {
        if stop.is_stopped() {
            return Ok(RunEnd::Stopped);
        }
        train_run_until(
            spec,
            dir,
            progress,
            force,
            stop,
            opts.tensorboard.as_deref(),
        )
        .map_err(|e| e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::definition::config::{Experiment, Overrides};
    use crate::experiment::run::metrics;
    use std::path::Path;

    const TINY: &str = r#"
methods = ["our1"]
seeds = "0"
[params]
env_name = "BP_MA"
grid_dim = 8
env_terminate_step = 30
total_epi = 40
eps_l_d_steps = 20
batch_size = 8
replay_buffer_size = 500
eval_freq = 5
checkpoint_freq = 20
"#;

    fn runs() -> Vec<RunSpec> {
        Experiment::parse(TINY, Path::new("t.toml"), "t", &Overrides::default())
            .unwrap()
            .runs()
            .unwrap()
    }

    fn opts(out: &Path) -> RunnerOptions {
        RunnerOptions {
            out: out.to_path_buf(),
            jobs: 1,
            force: false,
            quiet: true,
            tensorboard: None,
        }
    }

    /// A metrics row without its wall-clock column, floats as bits.
    type Row = (u64, u64, u64, u64, Option<u64>, Vec<Option<u64>>);

    /// Every metrics row without its wall-clock column.
    fn rows(dir: &Path) -> Vec<Row> {
        let table = metrics::read(&dir.join(metrics::METRICS_FILE)).unwrap();
        table
            .rows
            .iter()
            .map(|r| {
                let family = r.family.iter().map(|v| v.map(f64::to_bits)).collect();
                (
                    r.episode,
                    r.env_steps,
                    r.updates,
                    r.eval_return.to_bits(),
                    r.eval_return_undiscounted.map(f64::to_bits),
                    family,
                )
            })
            .collect()
    }

    #[test]
    fn a_run_stopped_between_checkpoints_resumes_to_the_uninterrupted_metrics() {
        let root = tempfile::tempdir().unwrap();
        let runs = runs();
        let whole = root.path().join("whole");
        let statuses = train_all(&runs, &opts(&whole), false, &StopSignal::new());
        assert!(matches!(statuses[0], RunStatus::Finished { .. }));

        // Raised before the first episode ends: the run stops after episode 1, between
        // checkpoints (every 20 episodes), with its checkpoint saved there.
        let stopped = root.path().join("stopped");
        let stop = StopSignal::new();
        stop.stop();
        let run_dir = runs[0].dir(&stopped);
        let first = run_all(&runs, &opts(&stopped), |spec, dir, progress| {
            train_run_until(spec, dir, progress, false, &stop, None).map_err(|e| e.to_string())
        });
        assert!(matches!(first[0], RunStatus::Stopped), "{first:?}");
        assert!(run_dir.join("checkpoint.bin").exists());
        assert!(!run_dir.join("finished").exists());
        let partial = metrics::read(&run_dir.join(metrics::METRICS_FILE)).unwrap();
        assert!(
            partial.rows.last().unwrap().episode < 20,
            "not stopped early"
        );

        // A raised signal starts no run at all.
        let untouched = root.path().join("untouched");
        let none = train_all(&runs, &opts(&untouched), false, &stop);
        assert!(matches!(none[0], RunStatus::Stopped));
        assert!(!runs[0].dir(&untouched).exists());

        let resumed = train_all(&runs, &opts(&stopped), false, &StopSignal::new());
        assert!(matches!(resumed[0], RunStatus::Finished { .. }));
        assert_eq!(rows(&runs[0].dir(&whole)), rows(&run_dir));
    }
}
