//! `rwt_noise.zoneplate`: the paper's anti-aliasing test, as `rwt zoneplate` runs it.

use crate::interrupt::interruptible;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rwt_core::analysis::zoneplate::{Pattern, ZonePlate};

/// Most pixels on a side (the reference takes 16 samples a pixel).
const MAX_SIZE: usize = 2048;

/// Pattern names, their errors `(patterns, 3)`: PSNR, low band, high band (dB), and the
/// images `(1 + patterns, size, size)`, the reference first.
type Plates<'py> = (
    Vec<&'static str>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
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
        let reference = plate.reference_image();
        let mut errors = Vec::new();
        let mut images = reference.clone();
        for pattern in Pattern::ALL {
            if cancel.is_set() {
                break;
            }
            let samples = plate.samples(pattern, &sampler, seed)?;
            let image = plate.reconstruct(samples);
            let e = plate.error(&image, &reference);
            errors.extend([e.psnr, e.low, e.high]);
            images.extend(image);
        }
        Ok::<_, rwt_core::query::QueryError>((errors, images))
    })?;
    let (errors, images) = rendered.map_err(|e| PyValueError::new_err(e.to_string()))?;
    let k = Pattern::ALL.len();
    let names = Pattern::ALL.iter().map(|p| p.name()).collect();
    let errors = Array2::from_shape_vec((k, 3), errors).expect("three figures a pattern");
    let images = Array3::from_shape_vec((k + 1, size, size), images).expect("an image each");
    Ok((names, errors.into_pyarray(py), images.into_pyarray(py)))
}
