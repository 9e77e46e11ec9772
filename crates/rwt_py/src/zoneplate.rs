//! `rwt_noise.zoneplate`: the paper's anti-aliasing test, as `rwt zoneplate` runs it.

use crate::interrupt::interruptible;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rwt_core::analysis::zoneplate::ZonePlate;

/// Most pixels on a side (the reference takes 16 samples a pixel).
const MAX_SIZE: usize = 2048;

/// Pattern names, their errors `(patterns, 3)`: PSNR, low band, high band (dB), the
/// images `(1 + patterns, size, size)`, the reference first, and the paper's claim checked
/// (aliasing removed, less noise).
type Plates<'py> = (
    Vec<&'static str>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    (bool, bool),
);

/// Renders the zone plate with every pattern at `size x size` pixels.
#[pyfunction]
#[pyo3(signature = (*, size = 512, seed = 0))]
pub fn zoneplate(py: Python<'_>, size: usize, seed: u64) -> PyResult<Plates<'_>> {
    if !(16..=MAX_SIZE).contains(&size) {
        return Err(PyValueError::new_err(format!(
            "size must be between 16 and {MAX_SIZE}, got {size}"
        )));
    }
    let plate = ZonePlate {
        size,
        ..ZonePlate::default()
    };
    let sampler = crate::tiles::sampler(None, seed)?;
    let rendered = interruptible(py, move |cancel| {
        plate.compare(&sampler, seed, || !cancel.is_set())
    })?;
    let comparison = rendered.map_err(|e| PyValueError::new_err(e.to_string()))?;
    let claim = comparison
        .claim()
        .map(|c| (c.aliasing_removed, c.less_noise))
        .ok_or_else(|| PyValueError::new_err("the zone plate was interrupted"))?;
    let k = comparison.renderings.len();
    let names = comparison
        .renderings
        .iter()
        .map(|r| r.pattern.name())
        .collect();
    let errors = comparison
        .renderings
        .iter()
        .flat_map(|r| [r.error.psnr, r.error.low, r.error.high]);
    let errors = Array2::from_shape_vec((k, 3), errors.collect()).expect("three figures a pattern");
    let mut images = comparison.reference;
    images.extend(comparison.renderings.into_iter().flat_map(|r| r.image));
    let images = Array3::from_shape_vec((k + 1, size, size), images).expect("an image each");
    Ok((
        names,
        errors.into_pyarray(py),
        images.into_pyarray(py),
        claim,
    ))
}
