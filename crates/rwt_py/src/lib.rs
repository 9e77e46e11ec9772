//! The native half of the Python package `rwt`: rwt_core's queries, stippling and analysis
//! over numpy arrays. The Python half (`python/rwt`) checks arguments, turns callables into
//! densities and shapes the results; everything here runs with the GIL released.

mod analyse;
mod errors;
mod sample;
mod stipple;
mod tiles;

use pyo3::prelude::*;

/// `rwt._rwt`: the functions `rwt`'s Python modules call.
#[pymodule]
fn _rwt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("BudgetError", m.py().get_type::<errors::BudgetError>())?;
    m.add("DEFAULT_BUDGET", rwt_core::query::DEFAULT_BUDGET)?;
    m.add_function(wrap_pyfunction!(sample::query, m)?)?;
    m.add_function(wrap_pyfunction!(stipple::stipple, m)?)?;
    m.add_function(wrap_pyfunction!(analyse::analyse, m)?)?;
    Ok(())
}
