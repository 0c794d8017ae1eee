//! The Rust core of the Python package `macdec` (`macdec._macdec`): environments ([`env`]),
//! training ([`train`]), results ([`results`]) and policies ([`policy`]), each a thin layer over
//! the library functions the `macdec` command line calls. The Python layer in `macdec/` turns
//! these into a PettingZoo `ParallelEnv`, a DataFrame and dicts keyed by agent.

// PyO3 0.22's `#[pymethods]` expansion converts every `PyResult` error into itself, which this
// clippy reports at each method's signature (PyO3 issue 4327); nothing in our code converts.
#![allow(clippy::useless_conversion)]

use pyo3::prelude::*;

mod env;
mod params;
mod policy;
mod results;
mod train;

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
    Ok(())
}
