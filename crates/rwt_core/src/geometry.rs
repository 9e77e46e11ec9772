//! Small geometric helpers shared by construction and analysis.

use glam::DVec2;

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
        let (x0, y0) = self.coords(p - DVec2::splat(r));
        let (x1, y1) = self.coords(p + DVec2::splat(r));
        let x0 = x0.max(0);
        let y0 = y0.max(0);
        let x1 = x1.min(self.cols as isize - 1);
        let y1 = y1.min(self.rows as isize - 1);
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                for &i in &self.cells[cy as usize * self.cols + cx as usize] {
                    f(i);
                }
            }
        }
    }
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
    fn grid_finds_points_within_radius() {
        let mut g = BucketGrid::new(DVec2::ZERO, DVec2::ONE, 0.1);
        g.insert(DVec2::new(0.5, 0.5), 7);
        g.insert(DVec2::new(0.9, 0.9), 8);
        let mut found = vec![];
        g.for_each_near(DVec2::new(0.52, 0.5), 0.05, |i| found.push(i));
        assert!(found.contains(&7) && !found.contains(&8));
    }
}
