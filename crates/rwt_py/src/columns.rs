//! A query's points as the columns numpy receives, written as the query produces them: no
//! vector of `Point`s in between (56 bytes a point, written and read once more), and each
//! point's id and density computed on the thread that found it.

use crate::huge_pages;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use rwt_core::density::Density;
use rwt_core::query::{Buffer, Point};

/// Hash salt of the 64-bit point ids (`PointId::hash`).
const ID_SALT: u64 = 0x1d5;

/// Most points reserved up front (640 MB of columns); larger queries grow from there.
const MAX_RESERVED: usize = 16 << 20;

/// Positions `(N, 2)`, 64-bit ids, thresholds and the density at each point.
pub type Arrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// Points as four columns.
#[derive(Default)]
pub struct Columns {
    xy: Vec<f64>,
    ids: Vec<u64>,
    thresholds: Vec<f64>,
    at: Vec<f64>,
}

impl Columns {
    /// Empty columns with room for about `points` points (at most [`MAX_RESERVED`]; none
    /// where the memory is not there: the columns then grow as they fill).
    pub fn with_room(points: f64) -> Self {
        let n = if points.is_finite() && points > 0.0 {
            (points as usize).min(MAX_RESERVED)
        } else {
            0
        };
        let mut c = Self::default();
        let _ = (c.xy.try_reserve_exact(2 * n), c.ids.try_reserve_exact(n));
        let _ = (c.thresholds.try_reserve_exact(n), c.at.try_reserve_exact(n));
        huge_pages::advise(&mut c.xy);
        huge_pages::advise(&mut c.ids);
        huge_pages::advise(&mut c.thresholds);
        huge_pages::advise(&mut c.at);
        c
    }

    /// Appends point `p` of the point set of `seed`, with `density` at its position.
    #[inline]
    pub fn push<D: Density + ?Sized>(&mut self, p: &Point, density: &D, seed: u64) {
        self.xy.extend([p.position.x, p.position.y]);
        self.ids.push(p.id.hash(seed, ID_SALT));
        self.thresholds.push(p.threshold);
        self.at.push(density.density(p.position));
    }

    /// Appends `other`'s points after these.
    pub fn append(&mut self, other: &Columns) {
        self.xy.extend_from_slice(&other.xy);
        self.ids.extend_from_slice(&other.ids);
        self.thresholds.extend_from_slice(&other.thresholds);
        self.at.extend_from_slice(&other.at);
    }

    /// The columns as numpy arrays (moved, not copied).
    pub fn into_arrays(self, py: Python<'_>) -> Arrays<'_> {
        let n = self.ids.len();
        let xy = Array2::from_shape_vec((n, 2), self.xy).expect("two coordinates per point");
        (
            xy.into_pyarray(py),
            self.ids.into_pyarray(py),
            self.thresholds.into_pyarray(py),
            self.at.into_pyarray(py),
        )
    }
}

/// A block's columns, emptied for the next block with their memory kept.
impl Buffer for Columns {
    fn clear(&mut self) {
        self.xy.clear();
        self.ids.clear();
        self.thresholds.clear();
        self.at.clear();
    }
}
