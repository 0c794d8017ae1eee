//! Python values to and from the TOML values domains read their keys from: `grid_dim=[6, 6]`
//! becomes `grid_dim = [6, 6]`, as a config's `[params]` table would hold it.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyString, PyTuple};

/// How deeply lists and dicts may nest in a parameter value (every domain key is at most two
/// deep, `grid_dim = [6, 6]`); deeper values are refused before the conversion recurses, so a
/// value nested 100 000 deep is a ValueError, not a stack overflow.
pub const MAX_PARAM_DEPTH: usize = 16;

/// One Python value as TOML, nested `depth` lists or dicts deep: bool, int, float, str,
/// list/tuple, dict. `key` names it in errors.
fn to_toml(key: &str, value: &Bound<'_, PyAny>, depth: usize) -> PyResult<toml::Value> {
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if is_numpy_bool(value) {
        return Ok(toml::Value::Boolean(value.is_truthy()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(value.extract()?));
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if let Ok(i) = value.extract::<i64>() {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(f) = value.extract::<f64>() {
        return Ok(toml::Value::Float(f));
    }
    let nests = value.is_instance_of::<PyList>()
        || value.is_instance_of::<PyTuple>()
        || value.is_instance_of::<PyDict>();
    if nests && depth >= MAX_PARAM_DEPTH {
        return Err(PyValueError::new_err(format!(
            "parameter `{key}`: lists and dicts nested more than {MAX_PARAM_DEPTH} deep"
        )));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value
            .iter()?
            .enumerate()
            .map(|(i, v)| to_toml(&format!("{key}[{i}]"), &v?, depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if let Ok(dict) = value.downcast::<PyDict>() {
        return Ok(toml::Value::Table(table_at(dict, Some(key), depth + 1)?));
    }
    Err(PyValueError::new_err(format!(
        "parameter `{key}`: {} is not a parameter value (expected a bool, int, float, str, or a list or dict of them)",
        value.get_type().name()?
    )))
}

/// NumPy's bool scalar (`np.True_`): no Python bool (nor int), yet it must read as a bool, not
/// as the float 1.0 its `__float__` gives. (NumPy's ints and floats convert through
/// `__index__` and `__float__` as Python's do.)
fn is_numpy_bool(value: &Bound<'_, PyAny>) -> bool {
    let t = value.get_type();
    let module = t
        .getattr("__module__")
        .and_then(|m| m.extract::<String>())
        .unwrap_or_default();
    let name = t.name().map(|n| n.to_string()).unwrap_or_default();
    module == "numpy" && (name == "bool" || name == "bool_")
}

/// A dict of parameters as a TOML table; keys must be strings.
pub fn to_table(dict: &Bound<'_, PyDict>, within: Option<&str>) -> PyResult<toml::Table> {
    table_at(dict, within, 0)
}

/// [`to_table`] of a dict nested `depth` lists or dicts deep.
fn table_at(dict: &Bound<'_, PyDict>, within: Option<&str>, depth: usize) -> PyResult<toml::Table> {
    let mut table = toml::Table::new();
    for (k, v) in dict.iter() {
        let key: String = k.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "parameter names must be strings, got {}",
                k.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        })?;
        let path = match within {
            Some(outer) => format!("{outer}.{key}"),
            None => key.clone(),
        };
        table.insert(key, to_toml(&path, &v, depth)?);
    }
    Ok(table)
}

/// A TOML value as the Python value it reads as.
pub fn to_py(py: Python<'_>, value: &toml::Value) -> PyObject {
    match value {
        toml::Value::String(s) => s.into_py(py),
        toml::Value::Integer(i) => i.into_py(py),
        toml::Value::Float(f) => f.into_py(py),
        toml::Value::Boolean(b) => b.into_py(py),
        toml::Value::Datetime(d) => d.to_string().into_py(py),
        toml::Value::Array(items) => {
            PyList::new_bound(py, items.iter().map(|v| to_py(py, v))).into_py(py)
        }
        toml::Value::Table(t) => table_to_py(py, t).into_py(py),
    }
}

/// A TOML table as a dict, in the table's order.
pub fn table_to_py<'py>(py: Python<'py>, table: &toml::Table) -> Bound<'py, PyDict> {
    let dict = PyDict::new_bound(py);
    for (k, v) in table {
        dict.set_item(k, to_py(py, v))
            .expect("setting a str key on a fresh dict cannot fail");
    }
    dict
}
