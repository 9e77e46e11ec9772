//! `rwt.stipple`: tone-true blue-noise stippling of a grey image, with `rwt stipple`'s
//! defaults (every setting left as `None` is `StippleSettings::default()`'s).

use crate::errors::stipple_error;
use crate::interrupt::interruptible;
use crate::tiles;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rwt_core::stipple::{DotCount, Grey, StippleLimits, StippleSettings, Stippler, ToneMap};
use std::path::PathBuf;

/// Dots, radius, and when rendered the ink raster and the tone errors (blue noise, then a
/// white-noise stipple of the same dots).
type Stippled<'py> = (
    Bound<'py, PyArray2<f64>>,
    f64,
    Option<Bound<'py, PyArray2<f32>>>,
    Option<(f64, f64)>,
);

/// Stipples `image` (grey levels 0 black .. 1 white, row 0 at the top); dot centres are in
/// image pixels, x right and y down.
#[pyfunction]
#[pyo3(signature = (image, *, dots = None, radius = None, gamma = None, contrast = None,
    seed = None, scale = None, render = false, max_dots = None, max_raster_pixels = None,
    max_image_pixels = None, tileset = None))]
#[allow(clippy::too_many_arguments)]
pub fn stipple<'py>(
    py: Python<'py>,
    image: PyReadonlyArray2<'py, f32>,
    dots: Option<usize>,
    radius: Option<f64>,
    gamma: Option<f64>,
    contrast: Option<f64>,
    seed: Option<u64>,
    scale: Option<f64>,
    render: bool,
    max_dots: Option<usize>,
    max_raster_pixels: Option<u64>,
    max_image_pixels: Option<u64>,
    tileset: Option<PathBuf>,
) -> PyResult<Stippled<'py>> {
    let dots = match (dots, radius) {
        (Some(_), Some(_)) => {
            return Err(PyValueError::new_err("give dots or radius, not both"));
        }
        (Some(n), None) => DotCount::Points(n),
        (None, Some(r)) => DotCount::Radius(r),
        (None, None) => DotCount::Auto,
    };
    let d = StippleSettings::default();
    let settings = StippleSettings {
        dots,
        tone: ToneMap {
            gamma: gamma.unwrap_or(d.tone.gamma),
            contrast: contrast.unwrap_or(d.tone.contrast),
        },
        seed: seed.unwrap_or(d.seed),
        scale: scale.unwrap_or(d.scale),
        limits: StippleLimits {
            max_dots: max_dots.unwrap_or(d.limits.max_dots),
            max_raster_pixels: max_raster_pixels.unwrap_or(d.limits.max_raster_pixels),
            max_image_pixels: max_image_pixels.unwrap_or(d.limits.max_image_pixels),
        },
    };
    let view = image.as_array();
    let (height, width) = view.dim();
    // Refused on the size alone, before the image is copied.
    settings.admit(width, height).map_err(stipple_error)?;
    let grey = Grey {
        width,
        height,
        values: view.iter().copied().collect(),
    };
    let stippler = match &tileset {
        Some(path) => Stippler::new(&tiles::load(path)?),
        None => Stippler::new(tiles::embedded()),
    };
    let (s, ink, tone) = interruptible(py, move |_| {
        let s = stippler.stipple(&grey, &settings)?;
        if !render {
            return Ok((s, None, None));
        }
        let ink = s.render(&s.dots, settings.scale)?;
        // The white-noise stipple is seeded as `rwt stipple` seeds it.
        let report = s.tone_report(&ink, settings.seed)?;
        let tone = (report.blue.mean_abs, report.white.mean_abs);
        Ok((s, Some(ink), Some(tone)))
    })?
    .map_err(stipple_error)?;
    let xy: Vec<f64> = s.dots.iter().flat_map(|d| [d.x, d.y]).collect();
    let xy = Array2::from_shape_vec((s.dots.len(), 2), xy).expect("two coordinates per dot");
    let raster = ink.map(|g| {
        Array2::from_shape_vec((g.height, g.width), g.values)
            .expect("a raster of its own size")
            .into_pyarray(py)
    });
    Ok((xy.into_pyarray(py), s.radius, raster, tone))
}
