//! Curves from elsewhere drawn beside ours (`macdec plot --beside FILE`): another code's own
//! per-seed logs (ACAC's `icml25_result/log/<env>/<alg>/<seed>.csv`, columns
//! `Timesteps,Eval/Return`), so a reproduction is read against the published runs in one figure
//! and one Welch table.
//!
//! The file names which of our curves each outside curve goes beside:
//!
//! ```toml
//! label = "ACAC's logs"                  # appended to each outside curve's legend
//! source = "LGAI-Research/acac 26b94d9, icml25_result/log (BSD-3)"
//! x_column = "Timesteps"                 # optional, this default: environment steps
//! y_column = "Eval/Return"               # optional, this default: undiscounted return
//!
//! [[curve]]
//! experiment = "bp6"                     # our experiment (the results tree's directory)
//! curve = "mac-iaicc"                    # the legend's method (our curve's name)
//! runs = "bp6/mac_iaicc"                 # a directory of <seed>.csv, relative to this file
//! ```
//!
//! Outside logs hold step counts and undiscounted returns only, so `--beside` draws with `--y
//! undiscounted` against `--x env_steps`, or against `--x acac_timesteps` for ACAC's logs, whose
//! `Timesteps` count only finished training episodes ([`super::axis::XAxis::AcacTimesteps`]).
//! Their runs stop at different steps from ours, so every run of an experiment that has an
//! outside curve, ours included, is read on one grid of steps up to the smallest last step any
//! of its runs reached
//! ([`on_common_steps`]): the summary and Welch tables then compare equal budgets, and their
//! `final_episode` column holds that step count.

use super::discover::{CurveData, ExperimentData, RunData};
use super::error::PlotError;
use crate::algos::families::Method;
use crate::curve_stats::interpolate;
use crate::files::bounded_read::{read_text_file, MAX_TEXT_BYTES};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// At most this many outside curves and runs per curve: a log tree is small.
const MAX_CURVES: usize = 1_000;
const MAX_RUNS: usize = 1_000;
/// At most this many points on the common grid (never more than the sparsest run has).
const MAX_GRID: usize = 1_000;

/// `--beside`'s file, as read.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BesideFile {
    /// Appended to each outside curve's legend, e.g. "ACAC's logs".
    pub label: String,
    /// Where the logs come from (kept for the reader of the file; not drawn).
    #[serde(default)]
    pub source: String,
    /// The column of environment steps.
    #[serde(default = "default_x")]
    pub x_column: String,
    /// The column of undiscounted evaluation returns.
    #[serde(default = "default_y")]
    pub y_column: String,
    /// Which outside runs go beside which of our curves.
    #[serde(default, rename = "curve")]
    pub curves: Vec<BesideCurve>,
}

fn default_x() -> String {
    "Timesteps".into()
}

fn default_y() -> String {
    "Eval/Return".into()
}

/// One outside curve.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BesideCurve {
    /// Our experiment it is drawn in.
    pub experiment: String,
    /// The method it is (for the legend: our curve's name, e.g. `mac-iaicc`).
    pub curve: String,
    /// Its directory of `<seed>.csv` files, relative to the file.
    pub runs: String,
}

fn bad(path: &Path, reason: impl Into<String>) -> PlotError {
    PlotError::Beside {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

/// Read and check `--beside`'s file.
pub fn read_file(path: &Path) -> Result<BesideFile, PlotError> {
    let text = read_text_file(path, MAX_TEXT_BYTES).map_err(|e| bad(path, e.to_string()))?;
    let file: BesideFile = toml::from_str(&text).map_err(|e| bad(path, e.to_string()))?;
    if file.curves.is_empty() {
        return Err(bad(path, "no [[curve]] entries"));
    }
    if file.curves.len() > MAX_CURVES {
        return Err(bad(path, format!("more than {MAX_CURVES} curves")));
    }
    Ok(file)
}

/// The outside curves of `file` (read from `path`), each read from its directory.
pub fn outside_curves(
    path: &Path,
    file: &BesideFile,
) -> Result<Vec<(String, CurveData)>, PlotError> {
    let base = path.parent().unwrap_or(Path::new("."));
    file.curves
        .iter()
        .map(|c| {
            let dir = base.join(&c.runs);
            let runs = read_runs(&dir, &file.x_column, &file.y_column)?;
            let legend = c
                .curve
                .parse::<Method>()
                .map_or(c.curve.clone(), |m| m.legend().into());
            Ok((
                c.experiment.clone(),
                CurveData {
                    name: format!("{legend} ({})", file.label),
                    method: None,
                    variant: String::new(),
                    runs,
                },
            ))
        })
        .collect()
}

/// Every `<seed>.csv` of `dir`, seeds ascending.
fn read_runs(dir: &Path, x: &str, y: &str) -> Result<Vec<RunData>, PlotError> {
    let entries = std::fs::read_dir(dir).map_err(|e| bad(dir, e.to_string()))?;
    let mut files: Vec<(u64, PathBuf)> = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| bad(dir, e.to_string()))?.path();
        if path.extension().and_then(|e| e.to_str()) != Some("csv") {
            continue;
        }
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let seed: u64 = stem
            .parse()
            .map_err(|_| bad(&path, "not <seed>.csv (the name must be the seed)"))?;
        files.push((seed, path));
        if files.len() > MAX_RUNS {
            return Err(bad(dir, format!("more than {MAX_RUNS} runs")));
        }
    }
    if files.is_empty() {
        return Err(bad(dir, "no <seed>.csv files"));
    }
    files.sort();
    files
        .into_iter()
        .map(|(seed, path)| read_run(&path, seed, x, y))
        .collect()
}

/// One outside run: `(step, return)` rows with steps strictly increasing and returns finite.
fn read_run(path: &Path, seed: u64, x: &str, y: &str) -> Result<RunData, PlotError> {
    let text = read_text_file(path, MAX_TEXT_BYTES).map_err(|e| bad(path, e.to_string()))?;
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().map_err(|e| bad(path, e.to_string()))?;
    let column = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| bad(path, format!("no `{name}` column")))
    };
    let (xi, yi) = (column(x)?, column(y)?);
    let mut steps = Vec::new();
    let mut points = Vec::new();
    for (row, record) in reader.records().enumerate() {
        let record = record.map_err(|e| bad(path, e.to_string()))?;
        let line = row + 2;
        let step: u64 = record
            .get(xi)
            .and_then(|s| s.trim().parse().ok())
            .ok_or_else(|| bad(path, format!("line {line}: `{x}` is not a step count")))?;
        let value: f64 = record
            .get(yi)
            .and_then(|s| s.trim().parse().ok())
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| bad(path, format!("line {line}: `{y}` is not a finite number")))?;
        if steps.last().is_some_and(|&last| step <= last) {
            return Err(bad(path, format!("line {line}: steps must increase")));
        }
        steps.push(step);
        points.push((points.len() as u64, value));
    }
    if points.is_empty() {
        return Err(bad(path, "no rows"));
    }
    Ok(RunData {
        seed,
        dir: path.to_path_buf(),
        points,
        steps,
        finished: true,
        wall_seconds: None,
        setting: None,
        provenance: None,
    })
}

/// Put every run of `exp` on one grid of steps (its x axis's step column) from 0 to the smallest
/// last step any run reached, with as many points as the sparsest run has evaluations up to
/// there (at most 1,000): each run's value at a step is linearly interpolated between its
/// evaluations (its first value before its first evaluation), and its points' episode is the
/// step, so every run is complete at the same last "episode" and the tables compare equal
/// budgets. A run that never reached a step past 0 is left out with a note.
pub fn on_common_steps(exp: &mut ExperimentData, notes: &mut Vec<String>) {
    let runs = || exp.curves.iter().flat_map(|c| &c.runs);
    let Some(end) = runs().filter_map(|r| r.steps.last().copied()).min() else {
        return;
    };
    if end == 0 {
        notes.push(format!(
            "{}: a run has no environment steps; nothing to draw beside",
            exp.name
        ));
        return;
    }
    let sparsest = runs()
        .map(|r| r.steps.iter().filter(|&&s| s <= end).count())
        .min()
        .unwrap_or(2);
    let n = sparsest.clamp(2, MAX_GRID);
    let grid: Vec<u64> = (0..n)
        .map(|i| (end as f64 * i as f64 / (n - 1) as f64).round() as u64)
        .collect();
    for curve in &mut exp.curves {
        for run in &mut curve.runs {
            let along: Vec<(f64, f64)> = run
                .steps
                .iter()
                .zip(&run.points)
                .map(|(&s, &(_, v))| (s as f64, v))
                .collect();
            run.points = grid
                .iter()
                .map(|&s| (s, interpolate(&along, s as f64)))
                .collect();
            run.steps = grid.clone();
        }
    }
    notes.push(format!(
        "{}: every run read on {n} points of its step axis from 0 to {end} (the smallest last step), so the tables compare equal budgets",
        exp.name
    ));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, text).unwrap();
        p
    }

    const FILE: &str = r#"
label = "their logs"
source = "somewhere"
[[curve]]
experiment = "bp6"
curve = "mac-iaicc"
runs = "bp6/mac_iaicc"
"#;

    #[test]
    fn outside_runs_are_read_by_seed_with_the_method_legend() {
        let t = tempfile::tempdir().unwrap();
        let f = write(t.path(), "beside.toml", FILE);
        write(
            t.path(),
            "bp6/mac_iaicc/1.csv",
            "Timesteps,Eval/Return\n100,1.5\n250,2.5\n",
        );
        write(
            t.path(),
            "bp6/mac_iaicc/0.csv",
            "Timesteps,Eval/Return\n90,1.0\n",
        );
        write(t.path(), "bp6/mac_iaicc/notes.txt", "not a run");
        let file = read_file(&f).unwrap();
        let curves = outside_curves(&f, &file).unwrap();
        assert_eq!(curves.len(), 1);
        let (exp, c) = &curves[0];
        assert_eq!(exp, "bp6");
        assert_eq!(c.legend(), "Mac-IAICC (their logs)");
        assert_eq!(c.runs.iter().map(|r| r.seed).collect::<Vec<_>>(), [0, 1]);
        assert_eq!(c.runs[1].steps, [100, 250]);
        assert_eq!(c.runs[1].points, [(0, 1.5), (1, 2.5)]);
    }

    #[test]
    fn bad_files_and_logs_are_named() {
        let t = tempfile::tempdir().unwrap();
        let cases = [
            ("label = 1", "invalid type"),
            ("label = \"x\"", "no [[curve]] entries"),
            ("label = \"x\"\ncolour = 2", "unknown field `colour`"),
        ];
        for (text, needle) in cases {
            let f = write(t.path(), "b.toml", text);
            let e = read_file(&f).unwrap_err().to_string();
            assert!(e.contains("b.toml") && e.contains(needle), "{e}");
        }
        let f = write(t.path(), "beside.toml", FILE);
        let file = read_file(&f).unwrap();
        let e = outside_curves(&f, &file).unwrap_err().to_string();
        assert!(e.contains("mac_iaicc"), "{e}");
        for (body, needle) in [
            ("Steps,Eval/Return\n1,2\n", "no `Timesteps` column"),
            ("Timesteps,Eval/Return\n", "no rows"),
            (
                "Timesteps,Eval/Return\n5,1\n5,2\n",
                "line 3: steps must increase",
            ),
            (
                "Timesteps,Eval/Return\n-5,1\n",
                "line 2: `Timesteps` is not a step",
            ),
            (
                "Timesteps,Eval/Return\n5,nan\n",
                "line 2: `Eval/Return` is not a finite",
            ),
        ] {
            let dir = t.path().join("bp6/mac_iaicc");
            let _ = std::fs::remove_dir_all(&dir);
            write(t.path(), "bp6/mac_iaicc/0.csv", body);
            let e = outside_curves(&f, &file).unwrap_err().to_string();
            assert!(e.contains("0.csv") && e.contains(needle), "{e}");
        }
        write(
            t.path(),
            "bp6/mac_iaicc/first.csv",
            "Timesteps,Eval/Return\n1,1\n",
        );
        let e = outside_curves(&f, &file).unwrap_err().to_string();
        assert!(
            e.contains("first.csv") && e.contains("must be the seed"),
            "{e}"
        );
    }

    fn run(steps: &[u64], values: &[f64]) -> RunData {
        RunData {
            seed: 0,
            dir: PathBuf::new(),
            points: values
                .iter()
                .enumerate()
                .map(|(i, &v)| (i as u64, v))
                .collect(),
            steps: steps.to_vec(),
            finished: true,
            wall_seconds: None,
            setting: None,
            provenance: None,
        }
    }

    #[test]
    fn every_run_is_read_on_one_grid_up_to_the_smallest_last_step() {
        let curve = |name: &str, runs| CurveData {
            name: name.into(),
            method: None,
            variant: String::new(),
            runs,
        };
        let mut exp = ExperimentData {
            name: "bp6".into(),
            curves: vec![
                curve(
                    "ours",
                    vec![run(&[0, 100, 200, 300, 400], &[0.0, 1.0, 2.0, 3.0, 4.0])],
                ),
                curve("theirs", vec![run(&[50, 150, 200], &[10.0, 20.0, 30.0])]),
            ],
        };
        let mut notes = Vec::new();
        on_common_steps(&mut exp, &mut notes);
        // Smallest last step 200; the sparsest run has 3 evaluations up to there.
        let ours = &exp.curves[0].runs[0];
        assert_eq!(ours.steps, [0, 100, 200]);
        assert_eq!(ours.points, [(0, 0.0), (100, 1.0), (200, 2.0)]);
        let theirs = &exp.curves[1].runs[0];
        // Before its first evaluation a run holds its first value; 100 is halfway 50..150.
        assert_eq!(theirs.points, [(0, 10.0), (100, 15.0), (200, 30.0)]);
        assert!(notes[0].contains("from 0 to 200"), "{notes:?}");
    }
}
