//! `macdec train --tensorboard DIR`: every run logs its evaluations as TensorBoard scalars while
//! it trains, besides writing them to its `metrics.csv`.
//!
//! A run's events go to `<DIR>/<experiment>/<curve>/seed-<k>/` (the results tree's layout, so
//! `tensorboard --logdir DIR` shows each run as `experiment/curve/seed-k`). At each evaluation
//! the row [`metrics`](super::metrics) records becomes one event: its step is the `episode`
//! column (training episodes completed) and each other column is a scalar tagged by its
//! `metrics.csv` name: `env_steps`, `updates`, `eval_return`, `eval_return_undiscounted`, the
//! family's own (value-based `epsilon`, `hysteresis`, `loss`; actor-critic `eps`,
//! `critic_loss`, `actor_loss`, `train_return`) and `wall_seconds`; an empty cell is no scalar.
//! Plot against environment steps by reading the `env_steps` tag.
//! Values are 32-bit floats, TensorBoard's `simple_value`.
//!
//! The file is flushed after each evaluation. Each time a run trains (first start, resume,
//! `--force`) it creates a new file (see [`EventWriter::create`]) that starts with a session
//! start at step 0 and then holds the run's whole curve so far, taken from its checkpoint: so
//! TensorBoard, which drops a run's earlier events at or after a session start's step, shows
//! exactly the curve `metrics.csv` will hold, with nothing a killed process logged after its
//! last checkpoint. Logging changes no number and is no part of a run's identity: a run trained
//! with and without it is the same run.

use crate::algos::training_loop::EvalPoint;
use crate::experiment::definition::config::RunSpec;
use crate::experiment::run::metrics::{EVAL_RETURN_UNDISCOUNTED, WALL_SECONDS};
use crate::files::links::create_real_dirs;
use crate::files::tensorboard::{Event, EventWriter, Scalar, What};
use std::io;
use std::path::{Path, PathBuf};

/// Check, before any run trains, that `root` can hold event files: a directory (created if
/// missing) this process can create files in. The error names the path and the problem.
pub fn check_root(root: &Path) -> io::Result<()> {
    let named = |what: String| io::Error::other(format!("{}: {what}", root.display()));
    match std::fs::metadata(root) {
        Ok(m) if !m.is_dir() => return Err(named("exists and is not a directory".into())),
        Ok(_) => {}
        Err(_) => {
            std::fs::create_dir_all(root).map_err(|e| named(format!("cannot be created: {e}")))?
        }
    }
    tempfile::Builder::new()
        .prefix(".macdec-write-check")
        .tempfile_in(root)
        .map_err(|e| named(format!("cannot create files in it: {e}")))?;
    Ok(())
}

/// The directory of a run's event files below `root`.
pub fn run_events_dir(root: &Path, spec: &RunSpec) -> PathBuf {
    spec.dir(root)
}

/// The scalars of one metrics row, in `metrics.csv` column order: every column but `episode`
/// (the step), tagged by its name; empty cells are left out.
pub fn scalars(family_columns: &[&str], row: &EvalPoint) -> Vec<Scalar> {
    let mut named: Vec<(&str, Option<f64>)> = vec![
        ("env_steps", Some(row.env_steps as f64)),
        ("updates", Some(row.updates as f64)),
        ("eval_return", Some(row.eval_return)),
        (EVAL_RETURN_UNDISCOUNTED, row.eval_return_undiscounted),
    ];
    named.extend(
        family_columns
            .iter()
            .copied()
            .zip(row.family.iter().copied()),
    );
    named.push((WALL_SECONDS, Some(row.wall_seconds)));
    named
        .into_iter()
        .filter_map(|(tag, value)| {
            value.map(|v| Scalar {
                tag: tag.to_string(),
                value: v as f32,
            })
        })
        .collect()
}

/// The TensorBoard log of one run while it trains: its open event file and how many of the
/// run's evaluation points are in it.
pub struct RunEvents {
    writer: EventWriter,
    family_columns: &'static [&'static str],
    written: usize,
    /// The Unix time the run's `wall_seconds` count from: an evaluation's event is timed at
    /// this plus its `wall_seconds` (the time it was taken, for points of this process).
    clock_zero: f64,
}

impl RunEvents {
    /// Start the log of `spec`'s run below `root`: create its directory (refusing links below
    /// `root`, as the results tree does) and a new event file there, with a session start at
    /// step 0 and then `evals`, the points the run already has (from its checkpoint), flushed.
    /// `wall_seconds` is the run's training time so far.
    pub fn open(
        root: &Path,
        spec: &RunSpec,
        family_columns: &'static [&'static str],
        evals: &[EvalPoint],
        wall_seconds: f64,
    ) -> io::Result<Self> {
        let dir = run_events_dir(root, spec);
        create_real_dirs(root, &dir)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", dir.display())))?;
        let now = unix_now();
        let mut writer = EventWriter::create(&dir, now)?;
        writer.write(&Event {
            wall_time: now,
            step: 0,
            what: What::SessionStart,
        })?;
        let mut log = RunEvents {
            writer,
            family_columns,
            written: 0,
            clock_zero: now - wall_seconds,
        };
        log.log_new(evals)?;
        log.writer.flush()?;
        Ok(log)
    }

    /// Write the points of `evals` (the run's whole curve, growing) not written yet, one event
    /// each, and flush when there were any: cheap to call after every episode.
    pub fn log_new(&mut self, evals: &[EvalPoint]) -> io::Result<()> {
        let Some(new) = evals.get(self.written..).filter(|n| !n.is_empty()) else {
            return Ok(());
        };
        for row in new {
            self.writer.write(&Event {
                wall_time: self.clock_zero + row.wall_seconds,
                step: i64::try_from(row.episode).unwrap_or(i64::MAX),
                what: What::Scalars(scalars(self.family_columns, row)),
            })?;
        }
        self.written = evals.len();
        self.writer.flush()
    }

    /// The event file being written.
    pub fn path(&self) -> &Path {
        self.writer.path()
    }
}

/// Seconds since the Unix epoch (0 on a clock set before it).
fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::definition::config::{Experiment, Overrides};
    use crate::files::tensorboard::{event_files, read_events};

    fn spec() -> RunSpec {
        let e = Experiment::parse("", Path::new("e.toml"), "e", &Overrides::default()).unwrap();
        e.runs().unwrap().remove(0)
    }

    fn point(episode: u64, loss: Option<f64>) -> EvalPoint {
        EvalPoint {
            episode,
            env_steps: 30 * episode,
            updates: episode / 2,
            eval_return: -1.0 + episode as f64 * 0.1,
            eval_return_undiscounted: Some(episode as f64),
            family: vec![Some(0.5), Some(1.0), loss],
            wall_seconds: 0.25 * episode as f64,
        }
    }

    const COLUMNS: &[&str] = &["epsilon", "hysteresis", "loss"];

    fn tags(s: &[Scalar]) -> Vec<&str> {
        s.iter().map(|s| s.tag.as_str()).collect()
    }

    #[test]
    fn every_metrics_column_but_the_episode_is_a_scalar_and_empty_cells_are_left_out() {
        let s = scalars(COLUMNS, &point(10, Some(0.125)));
        assert_eq!(
            tags(&s),
            [
                "env_steps",
                "updates",
                "eval_return",
                "eval_return_undiscounted",
                "epsilon",
                "hysteresis",
                "loss",
                "wall_seconds"
            ]
        );
        let values: Vec<f32> = s.iter().map(|s| s.value).collect();
        assert_eq!(values, [300.0, 5.0, 0.0, 10.0, 0.5, 1.0, 0.125, 2.5]);
        let no_loss = scalars(COLUMNS, &point(0, None));
        assert!(!tags(&no_loss).contains(&"loss"));
        assert_eq!(no_loss.len(), 7);
    }

    #[test]
    fn a_resumed_log_is_a_new_file_with_the_whole_curve_after_a_session_start() {
        let t = tempfile::tempdir().unwrap();
        let root = t.path().join("tb");
        let spec = spec();
        let curve: Vec<EvalPoint> = (0..4).map(|i| point(5 * i, Some(0.5))).collect();

        // A fresh run: a start and nothing else, then points as they come.
        let mut first = RunEvents::open(&root, &spec, COLUMNS, &[], 0.0).unwrap();
        first.log_new(&curve[..2]).unwrap();
        first.log_new(&curve[..2]).unwrap();
        first.log_new(&curve[..3]).unwrap();
        let events = read_events(first.path()).unwrap();
        assert_eq!(events[1].what, What::SessionStart);
        assert_eq!(events[1].step, 0);
        let steps: Vec<i64> = events[2..].iter().map(|e| e.step).collect();
        assert_eq!(steps, [0, 5, 10], "each point once, at its episode");

        // Resumed from a checkpoint holding two points (the third was logged, then lost).
        let resumed = RunEvents::open(&root, &spec, COLUMNS, &curve[..2], 0.5).unwrap();
        let dir = run_events_dir(&root, &spec);
        assert_eq!(dir, root.join("e/our1/seed-0"));
        assert_eq!(
            event_files(&dir).unwrap(),
            [first.path().to_path_buf(), resumed.path().to_path_buf()]
        );
        let events = read_events(resumed.path()).unwrap();
        assert!(matches!(events[0].what, What::FileVersion(_)));
        assert_eq!((events[1].step, &events[1].what), (0, &What::SessionStart));
        let steps: Vec<i64> = events[2..].iter().map(|e| e.step).collect();
        assert_eq!(steps, [0, 5]);
        // Timed on the run's own clock: the second point 1.25 s after the first.
        assert!((events[3].wall_time - events[2].wall_time - 1.25).abs() < 1e-3);
        assert_eq!(events[3].what, What::Scalars(scalars(COLUMNS, &curve[1])));
    }

    #[test]
    fn a_root_that_is_a_file_or_a_link_below_it_is_refused_naming_it() {
        let t = tempfile::tempdir().unwrap();
        let file = t.path().join("file");
        std::fs::write(&file, "").unwrap();
        let e = check_root(&file).unwrap_err().to_string();
        assert_eq!(
            e,
            format!("{}: exists and is not a directory", file.display())
        );
        let e = check_root(&file.join("below")).unwrap_err().to_string();
        assert!(e.contains("cannot be created"), "{e}");
        let fresh = t.path().join("a/b");
        check_root(&fresh).unwrap();
        assert!(fresh.is_dir());
        assert_eq!(
            std::fs::read_dir(&fresh).unwrap().count(),
            0,
            "no probe left"
        );

        // A link where the experiment's directory goes: refused, nothing written through it.
        let outside = t.path().join("outside");
        std::fs::create_dir(&outside).unwrap();
        std::os::unix::fs::symlink(&outside, fresh.join("e")).unwrap();
        let e = RunEvents::open(&fresh, &spec(), COLUMNS, &[], 0.0)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("symbolic link"), "{e}");
        assert_eq!(std::fs::read_dir(&outside).unwrap().count(), 0);
    }
}
