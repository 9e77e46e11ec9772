//! The native half of the Python package `rwt_noise`: rwt_core's queries, stippling and analysis
//! over numpy arrays. The Python half (`python/rwt_noise`) checks arguments, turns callables into
//! densities and shapes the results; everything here runs with the GIL released.

mod analyse;
mod bench;
mod columns;
mod errors;
mod huge_pages;
mod interrupt;
mod sample;
mod stipple;
mod tiles;
mod zoneplate;

use pyo3::prelude::*;

/// `rwt_noise._rwt`: the functions `rwt_noise`'s Python modules call.
#[pymodule]
fn _rwt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // numpy's C API is imported here, with the module, not by the first call that needs it:
    // a Ctrl-C during that import made the call panic ("Failed to access NumPy array API
    // capsule") instead of raising KeyboardInterrupt.
    numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add("BudgetError", m.py().get_type::<errors::BudgetError>())?;
    m.add("DEFAULT_BUDGET", rwt_core::query::DEFAULT_BUDGET)?;
    m.add("MAX_MAP_PIXELS", sample::MAX_MAP_PIXELS)?;
    m.add(
        "DEFAULT_MAX_IMAGE_PIXELS",
        rwt_core::stipple::DEFAULT_MAX_IMAGE_PIXELS,
    )?;
    m.add_function(wrap_pyfunction!(sample::query, m)?)?;
    m.add_function(wrap_pyfunction!(stipple::stipple, m)?)?;
    m.add_function(wrap_pyfunction!(analyse::analyse, m)?)?;
    m.add_function(wrap_pyfunction!(zoneplate::zoneplate, m)?)?;
    m.add_function(wrap_pyfunction!(bench::time_query, m)?)?;
    Ok(())
}
