//! The bounds that let a query refuse, up front, what it could not finish: its work, and
//! point spacings finer than positions resolve.

use super::{MAX_LEVEL, MIN_SPACING_ULPS, QueryError, Rect, Sampler};
use crate::density::{Density, sanitize};
use crate::geometry::hex_spacing;
use glam::DVec2;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Most density bounds evaluated while refining a work bound.
const MAX_EVALUATIONS: usize = 4096;

/// A part of the query rectangle with its work bound, ordered by the bound.
#[derive(PartialEq)]
struct Cell(f64, Rect);

impl Eq for Cell {}

impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Cell {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The four quadrants of `r`.
fn quadrants(r: &Rect) -> [Rect; 4] {
    let (min, max) = (r.min(), r.max());
    let c = (min + max) * 0.5;
    [
        Rect::from_ordered(min, c),
        Rect::from_ordered(DVec2::new(c.x, min.y), DVec2::new(max.x, c.y)),
        Rect::from_ordered(DVec2::new(min.x, c.y), DVec2::new(c.x, max.y)),
        Rect::from_ordered(c, max),
    ]
}

impl Sampler {
    /// A bound of the work a query of `rect` does: the density's integral (the points it
    /// yields on average) plus the tiles it visits where the density is positive (twice the
    /// tiles of the deepest level it reaches, which covers the coarser levels). The second
    /// term is negligible for wide rectangles but dominates for huge sparse or very thin
    /// ones. Refined best-first (the cell with the largest bound is split in four) until it
    /// fits the budget or 4096 bounds have been evaluated, so a small dense spot in a huge
    /// empty region is bounded tightly in a few hundred steps, and a huge region of very
    /// sparse density is refused instead of visiting billions of tiles.
    pub fn work_bound<D: Density + ?Sized>(&self, rect: &Rect, density: &D) -> f64 {
        if rect.is_empty() {
            return 0.0;
        }
        let target = self.budget as f64;
        let first = self.cell_bound(rect, density);
        let mut total = first;
        let mut heap = BinaryHeap::from([Cell(first, *rect)]);
        let mut evaluations = 1;
        while total > target && evaluations < MAX_EVALUATIONS && total.is_finite() {
            let Some(Cell(b, r)) = heap.pop() else { break };
            total -= b;
            for q in quadrants(&r) {
                let qb = self.cell_bound(&q, density);
                total += qb;
                evaluations += 1;
                if qb > 0.0 {
                    heap.push(Cell(qb, q));
                }
            }
            // Taking a cell that held most of the total off a running sum cancels what the
            // small cells added (a 1e9-wide rectangle summed to 0): sum them afresh.
            if b > 0.5 * total {
                total = heap.iter().map(|c| c.0).sum();
            }
        }
        total.max(0.0)
    }

    /// The work bound of one rectangle from the density's maximum over it.
    fn cell_bound<D: Density + ?Sized>(&self, r: &Rect, density: &D) -> f64 {
        let d = sanitize(density.max_over(r.min(), r.max()));
        if d.is_nan() {
            return f64::INFINITY;
        }
        if d <= 0.0 {
            return 0.0;
        }
        let s = self.tile_size;
        let n = self.n as f64;
        let finest = s / n.powi(MAX_LEVEL as i32);
        // Tiles are visited down to the first level whose tiles ask for at most the full
        // subdivision sequence: side s_deep with d * s_deep^2 <= n^2 N.
        // (Square roots apart: `sub_len / d` overflows for a denormal density.)
        let s_deep = ((self.sub_len as f64).sqrt() / d.sqrt() / n).clamp(finest, s);
        let size = r.size();
        let tiles = (size.x / s_deep + 2.0) * (size.y / s_deep + 2.0);
        d * r.area() + 2.0 * tiles
    }
}

/// Where a part of a query stands against the precision of `f64` positions.
struct Resolution {
    /// Spacing of points at the part's largest density.
    spacing: f64,
    /// Largest coordinate magnitude in the part.
    coordinate: f64,
    /// The `f64` step there (an upper bound: `coordinate * EPSILON`).
    step: f64,
}

impl Resolution {
    fn of<D: Density + ?Sized>(r: &Rect, density: &D) -> Option<Self> {
        let d = sanitize(density.max_over(r.min(), r.max()));
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        let coordinate = r.min().abs().max(r.max().abs()).max_element();
        Some(Self {
            spacing: hex_spacing(d),
            coordinate,
            step: (coordinate * f64::EPSILON).max(f64::MIN_POSITIVE),
        })
    }

    fn resolved(&self) -> bool {
        self.spacing >= MIN_SPACING_ULPS * self.step
    }
}

impl Sampler {
    /// Refuses a query whose densest points would be closer than [`MIN_SPACING_ULPS`] steps
    /// of `f64` at their coordinates. One density bound decides almost every query; a
    /// rectangle that fails as a whole is split where it fails (up to 4096 bounds), so a
    /// dense spot near the origin of a huge sparse rectangle is served.
    pub(super) fn check_precision<D: Density + ?Sized>(
        &self,
        rect: &Rect,
        density: &D,
    ) -> Result<(), QueryError> {
        let mut failing = Vec::new();
        match Resolution::of(rect, density) {
            Some(r) if !r.resolved() => failing.push((*rect, r)),
            _ => return Ok(()),
        }
        let mut evaluations = 1;
        while let Some((cell, worst)) = failing.pop() {
            if evaluations >= MAX_EVALUATIONS || cell.is_empty() {
                return Err(QueryError::Precision {
                    spacing: worst.spacing,
                    coordinate: worst.coordinate,
                    resolution: worst.step,
                });
            }
            for q in quadrants(&cell) {
                evaluations += 1;
                if let Some(r) = Resolution::of(&q, density).filter(|r| !r.resolved()) {
                    failing.push((q, r));
                }
            }
        }
        Ok(())
    }
}
