//! What `python -m rwt_noise.bench` measures the Python calls against: the Rust query alone,
//! as `rwt bench` times it.

use crate::tiles;
use glam::DVec2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rwt_core::density::Constant;
use rwt_core::query::Rect;
use std::time::Instant;

/// The points of a constant `density` over `rect` with base tiles `tile_size` wide, queried
/// on one thread into a vector reused between runs (`rwt bench`'s uniform query): how many,
/// and the best of `repeat` runs in seconds.
#[pyfunction]
#[pyo3(signature = (rect, density, *, tile_size, seed = 0, repeat = 3))]
pub fn time_query(
    py: Python<'_>,
    rect: (f64, f64, f64, f64),
    density: f64,
    tile_size: f64,
    seed: u64,
    repeat: usize,
) -> PyResult<(usize, f64)> {
    let (x0, y0, x1, y1) = rect;
    let rect = Rect::new(DVec2::new(x0, y0), DVec2::new(x1, y1))
        .map_err(|e| PyValueError::new_err(format!("rect: {e}")))?;
    let sampler = tiles::sampler(None, seed)?
        .with_tile_size(tile_size)
        .with_budget(usize::MAX);
    let density = Constant(density);
    sampler
        .admits(&rect, &density)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(py.detach(move || {
        let mut out = Vec::new();
        let mut best = f64::INFINITY;
        for _ in 0..repeat.max(1) {
            out.clear();
            let started = Instant::now();
            // Admitted above: the query cannot be refused.
            let _ = sampler.query(rect, &density, &mut out);
            best = best.min(started.elapsed().as_secs_f64());
        }
        (out.len(), best)
    }))
}
