//! Every run of a results tree as columns for `macdec.load_results`: read by the same reader
//! as `macdec results` ([`macdec::experiment::run::tidy_table`]), so the two give the same rows.

use crate::guarded;
use macdec::experiment::run::metrics::{EVAL_RETURN_UNDISCOUNTED, LEADING_COLUMNS, WALL_SECONDS};
use macdec::experiment::run::tidy_table::{read_run, tidy_runs, TidyError};
use numpy::IntoPyArray;
use pyo3::exceptions::{PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;

/// The runs and their rows, as plain vectors (built without the GIL).
struct Columns {
    /// (experiment, method, variant, seed) of each run.
    runs: Vec<(String, String, String, u64)>,
    /// The run of each row (index into `runs`).
    run_index: Vec<i64>,
    episode: Vec<i64>,
    env_steps: Vec<i64>,
    updates: Vec<i64>,
    eval_return: Vec<f64>,
    /// NaN for runs trained before the column existed.
    eval_return_undiscounted: Vec<f64>,
    /// Every family column of any run, in order of first appearance, NaN where a run lacks it.
    family: Vec<(String, Vec<f64>)>,
    wall_seconds: Vec<f64>,
}

fn read_all(root: &std::path::Path) -> Result<Columns, TidyError> {
    let runs = tidy_runs(root)?;
    let mut c = Columns {
        runs: Vec::with_capacity(runs.len()),
        run_index: Vec::new(),
        episode: Vec::new(),
        env_steps: Vec::new(),
        updates: Vec::new(),
        eval_return: Vec::new(),
        eval_return_undiscounted: Vec::new(),
        family: Vec::new(),
        wall_seconds: Vec::new(),
    };
    for (i, run) in runs.iter().enumerate() {
        let table = read_run(run)?;
        let before = c.episode.len();
        let at: Vec<usize> = table
            .family_columns
            .iter()
            .map(|name| match c.family.iter().position(|(n, _)| n == name) {
                Some(k) => k,
                None => {
                    c.family.push((name.clone(), vec![f64::NAN; before]));
                    c.family.len() - 1
                }
            })
            .collect();
        for r in &table.rows {
            c.run_index.push(i as i64);
            c.episode.push(r.episode as i64);
            c.env_steps.push(r.env_steps as i64);
            c.updates.push(r.updates as i64);
            c.eval_return.push(r.eval_return);
            c.eval_return_undiscounted
                .push(r.eval_return_undiscounted.unwrap_or(f64::NAN));
            c.wall_seconds.push(r.wall_seconds);
            for (_, col) in c.family.iter_mut() {
                col.push(f64::NAN);
            }
            for (j, &k) in at.iter().enumerate() {
                if let Some(v) = r.family[j] {
                    *c.family[k].1.last_mut().expect("just pushed") = v;
                }
            }
        }
        c.runs.push((
            run.experiment.clone(),
            run.method.clone(),
            run.variant.clone(),
            run.seed,
        ));
    }
    Ok(c)
}

/// Read every run below `root`: a dict with `runs` (a list of `(experiment, method, variant,
/// seed)`), `run_index` (each row's run, int64), `values` (one NumPy array per metrics column,
/// by name, so no column name can collide with these keys) and `columns` (their names in table
/// order; empty cells are NaN).
#[pyfunction]
pub fn read_results<'py>(py: Python<'py>, root: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    guarded(|| {
        if !root.is_dir() {
            return Err(PyFileNotFoundError::new_err(format!(
                "{}: no such results directory",
                root.display()
            )));
        }
        let c = py
            .allow_threads(|| read_all(&root))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let out = PyDict::new_bound(py);
        out.set_item("runs", PyList::new_bound(py, c.runs))?;
        out.set_item("run_index", c.run_index.into_pyarray_bound(py))?;
        let values = PyDict::new_bound(py);
        let mut names: Vec<String> = LEADING_COLUMNS.iter().map(|s| s.to_string()).collect();
        values.set_item("episode", c.episode.into_pyarray_bound(py))?;
        values.set_item("env_steps", c.env_steps.into_pyarray_bound(py))?;
        values.set_item("updates", c.updates.into_pyarray_bound(py))?;
        values.set_item("eval_return", c.eval_return.into_pyarray_bound(py))?;
        values.set_item(
            EVAL_RETURN_UNDISCOUNTED,
            c.eval_return_undiscounted.into_pyarray_bound(py),
        )?;
        names.push(EVAL_RETURN_UNDISCOUNTED.to_string());
        for (name, col) in c.family {
            values.set_item(&name, col.into_pyarray_bound(py))?;
            names.push(name);
        }
        values.set_item(WALL_SECONDS, c.wall_seconds.into_pyarray_bound(py))?;
        names.push(WALL_SECONDS.to_string());
        out.set_item("values", values)?;
        out.set_item("columns", names)?;
        Ok(out)
    })
}
