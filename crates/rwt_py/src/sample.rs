//! `rwt.sample`'s query: the points of a rectangle for a constant or a density map.

use crate::columns::{Arrays, Columns};
use crate::errors::{image_error, query_error};
use crate::interrupt::{Cancellable, interruptible};
use crate::tiles;
use glam::DVec2;
use numpy::PyReadonlyArray2;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;
use rwt_core::clumps::{ClumpKernel, ClumpParams, Clumps};
use rwt_core::density::{Constant, Density, ImageDensity, Placement};
use rwt_core::query::{DEFAULT_BUDGET, Point, QueryError, Rect, Sampler};
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::Arc;

/// Rectangles of at least this many base tiles are queried on all cores by
/// `Sampler::query_par`, as `rwt points` does: the same points in the same order.
const PARALLEL_TILES: f64 = 256.0;

/// Queries over fewer base tiles that may produce at least this many points are split into
/// a grid of chunks queried on all cores (the points of the chunks are exactly the
/// rectangle's; they come chunk by chunk).
const PARALLEL_POINTS: f64 = 100_000.0;

/// Chunks per axis of such a query.
const CHUNKS_PER_AXIS: usize = 8;

/// Longest side of a density map (as of an image density).
const MAX_MAP_SIDE: usize = 32_768;

/// Most values of a density map: 2^24 (4096 x 4096). A map takes about 20 bytes a value
/// while its density is made (the float64 array `rwt.sample` passes, its unit values and
/// the density): 340 MB at the limit. Checked on the array's shape, before it is converted.
pub const MAX_MAP_PIXELS: usize = 1 << 24;

/// A density as Python passes it: points per unit area, or a map of them (row 0 at the
/// rectangle's top edge, largest y).
#[derive(FromPyObject)]
pub enum DensityArg<'py> {
    /// The same density everywhere.
    Constant(f64),
    /// A map, bilinearly interpolated between texel centres.
    Map(PyReadonlyArray2<'py, f64>),
    /// Clumps: `(seed, clumps per unit area, points per clump, radius, kernel)`, the kernel
    /// `"thomas"` or `"matern"` (see `rwt_core::clumps`).
    Clumps((u64, f64, f64, f64, String)),
}

/// `(x0, y0, x1, y1)`.
type Corners = (f64, f64, f64, f64);

/// The points of `rect` for `density` times `scale`: positions, ids, thresholds and the
/// density at each point, in the query's order.
#[pyfunction]
#[pyo3(signature = (rect, density, *, scale = 1.0, extent = None, seed = 0, tile_size = 1.0,
    budget = DEFAULT_BUDGET, tileset = None))]
#[allow(clippy::too_many_arguments)]
pub fn query<'py>(
    py: Python<'py>,
    rect: Corners,
    density: DensityArg<'py>,
    scale: f64,
    extent: Option<Corners>,
    seed: u64,
    tile_size: f64,
    budget: usize,
    tileset: Option<PathBuf>,
) -> PyResult<Arrays<'py>> {
    let rect = rect_of(rect, "rect")?;
    if !(tile_size.is_finite() && tile_size > 0.0) {
        return Err(PyValueError::new_err(format!(
            "tile_size must be positive and finite, got {tile_size}"
        )));
    }
    if !(scale.is_finite() && scale >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "the density scale must be non-negative and finite, got {scale}"
        )));
    }
    let density: Arc<dyn Density + Send + Sync> = match density {
        DensityArg::Constant(c) if c.is_finite() && c >= 0.0 => Arc::new(Constant(c * scale)),
        DensityArg::Constant(c) => {
            return Err(PyValueError::new_err(format!(
                "density must be a non-negative finite number, got {c}"
            )));
        }
        DensityArg::Map(values) => {
            let over = rect_of(extent.unwrap_or(corners(&rect)), "extent")?;
            Arc::new(map_density(&values, over, scale)?)
        }
        DensityArg::Clumps(params) => Arc::new(clumps(params, scale)?),
    };
    let sampler = tiles::sampler(tileset.as_deref(), seed)?
        .with_tile_size(tile_size)
        .with_budget(budget);
    let columns = interruptible(py, move |cancel| {
        collect(
            &sampler,
            rect,
            &Cancellable {
                cancel,
                inner: density,
            },
            seed,
        )
    })?
    .map_err(query_error)?;
    Ok(columns.into_arrays(py))
}

/// The clumps density of Python's parameters, its points per clump times `scale`.
fn clumps(
    (seed, clumps, per_clump, radius, kernel): (u64, f64, f64, f64, String),
    scale: f64,
) -> PyResult<Clumps> {
    let kernel = match kernel.as_str() {
        "thomas" => ClumpKernel::Thomas,
        "matern" => ClumpKernel::Matern,
        other => {
            return Err(PyValueError::new_err(format!(
                "clump kernel must be \"thomas\" or \"matern\", got {other:?}"
            )));
        }
    };
    let params = ClumpParams {
        seed,
        clumps,
        per_clump: per_clump * scale,
        radius,
        kernel,
    };
    Clumps::new(params).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The points of `rect` as columns: serially, on all cores by base tiles (the serial
/// order), or on all cores by chunks (chunk by chunk) for many points over few base tiles.
fn collect<D: Density + Sync + ?Sized>(
    sampler: &Sampler,
    rect: Rect,
    density: &D,
    seed: u64,
) -> Result<Columns, QueryError> {
    let tile = sampler.tile_size();
    // Refused queries are refused whole, before any point or chunk.
    sampler.admits(&rect, density)?;
    let bound = sampler.work_bound(&rect, density);
    let mut out = Columns::with_room(bound);
    if rect.area() / (tile * tile) >= PARALLEL_TILES {
        let add = |c: &mut Columns, p: Point| c.push(&p, density, seed);
        let append = |c: &Columns| {
            out.append(c);
            ControlFlow::Continue(())
        };
        sampler.query_par_fold(rect, density, add, append, &|_| {})?;
        return Ok(out);
    }
    if bound < PARALLEL_POINTS || rayon::current_num_threads() < 2 {
        sampler.query_with(rect, density, |p| out.push(&p, density, seed))?;
        return Ok(out);
    }
    let parts: Vec<Result<Columns, QueryError>> = chunks(&rect, CHUNKS_PER_AXIS)
        .into_par_iter()
        .map(|chunk| {
            let mut part = Columns::default();
            sampler.query_with(chunk, density, |p| part.push(&p, density, seed))?;
            Ok(part)
        })
        .collect();
    for part in parts {
        out.append(&part?);
    }
    Ok(out)
}

/// A `k x k` grid of half-open chunks whose union is exactly `rect` (row by row from the
/// lowest y): neighbours share their edge coordinate, and the outer edges are `rect`'s.
fn chunks(rect: &Rect, k: usize) -> Vec<Rect> {
    let (lo, hi) = (rect.min(), rect.max());
    let edge = |a: f64, b: f64, i: usize| {
        if i == k {
            b
        } else {
            a + (b - a) * (i as f64 / k as f64)
        }
    };
    (0..k * k)
        .filter_map(|c| {
            let (i, j) = (c % k, c / k);
            let min = DVec2::new(edge(lo.x, hi.x, i), edge(lo.y, hi.y, j));
            let max = DVec2::new(edge(lo.x, hi.x, i + 1), edge(lo.y, hi.y, j + 1));
            Rect::new(min, max).ok()
        })
        .collect()
}

/// A rectangle from Python's corners (finite, not inverted).
fn rect_of((x0, y0, x1, y1): Corners, what: &str) -> PyResult<Rect> {
    Rect::new(DVec2::new(x0, y0), DVec2::new(x1, y1))
        .map_err(|e| PyValueError::new_err(format!("{what} ({x0}, {y0}, {x1}, {y1}): {e}")))
}

fn corners(r: &Rect) -> Corners {
    (r.min().x, r.min().y, r.max().x, r.max().y)
}

/// A density map over `over`: values are points per unit area (finite, non-negative).
fn map_density(
    values: &PyReadonlyArray2<'_, f64>,
    over: Rect,
    scale: f64,
) -> PyResult<ImageDensity> {
    let values = values.as_array();
    let (h, w) = values.dim();
    if h == 0 || w == 0 || h > MAX_MAP_SIDE || w > MAX_MAP_SIDE {
        return Err(PyValueError::new_err(format!(
            "density array: shape ({h}, {w}) must be between 1 and {MAX_MAP_SIDE} on each side"
        )));
    }
    if h * w > MAX_MAP_PIXELS {
        return Err(PyValueError::new_err(format!(
            "density array: shape ({h}, {w}) has more than {MAX_MAP_PIXELS} values"
        )));
    }
    if let Some(((row, col), v)) = values
        .indexed_iter()
        .find(|(_, v)| !(v.is_finite() && **v >= 0.0))
    {
        return Err(PyValueError::new_err(format!(
            "density array: value {v} at [{row}, {col}] is not a non-negative finite number"
        )));
    }
    let top = values.iter().copied().fold(0.0f64, f64::max);
    let unit: Vec<f32> = if top > 0.0 {
        values.iter().map(|v| (v / top) as f32).collect()
    } else {
        vec![0.0; values.len()]
    };
    if over.is_empty() {
        return Err(PyValueError::new_err(
            "extent: the density map's rectangle is empty",
        ));
    }
    let at = Placement {
        min: over.min(),
        size: over.size(),
        scale: top * scale,
    };
    ImageDensity::from_values(w as u32, h as u32, &unit, at).map_err(image_error)
}
