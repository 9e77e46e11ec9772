//! `rwt.analyse`: the normalized minimum distance and the averaged power spectrum of a point
//! set, over the square windows `rwt analyse` uses.

use crate::interrupt::interruptible;
use glam::DVec2;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rwt_core::analysis::{Spectrum, WindowGrid, rho};

/// Largest periodogram side: a window's cost is its points times this squared.
const MAX_SPECTRUM_SIZE: usize = 512;

/// rho, density, windows, window side, power `(size, size)`, radial mean power and
/// anisotropy (dB) per annulus.
type Analysed<'py> = (
    f64,
    f64,
    usize,
    f64,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// Analyses the points (`(N, 2)`) inside `window` (`x0, y0, x1, y1`, half-open).
#[pyfunction]
#[pyo3(signature = (points, window, *, size = 128))]
pub fn analyse<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    window: (f64, f64, f64, f64),
    size: usize,
) -> PyResult<Analysed<'py>> {
    let view = points.as_array();
    if view.ncols() != 2 {
        return Err(PyValueError::new_err(format!(
            "points must have shape (N, 2), got (N, {})",
            view.ncols()
        )));
    }
    if !(4..=MAX_SPECTRUM_SIZE).contains(&size) {
        return Err(PyValueError::new_err(format!(
            "size must be between 4 and {MAX_SPECTRUM_SIZE}, got {size}"
        )));
    }
    let (x0, y0, x1, y1) = window;
    let (min, max) = (DVec2::new(x0, y0), DVec2::new(x1, y1));
    if !(min.is_finite() && max.is_finite() && max.x > min.x && max.y > min.y) {
        return Err(PyValueError::new_err(format!(
            "window ({x0}, {y0}, {x1}, {y1}) must be finite with x1 > x0 and y1 > y0"
        )));
    }
    let inside: Vec<DVec2> = view
        .rows()
        .into_iter()
        .map(|r| DVec2::new(r[0], r[1]))
        .filter(|p| p.x >= min.x && p.y >= min.y && p.x < max.x && p.y < max.y)
        .collect();
    if inside.len() < 2 {
        return Err(PyValueError::new_err(format!(
            "{} points inside the window: at least 2 are needed",
            inside.len()
        )));
    }
    let grid = WindowGrid::new(min, max, inside.len())
        .map_err(|e| PyValueError::new_err(format!("window: {e}")))?;
    // The spectrum's windows are sized to its frequencies: smaller ones for many points.
    let spectral = WindowGrid::for_spectrum(min, max, inside.len(), size)
        .map_err(|e| PyValueError::new_err(format!("window: {e}")))?;
    let (rho, s) = interruptible(py, move |_| {
        let area = grid.side * grid.side;
        let rho = grid
            .split(inside.iter().copied())
            .iter()
            .filter_map(|(_, p)| rho(p, p.len() as f64 / area))
            .reduce(f64::min)
            .unwrap_or(f64::NAN);
        let windows = spectral.split(inside);
        (rho, Spectrum::averaged(&windows, spectral.side, size))
    })?;
    let power = Array2::from_shape_vec((s.size, s.size), s.power).expect("size x size");
    Ok((
        rho,
        grid.density,
        s.windows,
        spectral.side,
        power.into_pyarray(py),
        s.radial_mean.into_pyarray(py),
        s.anisotropy_db.into_pyarray(py),
    ))
}
