//! The traversal of a query: base tiles in blocks, then each tile's cells, its subdivision
//! ranking and its children, where the density's bounds ask for them.

use super::lattice::Placement;
use super::point::{Point, PointId};
use super::prepared::CellPoint;
use super::{MAX_LEVEL, OFFSET_STREAM, Rect, Sampler, TileRange};
use crate::density::{Density, LocalModel, Patch, sanitize};
use crate::rng::{hash_words, unit_f64};
use crate::tiling::base_tile;
use glam::DVec2;

/// Blocks of base tiles wider than this are bounded as a whole before they are split.
pub(super) const LEAF_BLOCK: i64 = 8;

/// Most cells of a subdivision (`n = 8`).
const MAX_CELLS: usize = 64;

/// One query in progress: the rectangle, the density and where points go.
pub(super) struct Visit<'a, 'e, D: ?Sized, F> {
    pub sampler: &'a Sampler,
    pub rect: Rect,
    pub density: &'a D,
    pub emit: &'e mut F,
}

/// Where a traversal's points go, run by run: a closure taking each [`Point`], or a sink
/// that keeps each point's frame and place in its cell list to build the points later.
pub(super) trait Sink {
    /// A run of points in `frame` begins.
    #[inline(always)]
    fn begin(&mut self, frame: &Frame) {
        let _ = frame;
    }
    /// The run's point `cp`, at `slot` in the frame's cell list and at `position`, appears.
    fn accept(&mut self, frame: &Frame, slot: usize, cp: &CellPoint, position: DVec2);
}

impl<F: FnMut(Point)> Sink for F {
    #[inline(always)]
    fn accept(&mut self, frame: &Frame, _: usize, cp: &CellPoint, position: DVec2) {
        self(frame.point(cp, position))
    }
}

/// Which of the sampler's cell lists a run's points come from.
#[derive(Clone, Copy)]
#[cfg_attr(not(feature = "parallel"), allow(dead_code))]
pub(super) struct CellList {
    tile: u16,
    cell: u8,
    /// The subdivision ranking's list of the cell, rather than the base points'.
    subdivision: bool,
}

impl Sampler {
    /// The points of a cell list.
    #[cfg(feature = "parallel")]
    #[inline(always)]
    pub(super) fn cell_list(&self, list: CellList) -> &[CellPoint] {
        let tile = &self.tiles[list.tile as usize];
        let lists = if list.subdivision {
            &tile.sub_cells
        } else {
            &tile.base_cells
        };
        &lists[list.cell as usize]
    }
}

/// What the points of a run share: the tile they belong to, the offset added to their
/// ranks and the area their ranking counts per.
#[derive(Clone, Copy)]
pub(super) struct Frame {
    /// The tile the points belong to (their identity and frame).
    owner: TileAt,
    /// Added to every rank (the base tile's hashed offset; 0 in subdivisions).
    offset: f64,
    /// Area of the tile whose ranking this is (thresholds are ranks per this area).
    area: f64,
    /// Where the points come from (what the parallel query keeps of them).
    #[cfg_attr(not(feature = "parallel"), allow(dead_code))]
    pub list: CellList,
}

impl Frame {
    /// The world position of `cp`, on the sampler's `placement`.
    #[inline(always)]
    pub fn position(&self, cp: &CellPoint, placement: &Placement) -> DVec2 {
        let o = &self.owner;
        placement.world(DVec2::new(
            (o.ix as f64 + cp.frac[0]) * o.side,
            (o.iy as f64 + cp.frac[1]) * o.side,
        ))
    }

    /// The rank of `cp` in its tile's ranking.
    #[inline(always)]
    fn rank(&self, cp: &CellPoint) -> f64 {
        cp.rank as f64 + self.offset
    }

    /// The point `cp` at its `position`.
    #[inline(always)]
    pub fn point(&self, cp: &CellPoint, position: DVec2) -> Point {
        let o = &self.owner;
        Point {
            position,
            id: PointId {
                level: o.level as u8,
                x: o.ix,
                y: o.iy,
                index: cp.index,
            },
            threshold: self.rank(cp) / self.area,
            class: 0,
        }
    }
}

/// A tile of some level at its lattice position.
#[derive(Clone, Copy)]
struct TileAt {
    level: u32,
    ix: i64,
    iy: i64,
    /// Side in world units.
    side: f64,
}

impl TileAt {
    /// The tile's world square on `placement` (closed: it holds its points).
    fn rect(&self, placement: &Placement) -> Rect {
        let s = self.side;
        placement.world_rect(
            DVec2::new(self.ix as f64 * s, self.iy as f64 * s),
            DVec2::new((self.ix + 1) as f64 * s, (self.iy + 1) as f64 * s),
        )
    }

    /// The world patch of the tile's cell `(a, b)` of `n x n` on `placement`.
    fn cell_patch(&self, (a, b): (i64, i64), n: i64, placement: &Placement) -> Patch {
        let child_s = self.side / n as f64;
        let origin = DVec2::new(self.ix as f64 * self.side, self.iy as f64 * self.side);
        let cell = DVec2::new(a as f64, b as f64);
        placement.world_patch(
            origin + cell * child_s,
            origin + (cell + DVec2::ONE) * child_s,
        )
    }
}

/// A density bound times an area: ranks per tile. Zero density is zero ranks even where the
/// area overflows to infinity (`0 * inf` is NaN, and `NaN.min(limit)` is `limit`: every empty
/// cell of a huge tile would inherit the tile's bound and be visited, 16^24 of them).
#[inline]
fn per_area(density: f64, area: f64) -> f64 {
    let d = sanitize(density);
    if d > 0.0 { d * area } else { 0.0 }
}

/// Upper and lower density bounds of each cell of a tile, times the tile's area: how many
/// of the tile's ranks the cell may show, and how many it shows for sure; and the density's
/// local model over the cell, where it has one.
struct CellBounds {
    limit: [f64; MAX_CELLS],
    low: [f64; MAX_CELLS],
    model: [Option<LocalModel>; MAX_CELLS],
}

/// What a tile's parent knows of it: its cell's bounds in the tile's own area units, and
/// the cell's local model.
#[derive(Clone, Copy)]
struct Known {
    limit: f64,
    low: f64,
    model: Option<LocalModel>,
}

/// A run of ranked points of one cell to emit, with what they share.
struct Run<'p> {
    points: &'p [CellPoint],
    /// Points whose rank is below this may appear.
    limit: f64,
    /// Points whose rank is below this appear without evaluating the density.
    sure: f64,
    /// Decides most of the other points without evaluating the density.
    model: Option<LocalModel>,
    frame: Frame,
}

impl<'a, D: Density + ?Sized, F: Sink> Visit<'a, '_, D, F> {
    /// Visits the base tiles `[i0, i1) x [j0, j1)`, halving the block while it is large and
    /// skipping blocks where the density is zero: an empty region costs one bound however
    /// many tiles it spans.
    pub fn blocks(&mut self, i0: i64, i1: i64, j0: i64, j1: i64, s: f64) {
        if i1 <= i0 || j1 <= j0 {
            return;
        }
        // Sides compared separately: their product can overflow for huge rectangles.
        if i1 - i0 > LEAF_BLOCK || j1 - j0 > LEAF_BLOCK {
            let block = self.sampler.block_rect(TileRange { i0, i1, j0, j1 });
            let Some(block) = block.intersect(&self.rect) else {
                return;
            };
            let bound = sanitize(self.density.max_over(block.min(), block.max()));
            if bound.is_nan() || bound <= 0.0 {
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
        for iy in j0..j1 {
            for ix in i0..i1 {
                let t = base_tile(self.sampler.seed, self.sampler.colors, ix, iy);
                let at = TileAt {
                    level: 0,
                    ix,
                    iy,
                    side: s,
                };
                self.tile(t, at, None);
            }
        }
    }

    /// The lower density bound over `rect` times `area`, at most `limit`; 0 when not finite.
    fn low(&self, rect: &Rect, limit: f64, area: f64) -> f64 {
        let low = per_area(self.density.min_over(rect.min(), rect.max()), area);
        if low.is_finite() { low.min(limit) } else { 0.0 }
    }

    /// Visits tile `t` at `at`, with what its parent knows of it. Points ranked below the
    /// lower bound are taken without evaluating the density (the bound guarantees the
    /// evaluation would take them).
    fn tile(&mut self, t: u16, at: TileAt, known: Option<Known>) {
        let tile_rect = at.rect(&self.sampler.placement);
        let Some(clip) = tile_rect.intersect(&self.rect) else {
            return;
        };
        let area = at.side * at.side;
        let known = known.unwrap_or_else(|| {
            let limit = per_area(self.density.max_over(clip.min(), clip.max()), area);
            Known {
                limit,
                low: self.low(&clip, limit, area),
                model: None,
            }
        });
        let limit = known.limit;
        if limit.is_nan() || limit <= 0.0 {
            return;
        }
        let bounds = self.cell_bounds(at, known, clip != tile_rect);
        if at.level == 0 {
            self.base_points(t, at, &bounds);
        }
        let big_n = self.sampler.points_per_tile as f64;
        if limit <= big_n || at.level >= MAX_LEVEL {
            return;
        }
        self.subdivision(t, at, &bounds);
    }

    /// Per-cell bounds pay off once the tile asks for more than a few points per cell, or
    /// when it is only partly inside the query; otherwise the tile's bounds (and its
    /// parent's model) serve all cells. A cell's own local model, where the density has one,
    /// gives both its bounds and its points' decisions.
    fn cell_bounds(&self, at: TileAt, known: Known, clipped: bool) -> CellBounds {
        let (n, placement) = (self.sampler.n, self.sampler.placement);
        let cells = (n * n) as usize;
        let Known { limit, low, model } = known;
        let mut bounds = CellBounds {
            limit: [limit; MAX_CELLS],
            low: [low; MAX_CELLS],
            model: [model; MAX_CELLS],
        };
        if !(limit > 4.0 * cells as f64 || clipped) {
            return bounds;
        }
        let area = at.side * at.side;
        for cell in 0..cells {
            let patch = at.cell_patch((cell as i64 % n, cell as i64 / n), n, &placement);
            let cell_rect = Rect::from_ordered(patch.min, patch.max);
            let Some(r) = cell_rect.intersect(&self.rect) else {
                (bounds.limit[cell], bounds.low[cell]) = (0.0, 0.0);
                continue;
            };
            let patch = Patch {
                min: r.min(),
                max: r.max(),
                ..patch
            };
            let cell_model = self.density.local_model(&patch);
            let (max, cell_low) = match cell_model {
                Some(m) => {
                    bounds.model[cell] = cell_model;
                    let (lo, hi) = m.bounds_over(&patch);
                    let mut max = per_area(hi, area);
                    // A model may be looser than the density's maximum, which the work
                    // bound admitted the query by: a cell is only subdivided when both
                    // ask for it (one bound against the n^2 its children would take).
                    if max > self.sampler.sub_len as f64 {
                        max = max.min(per_area(self.density.max_over(r.min(), r.max()), area));
                    }
                    (max, per_area(lo, area))
                }
                None => {
                    let max = per_area(self.density.max_over(r.min(), r.max()), area);
                    (max, self.low(&r, max.min(limit), area))
                }
            };
            let cell_max = max.min(limit);
            bounds.limit[cell] = cell_max;
            bounds.low[cell] = cell_low.min(cell_max).max(low);
        }
        bounds
    }

    /// The base tile's own points, each cell's run up to its bound.
    fn base_points(&mut self, t: u16, at: TileAt, bounds: &CellBounds) {
        let sampler = self.sampler;
        let offset = unit_f64(hash_words(
            sampler.seed ^ OFFSET_STREAM,
            &[at.ix as u64, at.iy as u64],
        ));
        let area = at.side * at.side;
        for (cell, points) in sampler.tiles[t as usize].base_cells.iter().enumerate() {
            self.emit_run(Run {
                points,
                limit: bounds.limit[cell] - offset,
                sure: bounds.low[cell],
                model: bounds.model[cell],
                frame: Frame {
                    owner: at,
                    offset,
                    area,
                    list: CellList {
                        tile: t,
                        cell: cell as u8,
                        subdivision: false,
                    },
                },
            });
        }
    }

    /// The tile's subdivision ranking past its base points (the points of its children that
    /// appear at this level), then the children whose cells ask for more than all of it.
    fn subdivision(&mut self, t: u16, at: TileAt, bounds: &CellBounds) {
        let sampler = self.sampler;
        let n = sampler.n;
        // Child lattice indices, with room for the cell offset: never overflow, just stop.
        let child = |v: i64| v.checked_mul(n).filter(|c| c.checked_add(n).is_some());
        let (Some(cx0), Some(cy0)) = (child(at.ix), child(at.iy)) else {
            return;
        };
        let big_n = sampler.points_per_tile as f64;
        let area = at.side * at.side;
        let tile = &sampler.tiles[t as usize];
        let child_at = |cell: usize| TileAt {
            level: at.level + 1,
            ix: cx0 + cell as i64 % n,
            iy: cy0 + cell as i64 / n,
            side: at.side / n as f64,
        };
        for (cell, points) in tile.sub_cells.iter().enumerate() {
            if bounds.limit[cell] > big_n {
                self.emit_run(Run {
                    points,
                    limit: bounds.limit[cell],
                    sure: bounds.low[cell],
                    model: bounds.model[cell],
                    frame: Frame {
                        owner: child_at(cell),
                        offset: 0.0,
                        area,
                        list: CellList {
                            tile: t,
                            cell: cell as u8,
                            subdivision: true,
                        },
                    },
                });
            }
        }
        let full = sampler.sub_len as f64;
        // The cell's bounds in the child's own area units.
        let cells = (n * n) as f64;
        for (cell, &child_tile) in tile.children.iter().enumerate() {
            let lim = bounds.limit[cell];
            if lim > full {
                let known = Known {
                    limit: lim / cells,
                    low: bounds.low[cell] / cells,
                    model: bounds.model[cell],
                };
                self.tile(child_tile, child_at(cell), Some(known));
            }
        }
    }

    /// Emits the points of a run that lie in the query and whose rank the density reaches.
    // Always inlined: it is the per-point loop, and the density call must inline into it
    // (measured: noise queries 1.3x faster than with a plain hint).
    #[inline(always)]
    fn emit_run(&mut self, run: Run<'a>) {
        let frame = &run.frame;
        self.emit.begin(frame);
        for (slot, cp) in run
            .points
            .iter()
            .take_while(|cp| (cp.rank as f64) < run.limit)
            .enumerate()
        {
            let p = frame.position(cp, &self.sampler.placement);
            let rank = frame.rank(cp);
            if self.rect.contains(p) && (rank < run.sure || self.decide(&run, p, rank)) {
                self.emit.accept(frame, slot, cp, p);
            }
        }
    }

    /// Whether a point whose rank the bounds leave open appears: by the run's local model
    /// where it decides, by the density otherwise.
    #[inline(always)]
    fn decide(&self, run: &Run, p: DVec2, rank: f64) -> bool {
        let area = run.frame.area;
        match run.model {
            Some(model) => model
                .decides(p, area, rank)
                .unwrap_or_else(|| self.density.exceeds_near(p, area, rank)),
            None => self.density.exceeds(p, area, rank),
        }
    }
}
