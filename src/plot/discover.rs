//! Finding the runs of a results tree: `<results>/<experiment>/<curve>/seed-<k>/` with a
//! `metrics.csv`, a `config.toml` and, once complete, a `finished` marker
//! (`experiment::definition::config`, `experiment::run::runner`).
//!
//! Results trees collect junk (a run killed before its first evaluation, a stray file, a copy
//! being synced), so anything that is not a run is skipped with a note. A malformed metrics file
//! is skipped with a warning as long as some other run is readable; if none is, it is the error.

use super::error::PlotError;
use super::setting::EnvSetting;
use crate::algos::families::Method;
use crate::experiment::run::metrics::{self, MetricsError};
use crate::experiment::run::provenance::Provenance;
use crate::experiment::run::results_tree;
use crate::files::bounded_read::{read_text_in_tree, MAX_TEXT_BYTES};
use std::path::{Path, PathBuf};

pub use crate::experiment::definition::config::SHARED_CURVES_FILE;
pub use crate::experiment::run::metrics::METRICS_FILE;
/// The file each run writes its resolved config to.
pub use crate::experiment::run::results_tree::CONFIG as CONFIG_FILE;

/// One run's learning curve and what a figure needs to know about it.
#[derive(Debug, Clone, PartialEq)]
pub struct RunData {
    /// The run's seed (from `seed-<k>`).
    pub seed: u64,
    /// The run directory.
    pub dir: PathBuf,
    /// `(episode, value)` per evaluation of the plotted column (`eval_return` unless another
    /// was asked for; rows with an empty cell are left out), episodes strictly increasing.
    pub points: Vec<(u64, f64)>,
    /// The step count of the x axis at the same rows as `points`, for figures and exports
    /// against steps rather than episodes: the `env_steps` column (environment steps taken when
    /// each evaluation ran), or the column `--x` names instead
    /// ([`crate::plot::axis::XAxis::steps_column`]).
    pub steps: Vec<u64>,
    /// Whether the run wrote its `finished` marker.
    pub finished: bool,
    /// Wall-clock seconds at the run's last evaluation; None for another code's logs drawn
    /// `--beside` ours, which record neither their time nor a provenance.
    pub wall_seconds: Option<f64>,
    /// The domain setting from `config.toml`, when it is present and readable.
    pub setting: Option<EnvSetting>,
    /// The build and machine that trained the run, when its `config.toml` records them.
    pub provenance: Option<Provenance>,
}

impl RunData {
    /// `(step count, value)` per evaluation: the run's curve against its [`RunData::steps`].
    pub fn along_steps(&self) -> Vec<(u64, f64)> {
        let values = self.points.iter().map(|&(_, v)| v);
        self.steps.iter().copied().zip(values).collect()
    }
}

/// All runs of one curve (a method, or a method at one sweep point), seeds ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveData {
    /// The directory name: `our1` or `our1@trace_len=10,l_rate=0.001`.
    pub name: String,
    /// The method, when the name starts with one of the five.
    pub method: Option<Method>,
    /// The sweep point after `@`, empty without a sweep.
    pub variant: String,
    /// The curve's runs, by seed.
    pub runs: Vec<RunData>,
}

impl CurveData {
    /// The paper's legend name, with the sweep point appended:
    /// `Our-1` or `Our-1 @ trace_len=10, l_rate=0.001`. Unknown methods keep their directory name.
    pub fn legend(&self) -> String {
        let base = self.method.map_or(self.name.as_str(), |m| m.legend());
        if self.method.is_none() || self.variant.is_empty() {
            base.to_string()
        } else {
            format!("{base} @ {}", self.variant.replace(',', ", "))
        }
    }
}

/// The curves of one experiment, in the paper's method order, then by sweep point.
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentData {
    /// The experiment's directory name.
    pub name: String,
    /// Its curves.
    pub curves: Vec<CurveData>,
}

/// Everything found under a results root, plus notes on what was skipped and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Discovery {
    /// The experiments found, by name.
    pub experiments: Vec<ExperimentData>,
    /// What was skipped and why.
    pub notes: Vec<String>,
}

/// Scan `results` for runs' `eval_return` curves (see [`discover_metric`]).
pub fn discover(results: &Path) -> Result<Discovery, PlotError> {
    discover_metric(results, EVAL_RETURN)
}

/// The column plotted by default: the evaluated policy's return.
pub const EVAL_RETURN: &str = "eval_return";

/// The step column runs are read with unless an axis asks for another.
pub const ENV_STEPS: &str = "env_steps";

/// Scan `results` for runs, reading the `metric` column of each `metrics.csv` (any leading or
/// family column) with its `env_steps` (see [`discover_along`]).
pub fn discover_metric(results: &Path, metric: &str) -> Result<Discovery, PlotError> {
    discover_along(results, metric, ENV_STEPS)
}

/// Scan `results` for runs, reading the `metric` column of each `metrics.csv` and the column of
/// step counts `steps_column` (`env_steps`, or another an x axis draws against:
/// [`crate::plot::axis::XAxis::steps_column`]). Fails only when the root cannot be read, when
/// it holds no run at all, or when every metrics file found is malformed. A run without either
/// column is skipped with a note.
pub fn discover_along(
    results: &Path,
    metric: &str,
    steps_column: &str,
) -> Result<Discovery, PlotError> {
    let exp_dirs = sorted_subdirs(results).map_err(|source| PlotError::ReadResults {
        path: results.to_path_buf(),
        source,
    })?;
    let mut notes = Vec::new();
    let mut malformed: Vec<(PathBuf, String)> = Vec::new();
    let mut experiments = Vec::new();
    for exp_dir in exp_dirs {
        let mut curves = Vec::new();
        for curve_dir in curve_dirs(results, &exp_dir, &mut notes) {
            let name = file_name(&curve_dir);
            let (method_name, variant) = name.split_once('@').unwrap_or((&name, ""));
            let method = method_name.parse::<Method>().ok();
            let mut runs = Vec::new();
            for run_dir in subdirs_or_note(&curve_dir, &mut notes) {
                match read_run(&run_dir, metric, steps_column) {
                    Ok(run) => runs.push(run),
                    Err(RunProblem::Skip(why)) => {
                        notes.push(format!("skipping {}: {why}", run_dir.display()))
                    }
                    Err(RunProblem::Malformed(path, why)) => malformed.push((path, why)),
                }
            }
            if runs.is_empty() {
                continue;
            }
            if method.is_none() {
                notes.push(format!(
                    "{}: `{method_name}` is not a known method; using the directory name as its legend",
                    curve_dir.display()
                ));
            }
            runs.sort_by_key(|r| r.seed);
            curves.push(CurveData {
                method,
                variant: variant.to_string(),
                name,
                runs,
            });
        }
        curves.sort_by_key(curve_order);
        if !curves.is_empty() {
            experiments.push(ExperimentData {
                name: file_name(&exp_dir),
                curves,
            });
        }
    }
    if experiments.is_empty() {
        return Err(match malformed.into_iter().next() {
            Some((path, message)) => PlotError::Malformed { path, message },
            None => PlotError::NoRuns {
                path: results.to_path_buf(),
            },
        });
    }
    for (path, why) in malformed {
        notes.push(format!(
            "warning: skipping malformed {}: {why}",
            path.display()
        ));
    }
    Ok(Discovery { experiments, notes })
}

/// The curve directories of an experiment: its own, plus those its `shared_curves.toml` names in
/// another experiment (which replace an own directory of the same name, with a note).
fn curve_dirs(results: &Path, exp_dir: &Path, notes: &mut Vec<String>) -> Vec<PathBuf> {
    let mut dirs = subdirs_or_note(exp_dir, notes);
    let shared_path = exp_dir.join(SHARED_CURVES_FILE);
    if std::fs::symlink_metadata(&shared_path).is_err() {
        return dirs;
    }
    let shared: std::collections::BTreeMap<String, String> =
        match read_text_in_tree(&shared_path, MAX_TEXT_BYTES)
            .map_err(|e| e.to_string())
            .and_then(|t| toml::from_str(&t).map_err(|e| e.to_string()))
        {
            Ok(map) => map,
            Err(e) => {
                notes.push(format!("warning: ignoring {}: {e}", shared_path.display()));
                return dirs;
            }
        };
    let plain = |s: &str| {
        !s.is_empty()
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "_-@=.,".contains(c))
            && !s.contains("..")
    };
    for (curve, home) in shared {
        if !plain(&curve) || !plain(&home) {
            notes.push(format!(
                "warning: {}: `{curve} = {home:?}` is not a curve and experiment name; ignored",
                shared_path.display()
            ));
            continue;
        }
        let target = results.join(&home).join(&curve);
        // A real directory: a link would draw runs from outside the results tree.
        if !std::fs::symlink_metadata(&target).is_ok_and(|m| m.is_dir()) {
            notes.push(format!(
                "{}: shared curve {curve} has no runs yet in {}",
                exp_dir.display(),
                target.display()
            ));
            continue;
        }
        if let Some(i) = dirs.iter().position(|d| file_name(d) == curve) {
            notes.push(format!(
                "{}: {curve} is shared with {home}; its own directory is ignored",
                exp_dir.display()
            ));
            dirs.remove(i);
        }
        dirs.push(target);
    }
    dirs
}

/// Paper order of methods (`Method::ALL`), then sweep point; unknown names last.
fn curve_order(c: &CurveData) -> (usize, String, String) {
    let rank = c
        .method
        .and_then(|m| Method::all().iter().position(|&x| x == m))
        .unwrap_or(Method::all().len());
    (rank, c.variant.clone(), c.name.clone())
}

enum RunProblem {
    /// Not a run (or not one yet): a note.
    Skip(String),
    /// A run whose metrics file cannot be used: a warning, or the error if nothing else exists.
    Malformed(PathBuf, String),
}

fn read_run(dir: &Path, metric: &str, steps_column: &str) -> Result<RunData, RunProblem> {
    let name = file_name(dir);
    let seed = results_tree::parse_seed_dir(&name)
        .ok_or_else(|| RunProblem::Skip("not a seed-<k> directory".into()))?;
    let Some(metrics_path) = metrics::locate(dir) else {
        return Err(RunProblem::Skip(format!("no {METRICS_FILE}")));
    };
    let bad = |why: String| RunProblem::Malformed(metrics_path.clone(), why);
    let table = metrics::read(&metrics_path).map_err(|e| {
        bad(match e {
            MetricsError::Csv { source, .. } => source.to_string(),
            MetricsError::Io { source, .. } => source.to_string(),
            MetricsError::Layout { message, .. } => message,
        })
    })?;
    let rows = &table.rows;
    if rows.is_empty() {
        // A header alone is a run before its first evaluation (`metrics::read` has already
        // refused a header that is not a metrics file's).
        return Err(RunProblem::Skip("no evaluation rows yet".into()));
    }
    for (i, pair) in rows.windows(2).enumerate() {
        if pair[1].episode <= pair[0].episode {
            return Err(bad(format!(
                "row {}: episode {} does not increase (previous {})",
                i + 2,
                pair[1].episode,
                pair[0].episode
            )));
        }
    }
    let Some(values) = table.column(metric) else {
        return Err(RunProblem::Skip(format!(
            "no `{metric}` column (it has {})",
            table.family_columns.join(", ")
        )));
    };
    // Step counts are whole numbers far below 2^53, so they pass through f64 exactly.
    let Some(counts) = table.column(steps_column) else {
        return Err(RunProblem::Skip(format!(
            "no `{steps_column}` column to draw against (it has {})",
            table.family_columns.join(", ")
        )));
    };
    let steps = counts
        .into_iter()
        .map(|c| c.filter(|c| c.is_finite() && *c >= 0.0).map(|c| c as u64));
    let (points, steps): (Vec<(u64, f64)>, Vec<u64>) = rows
        .iter()
        .zip(values)
        .zip(steps)
        .filter_map(|((r, v), s)| Some(((r.episode, v?), s?)))
        .unzip();
    if let Some((episode, value)) = points.iter().find(|(_, v)| !v.is_finite()) {
        return Err(bad(format!("episode {episode}: {metric} is {value}")));
    }
    if points.is_empty() {
        return Err(RunProblem::Skip(format!("no `{metric}` values yet")));
    }
    let config_text = read_text_in_tree(&dir.join(CONFIG_FILE), MAX_TEXT_BYTES).ok();
    let setting = config_text
        .as_deref()
        .and_then(|text| EnvSetting::from_config_toml(text).ok());
    let provenance = config_text.as_deref().and_then(|text| {
        let mut table: toml::Table = toml::from_str(text).ok()?;
        table.remove("provenance")?.try_into().ok()
    });
    Ok(RunData {
        seed,
        dir: dir.to_path_buf(),
        points,
        steps,
        finished: results_tree::is_finished(dir),
        wall_seconds: Some(rows.last().map_or(0.0, |r| r.wall_seconds)),
        setting,
        provenance,
    })
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Subdirectories sorted by name (files are ignored: they are not part of the layout; nor are
/// links, which would lead out of the results tree).
fn sorted_subdirs(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut dirs = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        if entry.file_type()?.is_dir() {
            dirs.push(entry.path());
        }
    }
    dirs.sort();
    Ok(dirs)
}

fn subdirs_or_note(dir: &Path, notes: &mut Vec<String>) -> Vec<PathBuf> {
    sorted_subdirs(dir).unwrap_or_else(|e| {
        notes.push(format!("skipping {}: {e}", dir.display()));
        Vec::new()
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::algos::value::method::ValueMethod;
    use crate::envs::EnvSpec;
    use crate::experiment::definition::run_settings::RunSettings;
    use crate::experiment::run::metrics::MetricsRow;

    /// Write a synthetic run: returns at the given episodes, a config, and optionally the marker.
    pub(crate) fn write_run(
        root: &Path,
        experiment: &str,
        curve: &str,
        seed: u64,
        points: &[(u64, f64)],
        env: EnvSpec,
        finished: bool,
    ) -> PathBuf {
        let dir = root
            .join(experiment)
            .join(curve)
            .join(results_tree::seed_dir_name(seed));
        std::fs::create_dir_all(&dir).unwrap();
        let rows: Vec<MetricsRow> = points
            .iter()
            .map(|&(episode, eval_return)| MetricsRow {
                episode,
                env_steps: episode * 50,
                updates: episode / 2,
                eval_return,
                eval_return_undiscounted: Some(eval_return),
                family: vec![Some(1.0), Some(1.0), None],
                wall_seconds: episode as f64 * 0.5,
            })
            .collect();
        let columns = crate::algos::value::learner::METRIC_COLUMNS;
        metrics::write(&dir.join(METRICS_FILE), &columns, &rows).unwrap();
        let config = RunSettings::paper(env, Method::Value(ValueMethod::Our1));
        std::fs::write(dir.join(CONFIG_FILE), toml::to_string(&config).unwrap()).unwrap();
        if finished {
            std::fs::write(dir.join(results_tree::FINISHED), "").unwrap();
        }
        dir
    }

    fn bp10_spec() -> EnvSpec {
        crate::envs::box_pushing::spec(10, 100)
    }

    #[test]
    fn finds_experiments_curves_and_seeds_in_paper_order() {
        let t = tempfile::tempdir().unwrap();
        let pts = [(0, 1.0), (10, 2.0)];
        write_run(t.path(), "fig4a", "our1", 10, &pts, bp10_spec(), true);
        write_run(t.path(), "fig4a", "our1", 2, &pts[..1], bp10_spec(), false);
        write_run(t.path(), "fig4a", "dec-hddrqn", 0, &pts, bp10_spec(), true);
        write_run(
            t.path(),
            "fig4a",
            "our1@trace_len=10",
            0,
            &pts,
            bp10_spec(),
            true,
        );
        let d = discover(t.path()).unwrap();
        assert_eq!(d.experiments.len(), 1);
        let names: Vec<&str> = d.experiments[0]
            .curves
            .iter()
            .map(|c| c.name.as_str())
            .collect();
        assert_eq!(names, ["dec-hddrqn", "our1", "our1@trace_len=10"]);
        let our1 = &d.experiments[0].curves[1];
        assert_eq!(
            our1.runs.iter().map(|r| r.seed).collect::<Vec<_>>(),
            [2, 10]
        );
        assert!(!our1.runs[0].finished && our1.runs[1].finished);
        assert_eq!(our1.runs[0].points, vec![(0, 1.0)]);
        // write_run records env_steps = 50 x episode, row for row with the returns.
        assert_eq!(our1.runs[1].steps, vec![0, 500]);
        assert_eq!(our1.runs[1].wall_seconds, Some(5.0));
        assert_eq!(
            our1.runs[1].setting.clone().unwrap().optimal_return(),
            Some(80.71093744250365)
        );
        assert!(d.notes.is_empty(), "{:?}", d.notes);
    }

    #[test]
    fn legends_use_the_paper_names_with_the_sweep_point() {
        let c = |name: &str, method, variant: &str| CurveData {
            name: name.into(),
            method,
            variant: variant.into(),
            runs: vec![],
        };
        assert_eq!(
            c("our1-r", Some(Method::Value(ValueMethod::Our1R)), "").legend(),
            "Our-1-R"
        );
        assert_eq!(
            c(
                "our2@l_rate=0.001,trace_len=10",
                Some(Method::Value(ValueMethod::Our2)),
                "l_rate=0.001,trace_len=10"
            )
            .legend(),
            "Our-2 @ l_rate=0.001, trace_len=10"
        );
        assert_eq!(c("mine", None, "").legend(), "mine");
    }

    #[test]
    fn shared_curves_are_read_from_the_experiment_they_belong_to() {
        let t = tempfile::tempdir().unwrap();
        let bp = crate::envs::box_pushing::paper_spec(10);
        write_run(t.path(), "fig5", "our2", 0, &[(0, 1.0)], bp.clone(), true);
        write_run(t.path(), "fig5", "our2", 1, &[(0, 2.0)], bp.clone(), true);
        write_run(t.path(), "fig6", "our1", 0, &[(0, 3.0)], bp.clone(), true);
        // A stale own copy is replaced by the shared one, with a note.
        write_run(t.path(), "fig6", "our2", 7, &[(0, 9.0)], bp.clone(), true);
        std::fs::write(
            t.path().join("fig6").join(SHARED_CURVES_FILE),
            "our2 = \"fig5\"\nour1-r = \"fig5\"\nbad = \"../x\"\n",
        )
        .unwrap();
        let d = discover(t.path()).unwrap();
        let fig6 = d.experiments.iter().find(|e| e.name == "fig6").unwrap();
        let names: Vec<&str> = fig6.curves.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["our1", "our2"]);
        let seeds: Vec<u64> = fig6.curves[1].runs.iter().map(|r| r.seed).collect();
        assert_eq!(seeds, [0, 1]);
        let notes = d.notes.join("\n");
        assert!(notes.contains("our2 is shared with fig5"), "{notes}");
        assert!(
            notes.contains("shared curve our1-r has no runs yet"),
            "{notes}"
        );
        assert!(notes.contains("not a curve and experiment name"), "{notes}");
        // fig5 itself still has its curve.
        let fig5 = d.experiments.iter().find(|e| e.name == "fig5").unwrap();
        assert_eq!(fig5.curves[0].runs.len(), 2);
    }

    #[test]
    fn junk_is_skipped_with_notes() {
        let t = tempfile::tempdir().unwrap();
        write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        std::fs::create_dir_all(t.path().join("e/our1/seed-1")).unwrap(); // no metrics yet
        std::fs::create_dir_all(t.path().join("e/our1/tmp")).unwrap(); // not a seed dir
        std::fs::write(t.path().join("e/README.txt"), "stray file").unwrap();
        std::fs::create_dir_all(t.path().join("empty_experiment/our1")).unwrap();
        let d = discover(t.path()).unwrap();
        assert_eq!(d.experiments.len(), 1);
        assert_eq!(d.experiments[0].curves[0].runs.len(), 1);
        assert_eq!(d.notes.len(), 2, "{:?}", d.notes);
        assert!(d.notes[0].contains("seed-1") && d.notes[0].contains("no metrics.csv"));
        assert!(d.notes[1].contains("tmp") && d.notes[1].contains("seed-<k>"));
    }

    #[test]
    fn malformed_csv_is_a_warning_when_other_runs_exist() {
        let t = tempfile::tempdir().unwrap();
        write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        let bad = write_run(t.path(), "e", "our1", 1, &[(0, 1.0)], bp10_spec(), true);
        std::fs::write(bad.join(METRICS_FILE), "episode,eval_return\nten,abc\n").unwrap();
        let d = discover(t.path()).unwrap();
        assert_eq!(d.experiments[0].curves[0].runs.len(), 1);
        assert!(d
            .notes
            .iter()
            .any(|n| n.starts_with("warning") && n.contains("seed-1/metrics.csv")));
    }

    #[test]
    fn malformed_csv_is_the_error_when_it_is_the_only_run() {
        let t = tempfile::tempdir().unwrap();
        let bad = write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        std::fs::write(bad.join(METRICS_FILE), "episode,eval_return\nten,abc\n").unwrap();
        let err = discover(t.path()).unwrap_err();
        assert!(matches!(err, PlotError::Malformed { .. }));
        assert!(err.to_string().contains("seed-0/metrics.csv"), "{err}");
    }

    #[test]
    fn a_header_only_run_is_skipped_but_a_foreign_header_is_malformed() {
        let t = tempfile::tempdir().unwrap();
        write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        write_run(t.path(), "e", "our1", 1, &[], bp10_spec(), false);
        let foreign = write_run(t.path(), "e", "our1", 2, &[(0, 1.0)], bp10_spec(), true);
        std::fs::write(foreign.join(METRICS_FILE), "x,y\n").unwrap();
        let d = discover(t.path()).unwrap();
        assert_eq!(d.experiments[0].curves[0].runs.len(), 1);
        assert!(d.notes[0].contains("seed-1") && d.notes[0].contains("no evaluation rows"));
        assert!(d.notes[1].starts_with("warning") && d.notes[1].contains("seed-2"));
        assert!(d.notes[1].contains("eval_return"), "{:?}", d.notes);
    }

    #[test]
    fn episodes_that_go_backwards_are_malformed() {
        let t = tempfile::tempdir().unwrap();
        write_run(
            t.path(),
            "e",
            "our1",
            0,
            &[(10, 1.0), (10, 2.0)],
            bp10_spec(),
            true,
        );
        let err = discover(t.path()).unwrap_err();
        assert!(err.to_string().contains("does not increase"), "{err}");
    }

    #[test]
    fn empty_or_missing_results_are_errors() {
        let t = tempfile::tempdir().unwrap();
        assert!(matches!(
            discover(t.path()).unwrap_err(),
            PlotError::NoRuns { .. }
        ));
        assert!(matches!(
            discover(&t.path().join("nope")).unwrap_err(),
            PlotError::ReadResults { .. }
        ));
    }

    #[test]
    fn along_acac_timesteps_runs_are_read_with_that_column_and_others_are_skipped() {
        let t = tempfile::tempdir().unwrap();
        // An ACAC run: 100 steps of finished episodes per 240 steps taken, a row without the
        // count left out.
        let acac = write_run(t.path(), "e", "acac", 0, &[(0, 1.0)], bp10_spec(), true);
        let rows: Vec<MetricsRow> = [(16, Some(100.0)), (32, None), (48, Some(300.0))]
            .into_iter()
            .map(|(episode, counted)| MetricsRow {
                episode,
                env_steps: episode * 15,
                updates: episode / 16,
                eval_return: 2.0,
                eval_return_undiscounted: Some(2.0),
                family: vec![counted, Some(0.5), None, None, None],
                wall_seconds: 1.0,
            })
            .collect();
        let columns = crate::algos::acac::learner::METRIC_COLUMNS;
        metrics::write(&acac.join(METRICS_FILE), &columns, &rows).unwrap();
        write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        let d = discover_along(t.path(), EVAL_RETURN, "acac_timesteps").unwrap();
        let curves = &d.experiments[0].curves;
        assert_eq!(curves.len(), 1, "the value run has no such column");
        assert_eq!(curves[0].runs[0].steps, [100, 300]);
        assert_eq!(curves[0].runs[0].points, [(16, 2.0), (48, 2.0)]);
        assert!(d.notes.iter().any(
            |n| n.contains("our1") && n.contains("no `acac_timesteps` column to draw against")
        ));
        // Along env_steps the same runs give the steps taken.
        let d = discover_along(t.path(), EVAL_RETURN, ENV_STEPS).unwrap();
        let acac = d.experiments[0]
            .curves
            .iter()
            .find(|c| c.name == "acac")
            .unwrap();
        assert_eq!(acac.runs[0].steps, [240, 480, 720]);
    }
}
