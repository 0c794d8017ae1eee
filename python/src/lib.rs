//! The Rust core of the Python package `macdec` (`macdec._macdec`): environments ([`env`]),
//! training ([`train`]), results ([`results`]) and policies ([`policy`]), each a thin layer over
//! the library functions the `macdec` command line calls. The Python layer in `macdec/` turns
//! these into a PettingZoo `ParallelEnv`, a DataFrame and dicts keyed by agent.

// PyO3 0.22's `#[pymethods]` expansion converts every `PyResult` error into itself, which this
// clippy reports at each method's signature (PyO3 issue 4327); nothing in our code converts.
#![allow(clippy::useless_conversion)]

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

mod env;
mod params;
mod policy;
mod results;
mod train;

/// Runs one call into the library, turning a panic (a bug in macdec, whatever the input) into a
/// `RuntimeError` naming it: PyO3's own `PanicException` derives from `BaseException`, so it
/// would escape a user's `except Exception` and end their process or notebook kernel. Every
/// entry point that does more than read a field goes through here. An object whose call
/// panicked may be half-updated: the message says to rebuild it.
pub(crate) fn guarded<T>(call: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(call)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into());
        Err(PyRuntimeError::new_err(format!(
            "internal error in macdec: {what} (a bug: please report it with the call that caused \
             it; rebuild the object before using it again)"
        )))
    })
}

/// Panics inside [`guarded`], so the tests can check that a panic reaches Python as a
/// `RuntimeError` (no public input is known to panic; this is the only way to cause one).
#[pyfunction]
fn _panic_for_test() -> PyResult<()> {
    guarded(|| panic!("a test panic"))
}

/// The extension module.
#[pymodule]
fn _macdec(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<env::Env>()?;
    m.add_class::<env::VectorEnv>()?;
    m.add_class::<policy::Policy>()?;
    m.add_function(wrap_pyfunction!(env::env_ids, m)?)?;
    m.add_function(wrap_pyfunction!(train::train, m)?)?;
    m.add_function(wrap_pyfunction!(results::read_results, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    Ok(())
}
