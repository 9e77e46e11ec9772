//! Small geometric helpers shared by construction and analysis.

use glam::DVec2;
use std::ops::ControlFlow;

/// Spacing of a hexagonal packing of `k` points on unit area: the largest possible minimum
/// distance. The normalized minimum distance `rho` is `d_min / hex_spacing(k)`.
#[inline]
pub fn hex_spacing(points_per_unit_area: f64) -> f64 {
    (2.0 / (3.0f64.sqrt() * points_per_unit_area)).sqrt()
}

/// Shortest offset from `a` to `b` on the unit torus.
#[cfg(feature = "build")]
#[inline]
pub fn torus_delta(a: DVec2, b: DVec2) -> DVec2 {
    let mut d = b - a;
    d.x -= d.x.round();
    d.y -= d.y.round();
    d
}

/// The translations under which a disc of radius `r` around `p` overlaps the unit square
/// (the identity first), for toroidal neighbour searches.
pub fn torus_shifts(p: DVec2, r: f64) -> impl Iterator<Item = DVec2> {
    let xs: &[f64] = if p.x < r {
        &[0.0, 1.0]
    } else if p.x > 1.0 - r {
        &[0.0, -1.0]
    } else {
        &[0.0]
    };
    let ys: &[f64] = if p.y < r {
        &[0.0, 1.0]
    } else if p.y > 1.0 - r {
        &[0.0, -1.0]
    } else {
        &[0.0]
    };
    xs.iter()
        .flat_map(move |&x| ys.iter().map(move |&y| DVec2::new(x, y)))
}

/// A uniform bucket grid over a rectangle, storing indices. Used for neighbour searches in
/// construction and analysis (points are few enough per cell that a grid beats a tree).
#[derive(Clone, Debug)]
pub struct BucketGrid {
    origin: DVec2,
    cell: f64,
    cols: usize,
    rows: usize,
    cells: Vec<Vec<u32>>,
}

impl BucketGrid {
    /// A grid covering `[min, max]` with square cells of about `cell` side.
    pub fn new(min: DVec2, max: DVec2, cell: f64) -> Self {
        let size = (max - min).max(DVec2::splat(cell));
        let cols = ((size.x / cell).ceil() as usize).clamp(1, 4096);
        let rows = ((size.y / cell).ceil() as usize).clamp(1, 4096);
        let cell = (size.x / cols as f64).max(size.y / rows as f64);
        Self {
            origin: min,
            cell,
            cols,
            rows,
            cells: vec![Vec::new(); cols * rows],
        }
    }

    #[inline]
    fn coords(&self, p: DVec2) -> (isize, isize) {
        let q = (p - self.origin) / self.cell;
        (q.x.floor() as isize, q.y.floor() as isize)
    }

    /// Inserts index `i` at position `p` (clamped into the grid).
    pub fn insert(&mut self, p: DVec2, i: u32) {
        let (cx, cy) = self.coords(p);
        let cx = cx.clamp(0, self.cols as isize - 1) as usize;
        let cy = cy.clamp(0, self.rows as isize - 1) as usize;
        self.cells[cy * self.cols + cx].push(i);
    }

    /// Calls `f` with every index stored in a cell that intersects the disc `(p, r)`.
    #[inline]
    pub fn for_each_near(&self, p: DVec2, r: f64, mut f: impl FnMut(u32)) {
        let _ = self.try_for_each_near(p, r, |i| {
            f(i);
            ControlFlow::Continue(())
        });
    }

    /// [`BucketGrid::for_each_near`] until `f` breaks.
    #[inline]
    pub fn try_for_each_near(
        &self,
        p: DVec2,
        r: f64,
        mut f: impl FnMut(u32) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let (x0, y0) = self.coords(p - DVec2::splat(r));
        let (x1, y1) = self.coords(p + DVec2::splat(r));
        let x0 = x0.max(0);
        let y0 = y0.max(0);
        let x1 = x1.min(self.cols as isize - 1);
        let y1 = y1.min(self.rows as isize - 1);
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                for &i in &self.cells[cy as usize * self.cols + cx as usize] {
                    f(i)?;
                }
            }
        }
        ControlFlow::Continue(())
    }
}

/// Each point's nearest other point, `(index, distance)` (plane, no wrapping; `None` for a
/// point alone). A bucket grid with about one point per cell, searched in growing squares:
/// linear in the number of points for any set without dense clusters, and for coincident
/// points too (a point stops searching at a twin: nothing is nearer than 0).
pub fn nearest_neighbours(points: &[DVec2]) -> Vec<Option<(u32, f64)>> {
    if points.len() < 2 {
        return vec![None; points.len()];
    }
    let (mut min, mut max) = (points[0], points[0]);
    for &p in points {
        min = min.min(p);
        max = max.max(p);
    }
    let area = ((max.x - min.x) * (max.y - min.y)).max(1e-300);
    let cell = (area / points.len() as f64).sqrt().max(1e-12);
    let mut grid = BucketGrid::new(min, max, cell);
    for (i, &p) in points.iter().enumerate() {
        grid.insert(p, i as u32);
    }
    let reach = (max - min).length() + cell;
    let nearest = |i: usize, p: DVec2| {
        let mut r = cell;
        loop {
            let mut best: Option<(u32, f64)> = None;
            let _ = grid.try_for_each_near(p, r, |j| {
                if j as usize == i {
                    return ControlFlow::Continue(());
                }
                let d = (points[j as usize] - p).length();
                if best.is_none_or(|(_, b)| d < b) {
                    best = Some((j, d));
                }
                if d == 0.0 {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            });
            match best {
                Some((_, d)) if d <= r => return best,
                _ if reach.is_nan() || r > reach => return best,
                _ => r *= 2.0,
            }
        }
    };
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| nearest(i, p))
        .collect()
}

/// The two closest points `(i, j, distance)`, `i < j`, or `None` with fewer than two.
pub fn closest_pair(points: &[DVec2]) -> Option<(usize, usize, f64)> {
    nearest_neighbours(points)
        .into_iter()
        .enumerate()
        .filter_map(|(i, n)| n.map(|(j, d)| (i.min(j as usize), i.max(j as usize), d)))
        .min_by(|a, b| a.2.total_cmp(&b.2))
}

#[cfg(feature = "build")]
/// Even-odd point-in-polygon test.
pub fn point_in_polygon(p: DVec2, polygon: &[DVec2]) -> bool {
    let mut inside = false;
    let mut j = polygon.len() - 1;
    for i in 0..polygon.len() {
        let (a, b) = (polygon[i], polygon[j]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torus_delta_takes_the_short_way_round() {
        let d = torus_delta(DVec2::new(0.95, 0.5), DVec2::new(0.05, 0.5));
        assert!((d.x - 0.1).abs() < 1e-12 && d.y.abs() < 1e-12);
    }

    #[test]
    fn polygon_contains_inner_point_only() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!(point_in_polygon(DVec2::new(0.5, 0.5), &square));
        assert!(!point_in_polygon(DVec2::new(1.5, 0.5), &square));
    }

    #[test]
    fn nearest_neighbours_are_exact_and_linear_on_coincident_points() {
        let mut rng = crate::rng::Rng::new(5, 1);
        let pts: Vec<DVec2> = (0..500)
            .map(|_| DVec2::new(rng.next_f64(), rng.next_f64() * 3.0))
            .collect();
        let fast = nearest_neighbours(&pts);
        for (i, p) in pts.iter().enumerate() {
            let brute = (0..pts.len())
                .filter(|&j| j != i)
                .map(|j| (pts[j] - *p).length())
                .fold(f64::INFINITY, f64::min);
            assert_eq!(fast[i].unwrap().1, brute);
        }
        // 200 000 points in one place and one far away: one cell holds them all, and each
        // stops at its first twin.
        let mut heap = vec![DVec2::splat(0.25); 200_000];
        heap.push(DVec2::new(1e6, -3.0));
        let near = nearest_neighbours(&heap);
        assert!(near[..200_000].iter().all(|n| n.unwrap().1 == 0.0));
        assert!(near[200_000].unwrap().1 > 1e5);
        // (Quadratic would be 4e10 distance checks: this test would run for minutes.)
        assert_eq!(closest_pair(&heap).unwrap().2, 0.0);
    }

    #[test]
    fn grid_finds_points_within_radius() {
        let mut g = BucketGrid::new(DVec2::ZERO, DVec2::ONE, 0.1);
        g.insert(DVec2::new(0.5, 0.5), 7);
        g.insert(DVec2::new(0.9, 0.9), 8);
        let mut found = vec![];
        g.for_each_near(DVec2::new(0.52, 0.5), 0.05, |i| found.push(i));
        assert!(found.contains(&7) && !found.contains(&8));
    }
}
