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

use crate::density::{Density, sanitize};
use crate::rng::{hash_words, unit_f64};
use crate::tileset::{TileSet, fixed_to_unit};
use crate::tiling::base_tile;
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Deepest subdivision level visited: `n^(2 * 24)` times the base density, far beyond any
/// budget. Deeper requests are served at this level's density.
pub const MAX_LEVEL: u32 = 24;

/// Largest coordinate magnitude, in base tiles, a query may touch (keeps lattice indices of
/// every level inside `i64`).
pub const MAX_TILE_COORDINATE: f64 = 1.0e12;

/// Hash stream of the per-base-tile rank offsets.
const OFFSET_STREAM: u64 = 0x0ff5_e7a1_u64;

/// A half-open rectangle `[min, max)` in world units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rect {
    /// Inclusive lower corner.
    pub min: DVec2,
    /// Exclusive upper corner.
    pub max: DVec2,
}

impl Rect {
    /// A rectangle; it may be empty, but not inverted or non-finite.
    pub fn new(min: DVec2, max: DVec2) -> Result<Self, QueryError> {
        if !(min.is_finite() && max.is_finite()) {
            return Err(QueryError::NonFiniteRect);
        }
        if max.x < min.x || max.y < min.y {
            return Err(QueryError::InvertedRect);
        }
        Ok(Self { min, max })
    }

    /// Whether `p` is inside (half-open).
    #[inline]
    pub fn contains(&self, p: DVec2) -> bool {
        p.x >= self.min.x && p.y >= self.min.y && p.x < self.max.x && p.y < self.max.y
    }

    /// Area.
    pub fn area(&self) -> f64 {
        (self.max.x - self.min.x) * (self.max.y - self.min.y)
    }

    fn is_empty(&self) -> bool {
        !(self.max.x > self.min.x && self.max.y > self.min.y)
    }

    fn intersect(&self, other: &Rect) -> Rect {
        Rect {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        }
    }
}

/// Why a query was refused. Nothing is generated when a query is refused up front.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum QueryError {
    /// A corner is NaN or infinite.
    #[error("query rectangle is not finite")]
    NonFiniteRect,
    /// `max < min` on some axis.
    #[error("query rectangle is inverted (max < min)")]
    InvertedRect,
    /// Coordinates beyond [`MAX_TILE_COORDINATE`] base tiles.
    #[error(
        "query rectangle reaches {tiles:e} tiles from the origin (limit {MAX_TILE_COORDINATE:e})"
    )]
    TooFar {
        /// Distance in base tiles.
        tiles: f64,
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

/// Stable identity of a point: the tile it first appears in and its index there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct PointId {
    /// Subdivision level (0 = base tiles).
    pub level: u8,
    /// Lattice column of the tile at that level.
    pub x: i64,
    /// Lattice row of the tile at that level.
    pub y: i64,
    /// Index of the point in its tile.
    pub index: u16,
}

impl PointId {
    /// A 64-bit hash of the identity and a salt: the source of every derived attribute.
    #[inline]
    pub fn hash(&self, seed: u64, salt: u64) -> u64 {
        hash_words(
            seed,
            &[
                salt,
                self.level as u64,
                self.x as u64,
                self.y as u64,
                self.index as u64,
            ],
        )
    }

    /// A number in `[0, 1)` hashed from the identity (same on every platform).
    #[inline]
    pub fn unit(&self, seed: u64, salt: u64) -> f64 {
        unit_f64(self.hash(seed, salt))
    }

    /// A rotation angle in `[0, 2 pi)`, hashed from the identity.
    #[inline]
    pub fn rotation(&self, seed: u64) -> f64 {
        self.unit(seed, 0x0107) * std::f64::consts::TAU
    }

    /// A scale factor in `[1 - variation, 1 + variation]`, hashed from the identity.
    #[inline]
    pub fn scale(&self, seed: u64, variation: f64) -> f64 {
        1.0 + variation * (2.0 * self.unit(seed, 0x05ca) - 1.0)
    }
}

/// A point of a query.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// World position.
    pub position: DVec2,
    /// Stable identity.
    pub id: PointId,
    /// The point is present wherever the density at its position exceeds this (points per
    /// unit area): use it to fade points in, or to pick a level of detail. Thresholds of one
    /// base tile's points are `(rank + offset) / area` (see the module docs).
    pub threshold: f64,
    /// Class index (see [`Sampler::query_classes`]); 0 for single-density queries.
    pub class: u16,
}

/// A point of a tile's cell list: its rank in the list it comes from, its index in the tile
/// it belongs to, and its position in that tile.
#[derive(Clone, Copy, Debug)]
struct CellPoint {
    rank: u32,
    index: u16,
    frac: [f64; 2],
}

/// A tile prepared for queries: its points grouped by the `n x n` cells of its subdivision,
/// each group in rank order, so that a query bounds the density per cell and only touches
/// the cells it needs.
#[derive(Clone, Debug)]
struct RuntimeTile {
    /// Base points by the cell they lie in (`rank` = base rank, `frac` in this tile).
    base_cells: Vec<Vec<CellPoint>>,
    /// Subdivision points of rank `N..n^2 N` by child cell (`index` and `frac` in the child).
    sub_cells: Vec<Vec<CellPoint>>,
    children: Vec<u16>,
}

/// Generates points of a tile set's infinite point set: the run-time side of rwt.
#[derive(Clone, Debug)]
pub struct Sampler {
    /// Shared: cloning a sampler (to reseed it, or to hand it to another thread) is cheap.
    tiles: std::sync::Arc<Vec<RuntimeTile>>,
    n: i64,
    points_per_tile: usize,
    sub_len: usize,
    colors: u8,
    seed: u64,
    tile_size: f64,
    budget: usize,
}

impl Sampler {
    /// A sampler over `set`'s tiling for `seed`, with base tiles 1 world unit wide and a
    /// budget of 50 million points per query.
    pub fn new(set: &TileSet, seed: u64) -> Self {
        let n = set.subdivision as usize;
        let big_n = set.points_per_tile as usize;
        let tiles = set
            .tiles
            .iter()
            .map(|t| {
                let mut base_cells = vec![Vec::new(); n * n];
                for (k, p) in t.points.iter().enumerate() {
                    let frac = [fixed_to_unit(p[0]), fixed_to_unit(p[1])];
                    let cell = ((frac[1] * n as f64) as usize).min(n - 1) * n
                        + ((frac[0] * n as f64) as usize).min(n - 1);
                    base_cells[cell].push(CellPoint {
                        rank: k as u32,
                        index: k as u16,
                        frac,
                    });
                }
                let mut sub_cells = vec![Vec::new(); n * n];
                for (r, &e) in t.subdivision.iter().enumerate().skip(big_n) {
                    let (cell, index) = ((e >> 16) as usize, (e & 0xffff) as u16);
                    let q = set.tiles[t.children[cell] as usize].points[index as usize];
                    sub_cells[cell].push(CellPoint {
                        rank: r as u32,
                        index,
                        frac: [fixed_to_unit(q[0]), fixed_to_unit(q[1])],
                    });
                }
                RuntimeTile {
                    base_cells,
                    sub_cells,
                    children: t.children.clone(),
                }
            })
            .collect::<Vec<_>>();
        Self {
            tiles: std::sync::Arc::new(tiles),
            n: n as i64,
            points_per_tile: big_n,
            sub_len: set.subdivision_len(),
            colors: set.colors,
            seed,
            tile_size: 1.0,
            budget: 50_000_000,
        }
    }

    /// The same tiles with another tiling seed: another, independent point set. Cheap (the
    /// prepared tiles are shared), unlike [`Sampler::new`].
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Base tiles `size` world units wide (finite, positive).
    pub fn with_tile_size(mut self, size: f64) -> Self {
        if size.is_finite() && size > 0.0 {
            self.tile_size = size;
        }
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

    /// Points per tile of the underlying set.
    pub fn points_per_tile(&self) -> usize {
        self.points_per_tile
    }

    /// A bound of the work a query of `rect` does: the density's integral (the points it
    /// yields on average) plus the tiles it visits where the density is positive (twice the
    /// tiles of the deepest level it reaches, which covers the coarser levels). The second
    /// term is negligible for wide rectangles but dominates for huge sparse or very thin
    /// ones. Refined best-first (the cell
    /// with the largest bound is split in four) until it fits the budget or 4096 bounds have
    /// been evaluated, so a small dense spot in a huge empty region is bounded tightly in a
    /// few hundred steps, and a huge region of very sparse density is refused instead of
    /// visiting billions of tiles.
    pub fn work_bound<D: Density + ?Sized>(&self, rect: &Rect, density: &D) -> f64 {
        #[derive(PartialEq)]
        struct Cell(f64, Rect);
        impl Eq for Cell {}
        impl PartialOrd for Cell {
            fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
                Some(self.cmp(other))
            }
        }
        impl Ord for Cell {
            fn cmp(&self, other: &Self) -> std::cmp::Ordering {
                self.0.total_cmp(&other.0)
            }
        }
        if rect.is_empty() {
            return 0.0;
        }
        let s = self.tile_size;
        let n = self.n as f64;
        let finest = s / n.powi(MAX_LEVEL as i32);
        let bound = |r: &Rect| {
            let d = sanitize(density.max_over(r.min, r.max));
            if d.is_nan() {
                return f64::INFINITY;
            }
            if d <= 0.0 {
                return 0.0;
            }
            // Tiles are visited down to the first level whose tiles ask for at most the
            // full subdivision sequence: side s_deep with d * s_deep^2 <= n^2 N.
            let s_deep = ((self.sub_len as f64 / d).sqrt() / n).clamp(finest, s);
            let tiles = ((r.max.x - r.min.x) / s_deep + 2.0) * ((r.max.y - r.min.y) / s_deep + 2.0);
            d * r.area() + 2.0 * tiles
        };
        let target = self.budget as f64;
        let first = bound(rect);
        let mut total = first;
        let mut heap = std::collections::BinaryHeap::from([Cell(first, *rect)]);
        let mut evaluations = 1;
        while total > target && evaluations < 4096 && total.is_finite() {
            let Some(Cell(b, r)) = heap.pop() else { break };
            let c = (r.min + r.max) * 0.5;
            total -= b;
            for q in [
                Rect { min: r.min, max: c },
                Rect {
                    min: DVec2::new(c.x, r.min.y),
                    max: DVec2::new(r.max.x, c.y),
                },
                Rect {
                    min: DVec2::new(r.min.x, c.y),
                    max: DVec2::new(c.x, r.max.y),
                },
                Rect { min: c, max: r.max },
            ] {
                let qb = bound(&q);
                total += qb;
                evaluations += 1;
                if qb > 0.0 {
                    heap.push(Cell(qb, q));
                }
            }
        }
        total.max(0.0)
    }

    fn check(&self, rect: &Rect) -> Result<(), QueryError> {
        let far = rect.min.abs().max(rect.max.abs()).max_element() / self.tile_size;
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
        self.check(&rect)?;
        let estimate = self.work_bound(&rect, density);
        if estimate.is_nan() || estimate > self.budget as f64 {
            return Err(QueryError::BudgetExceeded {
                estimate,
                budget: self.budget,
            });
        }
        let mut count = 0usize;
        if rect.is_empty() {
            return Ok(0);
        }
        let s = self.tile_size;
        let (i0, i1) = (
            (rect.min.x / s).floor() as i64,
            (rect.max.x / s).ceil() as i64,
        );
        let (j0, j1) = (
            (rect.min.y / s).floor() as i64,
            (rect.max.y / s).ceil() as i64,
        );
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

/// The sum of a slice of densities.
struct SumOf<'a, D>(&'a [D]);

impl<D: Density> Density for SumOf<'_, D> {
    fn density(&self, p: DVec2) -> f64 {
        self.0.iter().map(|d| sanitize(d.density(p))).sum()
    }
    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.0.iter().map(|d| sanitize(d.max_over(min, max))).sum()
    }
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.0.iter().map(|d| sanitize(d.min_over(min, max))).sum()
    }
}

struct Visit<'a, D: ?Sized, F> {
    sampler: &'a Sampler,
    rect: Rect,
    density: &'a D,
    emit: &'a mut F,
}

impl<D: Density + ?Sized, F: FnMut(Point)> Visit<'_, D, F> {
    /// Visits the base tiles `[i0, i1) x [j0, j1)`, halving the block while it is large and
    /// skipping blocks where the density is zero: an empty region costs one bound however
    /// many tiles it spans.
    fn blocks(&mut self, i0: i64, i1: i64, j0: i64, j1: i64, s: f64) {
        const LEAF: i64 = 8;
        if i1 <= i0 || j1 <= j0 {
            return;
        }
        // Sides compared separately: their product can overflow for huge rectangles.
        if i1 - i0 > LEAF || j1 - j0 > LEAF {
            let block = Rect {
                min: DVec2::new(i0 as f64 * s, j0 as f64 * s),
                max: DVec2::new(i1 as f64 * s, j1 as f64 * s),
            }
            .intersect(&self.rect);
            let bound = sanitize(self.density.max_over(block.min, block.max));
            if block.is_empty() || bound.is_nan() || bound <= 0.0 {
                return;
            }
            let (im, jm) = (i0 + (i1 - i0) / 2, j0 + (j1 - j0) / 2);
            if i1 - i0 >= j1 - j0 {
                self.blocks(i0, im, j0, j1, s);
                self.blocks(im, i1, j0, j1, s);
            } else {
                self.blocks(i0, i1, j0, jm, s);
                self.blocks(i0, i1, jm, j1, s);
            }
            return;
        }
        for j in j0..j1 {
            for i in i0..i1 {
                let t = base_tile(self.sampler.seed, self.sampler.colors, i, j);
                self.tile(t, 0, i, j, s, None);
            }
        }
    }

    /// The lower density bound over `rect` times `area`, at most `limit`; 0 when not finite.
    fn low(&self, rect: &Rect, limit: f64, area: f64) -> f64 {
        let low = sanitize(self.density.min_over(rect.min, rect.max)) * area;
        if low.is_finite() { low.min(limit) } else { 0.0 }
    }

    /// Visits tile `t` of level `level` at lattice `(ix, iy)`, side `s`. `known` is the
    /// upper and lower density bounds over its part of the query times its area, when the
    /// parent has them. Points ranked below the lower bound are taken without evaluating the
    /// density (the bound guarantees the evaluation would take them).
    fn tile(&mut self, t: u16, level: u32, ix: i64, iy: i64, s: f64, known: Option<(f64, f64)>) {
        let tile_rect = Rect {
            min: DVec2::new(ix as f64 * s, iy as f64 * s),
            max: DVec2::new((ix + 1) as f64 * s, (iy + 1) as f64 * s),
        };
        let clip = tile_rect.intersect(&self.rect);
        if clip.is_empty() {
            return;
        }
        let area = s * s;
        let (limit, low) = known.unwrap_or_else(|| {
            let limit = sanitize(self.density.max_over(clip.min, clip.max)) * area;
            (limit, self.low(&clip, limit, area))
        });
        if limit.is_nan() || limit <= 0.0 {
            return;
        }
        let sampler = self.sampler;
        let tile = &sampler.tiles[t as usize];
        let big_n = sampler.points_per_tile as f64;
        let n = sampler.n;
        let cells = (n * n) as usize;
        let child_s = s / n as f64;
        // Per-cell bounds pay off once the tile asks for more than a few points per cell, or
        // when it is only partly inside the query; otherwise the tile's bound serves all.
        let mut cell_limit = [limit; 64];
        let mut cell_low = [low; 64];
        if limit > 4.0 * cells as f64 || clip != tile_rect {
            for (cell, (slot, low_slot)) in cell_limit[..cells]
                .iter_mut()
                .zip(&mut cell_low[..cells])
                .enumerate()
            {
                let (a, b) = ((cell as i64 % n) as f64, (cell as i64 / n) as f64);
                let cell_rect = Rect {
                    min: tile_rect.min + DVec2::new(a, b) * child_s,
                    max: tile_rect.min + DVec2::new(a + 1.0, b + 1.0) * child_s,
                }
                .intersect(&self.rect);
                (*slot, *low_slot) = if cell_rect.is_empty() {
                    (0.0, 0.0)
                } else {
                    let cell_max = (sanitize(self.density.max_over(cell_rect.min, cell_rect.max))
                        * area)
                        .min(limit);
                    (cell_max, self.low(&cell_rect, cell_max, area).max(low))
                };
            }
        }
        if level == 0 {
            let offset = unit_f64(hash_words(
                sampler.seed ^ OFFSET_STREAM,
                &[ix as u64, iy as u64],
            ));
            for (cell, points) in tile.base_cells.iter().enumerate() {
                let lim = cell_limit[cell] - offset;
                let sure = cell_low[cell];
                for cp in points.iter().take_while(|cp| (cp.rank as f64) < lim) {
                    let p = DVec2::new((ix as f64 + cp.frac[0]) * s, (iy as f64 + cp.frac[1]) * s);
                    let rank = cp.rank as f64 + offset;
                    if self.rect.contains(p)
                        && (rank < sure || sanitize(self.density.density(p)) * area > rank)
                    {
                        (self.emit)(Point {
                            position: p,
                            id: PointId {
                                level: 0,
                                x: ix,
                                y: iy,
                                index: cp.index,
                            },
                            threshold: rank / area,
                            class: 0,
                        });
                    }
                }
            }
        }
        if limit <= big_n || level >= MAX_LEVEL {
            return;
        }
        // Child lattice indices, with room for the cell offset: never overflow, just stop.
        let child = |v: i64| v.checked_mul(n).filter(|c| c.checked_add(n).is_some());
        let (Some(cx0), Some(cy0)) = (child(ix), child(iy)) else {
            return;
        };
        let full = sampler.sub_len as f64;
        for (cell, points) in tile.sub_cells.iter().enumerate() {
            let lim = cell_limit[cell];
            if lim <= big_n {
                continue;
            }
            let sure = cell_low[cell];
            let (cx, cy) = (cx0 + cell as i64 % n, cy0 + cell as i64 / n);
            for cp in points.iter().take_while(|cp| (cp.rank as f64) < lim) {
                let p = DVec2::new(
                    (cx as f64 + cp.frac[0]) * child_s,
                    (cy as f64 + cp.frac[1]) * child_s,
                );
                let rank = cp.rank as f64;
                if self.rect.contains(p)
                    && (rank < sure || sanitize(self.density.density(p)) * area > rank)
                {
                    (self.emit)(Point {
                        position: p,
                        id: PointId {
                            level: level as u8 + 1,
                            x: cx,
                            y: cy,
                            index: cp.index,
                        },
                        threshold: cp.rank as f64 / area,
                        class: 0,
                    });
                }
            }
        }
        for (cell, &child_tile) in tile.children.iter().enumerate() {
            let lim = cell_limit[cell];
            if lim > full {
                let (cx, cy) = (cx0 + cell as i64 % n, cy0 + cell as i64 / n);
                // The cell's bounds in the child's own area units.
                let cells = (n * n) as f64;
                self.tile(
                    child_tile,
                    level + 1,
                    cx,
                    cy,
                    child_s,
                    Some((lim / cells, cell_low[cell] / cells)),
                );
            }
        }
    }
}
