//! rwt_core's errors as Python exceptions: `BudgetError` for a runaway point budget (raised
//! before anything is allocated), `ValueError` for bad arguments, `OSError` for files.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::{PyErr, create_exception};
use rwt_core::density::ImageDensityError;
use rwt_core::query::QueryError;
use rwt_core::stipple::StippleError;
use rwt_core::tileset::TileSetError;

create_exception!(
    rwt,
    BudgetError,
    PyValueError,
    "The request would produce more points (or dots, or raster pixels) than its budget \
     allows; it was refused before anything was allocated. Ask for a smaller rectangle, a \
     lower density or fewer points, or raise the budget."
);

/// A refused query.
pub fn query_error(e: QueryError) -> PyErr {
    match e {
        QueryError::BudgetExceeded { .. } => BudgetError::new_err(e.to_string()),
        e => PyValueError::new_err(e.to_string()),
    }
}

/// A refused stipple.
pub fn stipple_error(e: StippleError) -> PyErr {
    match e {
        StippleError::TooManyDots { .. }
        | StippleError::RasterTooLarge { .. }
        | StippleError::ImageTooLarge { .. }
        | StippleError::OutOfMemory { .. } => BudgetError::new_err(e.to_string()),
        StippleError::Query(q) => query_error(q),
        e => PyValueError::new_err(e.to_string()),
    }
}

/// A density map that could not be made.
pub fn image_error(e: ImageDensityError) -> PyErr {
    PyValueError::new_err(format!("density array: {e}"))
}

/// A tile set file that could not be read.
pub fn tileset_error(path: &std::path::Path, e: TileSetError) -> PyErr {
    match e {
        TileSetError::File(e) => PyOSError::new_err(e.to_string()),
        e => PyValueError::new_err(format!("{}: {e}", path.display())),
    }
}
