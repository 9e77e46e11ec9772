//! Random-access blue-noise queries (paper sections 3 and 5.2).
//!
//! For a rectangle and a density, every base tile over the rectangle contributes its points
//! whose rank plus the tile's offset is below `density x tile area`; where the density's maximum over a tile asks
//! for more than the tile holds, the tile's subdivision ranking continues the sequence
//! (ranks `N..n^2 N`), and where it asks for more than that, the children are visited in
//! turn. Work and output are proportional to the integral of the density; nothing is
//! allocated per tile (the recursion lives on the stack, results go to a callback).
//!
//! The offset is a number in `[0, 1)` hashed from the base tile's lattice position. Without
//! it a tile's first point would appear at any positive density, so a density of 0.1
//! points per tile would still put one point in every tile; with it, a tile's `k`-th point
//! appears at `(k + offset) / area`, and the expected count is the integral at every
//! density, however sparse.
//!
//! Every point is produced exactly once, at the coarsest level where it exists, with a
//! stable [`PointId`]. A point is included exactly when the density at its position exceeds
//! its [`Point::threshold`], so raising the density anywhere only adds points, and splitting
//! a rectangle into pieces (half-open: `[min, max)`) yields exactly the union of the pieces.

mod lattice;
mod locate;
#[cfg(feature = "parallel")]
mod parallel;
mod point;
mod prepared;
mod rect;
mod traversal;
mod work_bound;

pub use lattice::Lattice;
#[cfg(feature = "parallel")]
pub use parallel::Buffer;
pub use point::{Point, PointId};
pub use rect::Rect;

use crate::density::{Density, SumOf, sanitize};
use crate::tileset::TileSet;
use lattice::Placement;
use prepared::PreparedTile;
use std::sync::Arc;
use traversal::Visit;

/// Deepest subdivision level visited: `n^(2 * 24)` times the base density, far beyond any
/// budget. Deeper requests are served at this level's density.
pub const MAX_LEVEL: u32 = 24;

/// Largest coordinate magnitude, in base tiles, a query may touch (keeps lattice indices of
/// every level inside `i64`).
pub const MAX_TILE_COORDINATE: f64 = 1.0e12;

/// Fewest steps between adjacent `f64` values a point spacing must span where a query's
/// points lie: rounding then moves a point by at most 1/512 of the spacing, which leaves
/// every spacing statistic as it is. Denser points far from the origin are
/// [`QueryError::Precision`].
pub const MIN_SPACING_ULPS: f64 = 256.0;

/// Most points (or base tiles visited) one query may produce unless
/// [`Sampler::with_budget`] says otherwise: 50 million, about 2 GB of points.
pub const DEFAULT_BUDGET: usize = 50_000_000;

/// Hash stream of the per-base-tile rank offsets.
const OFFSET_STREAM: u64 = 0x0ff5_e7a1_u64;

/// Why a query was refused. Nothing is generated when a query is refused up front.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum QueryError {
    /// A corner is NaN or infinite.
    #[error("query rectangle is not finite")]
    NonFiniteRect,
    /// `max < min` on some axis.
    #[error("query rectangle is inverted (max < min)")]
    InvertedRect,
    /// A tile size whose area is not a normal `f64` at some level (from the base tile
    /// to [`MAX_LEVEL`]): above about 1e154 or below about 1e-139 world units.
    #[error("tile size {size:e} is out of range: tile areas must be normal numbers at every level")]
    TileSize {
        /// The sampler's tile size.
        size: f64,
    },
    /// Coordinates beyond [`MAX_TILE_COORDINATE`] base tiles.
    #[error(
        "query rectangle reaches {tiles:e} tiles from the origin (limit {MAX_TILE_COORDINATE:e})"
    )]
    TooFar {
        /// Distance in base tiles.
        tiles: f64,
    },
    /// The density asks for points closer together than `f64` positions resolve at the
    /// rectangle's coordinates (see [`MIN_SPACING_ULPS`]): they would collapse onto a few
    /// distinct positions. Query nearer the origin, or at a lower density.
    #[error(
        "points would be {spacing:.3e} apart near coordinate {coordinate:.3e}, where positions \
         resolve only {resolution:.3e} ({MIN_SPACING_ULPS} steps per spacing are needed): \
         query nearer the origin or lower the density"
    )]
    Precision {
        /// The spacing of the densest points, in world units.
        spacing: f64,
        /// The largest coordinate magnitude where they would be.
        coordinate: f64,
        /// The step between adjacent `f64` values there.
        resolution: f64,
    },
    /// The query asks for more points, or spans more base tiles of positive density, than
    /// the budget allows (see [`Sampler::work_bound`]).
    #[error(
        "query may produce up to {estimate:.0} points or tile visits, over the budget of {budget} \
         (ask for a smaller rectangle, a lower density or larger tiles)"
    )]
    BudgetExceeded {
        /// Bound of the points plus base tiles visited.
        estimate: f64,
        /// The budget.
        budget: usize,
    },
}

/// Base tiles `[i0, i1) x [j0, j1)` of a query.
#[derive(Clone, Copy)]
struct TileRange {
    i0: i64,
    i1: i64,
    j0: i64,
    j1: i64,
}

/// Generates points of a tile set's infinite point set: the run-time side of rwt.
#[derive(Clone, Debug)]
pub struct Sampler {
    /// Shared: cloning a sampler (to reseed it, or to hand it to another thread) is cheap.
    tiles: Arc<Vec<PreparedTile>>,
    n: i64,
    points_per_tile: usize,
    sub_len: usize,
    colors: u8,
    seed: u64,
    tile_size: f64,
    lattice: Lattice,
    /// Where the seed's lattice lies in the world (from the seed, lattice and tile size).
    placement: Placement,
    budget: usize,
    /// [`TileSet::fingerprint`] of the set.
    fingerprint: u64,
}

impl Sampler {
    /// A sampler over `set`'s tiling for `seed`, with base tiles 1 world unit wide on the
    /// seed's own lattice ([`Lattice::Seeded`]) and a budget of [`DEFAULT_BUDGET`] points
    /// per query.
    pub fn new(set: &TileSet, seed: u64) -> Self {
        let tiles = set
            .tiles
            .iter()
            .map(|t| PreparedTile::new(set, t))
            .collect();
        Self {
            tiles: Arc::new(tiles),
            n: set.subdivision as i64,
            points_per_tile: set.points_per_tile as usize,
            sub_len: set.subdivision_len(),
            colors: set.colors,
            seed,
            tile_size: 1.0,
            lattice: Lattice::Seeded,
            placement: Placement::new(Lattice::Seeded, seed, 1.0),
            budget: DEFAULT_BUDGET,
            fingerprint: set.fingerprint(),
        }
    }

    /// The same tiles with another tiling seed: another, independent point set. Cheap (the
    /// prepared tiles are shared), unlike [`Sampler::new`].
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self.place()
    }

    /// Base tiles `size` world units wide (finite, positive).
    pub fn with_tile_size(mut self, size: f64) -> Self {
        if size.is_finite() && size > 0.0 {
            self.tile_size = size;
        }
        self.place()
    }

    /// How the seed places the tiling: [`Lattice::Aligned`] keeps the places of point sets
    /// of format 1 (edits and layer files written before the seeded lattice).
    pub fn with_lattice(mut self, lattice: Lattice) -> Self {
        self.lattice = lattice;
        self.place()
    }

    /// The placement of the seed, lattice and tile size.
    fn place(mut self) -> Self {
        self.placement = Placement::new(self.lattice, self.seed, self.tile_size);
        self
    }

    /// Largest number of points one query may produce.
    pub fn with_budget(mut self, budget: usize) -> Self {
        self.budget = budget;
        self
    }

    /// Base tile size in world units.
    pub fn tile_size(&self) -> f64 {
        self.tile_size
    }

    /// The tiling seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// How the seed places the tiling.
    pub fn lattice(&self) -> Lattice {
        self.lattice
    }

    /// [`TileSet::fingerprint`] of the set the sampler was made from.
    pub fn tile_set_fingerprint(&self) -> u64 {
        self.fingerprint
    }

    /// Points per tile of the underlying set.
    pub fn points_per_tile(&self) -> usize {
        self.points_per_tile
    }

    /// The world rectangle of base tiles `range`.
    fn block_rect(&self, range: TileRange) -> Rect {
        let s = self.tile_size;
        let TileRange { i0, i1, j0, j1 } = range;
        self.placement.world_rect(
            glam::DVec2::new(i0 as f64 * s, j0 as f64 * s),
            glam::DVec2::new(i1 as f64 * s, j1 as f64 * s),
        )
    }

    fn check(&self, rect: &Rect) -> Result<(), QueryError> {
        let s = self.tile_size;
        let finest = s / (self.n as f64).powi(MAX_LEVEL as i32);
        if !((s * s).is_finite() && (finest * finest).is_normal()) {
            return Err(QueryError::TileSize { size: s });
        }
        let far = rect.min().abs().max(rect.max().abs()).max_element() / self.tile_size;
        if far > MAX_TILE_COORDINATE {
            return Err(QueryError::TooFar { tiles: far });
        }
        Ok(())
    }

    /// Calls `emit` with every point of `rect` for `density`; returns how many.
    pub fn query_with<D: Density + ?Sized>(
        &self,
        rect: Rect,
        density: &D,
        mut emit: impl FnMut(Point),
    ) -> Result<usize, QueryError> {
        let Some(TileRange { i0, i1, j0, j1 }) = self.admit(&rect, density)? else {
            return Ok(0);
        };
        let s = self.tile_size;
        let mut count = 0usize;
        let mut visit = Visit {
            sampler: self,
            rect,
            density,
            emit: &mut |p: Point| {
                count += 1;
                emit(p)
            },
        };
        visit.blocks(i0, i1, j0, j1, s);
        Ok(count)
    }

    /// The checks every query of `rect` for `density` makes before producing a point
    /// (coordinates, budget, precision), alone: a tool calls it before it opens an output,
    /// so that a refused query leaves existing files as they were.
    pub fn admits<D: Density + ?Sized>(&self, rect: &Rect, density: &D) -> Result<(), QueryError> {
        self.admit(rect, density).map(|_| ())
    }

    /// Checks a query against the coordinate limit and the budget; returns the base tiles
    /// it spans (`None` for an empty rectangle).
    fn admit<D: Density + ?Sized>(
        &self,
        rect: &Rect,
        density: &D,
    ) -> Result<Option<TileRange>, QueryError> {
        self.check(rect)?;
        let estimate = self.work_bound(rect, density);
        if estimate.is_nan() || estimate > self.budget as f64 {
            return Err(QueryError::BudgetExceeded {
                estimate,
                budget: self.budget,
            });
        }
        self.check_precision(rect, density)?;
        if rect.is_empty() {
            return Ok(None);
        }
        let [i0, i1, j0, j1] = self.placement.tile_range(rect, self.tile_size);
        Ok(Some(TileRange { i0, i1, j0, j1 }))
    }

    /// All points of `rect` for `density`, appended to `out`; returns how many.
    pub fn query<D: Density + ?Sized>(
        &self,
        rect: Rect,
        density: &D,
        out: &mut Vec<Point>,
    ) -> Result<usize, QueryError> {
        self.query_with(rect, density, |p| out.push(p))
    }

    /// Several classes sharing one point set (paper section 6.3): points follow the sum of
    /// the class densities, and a point of threshold `tau` at `p` belongs to the first class
    /// `i` with `tau < d_0(p) + ... + d_i(p)`. So class 0 alone is exactly the point set of
    /// `d_0` (blue noise by itself), classes `0..=i` together that of `d_0 + ... + d_i`, and
    /// every class appears in proportion to its density.
    pub fn query_classes<D: Density>(
        &self,
        rect: Rect,
        classes: &[D],
        mut emit: impl FnMut(Point),
    ) -> Result<usize, QueryError> {
        let total = SumOf(classes);
        self.query_with(rect, &total, |mut p| {
            let mut cumulative = 0.0;
            p.class = (classes.len().saturating_sub(1)) as u16;
            for (i, c) in classes.iter().enumerate() {
                cumulative += sanitize(c.density(p.position));
                if p.threshold < cumulative {
                    p.class = i as u16;
                    break;
                }
            }
            emit(p)
        })
    }
}
