//! Nearest-neighbour statistics and the normalized minimum distance.

use crate::geometry::{BucketGrid, hex_spacing};
use glam::DVec2;

/// Smallest distance between two distinct points, or `None` with fewer than two points.
pub fn min_distance(points: &[DVec2]) -> Option<f64> {
    nearest_neighbour_distances(points)
        .into_iter()
        .reduce(f64::min)
}

/// Distance from every point to its nearest other point (plane, no wrapping). Points
/// without any other point get `f64::INFINITY`.
pub fn nearest_neighbour_distances(points: &[DVec2]) -> Vec<f64> {
    if points.len() < 2 {
        return vec![f64::INFINITY; points.len()];
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
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let mut r = cell;
            loop {
                let mut best = f64::INFINITY;
                grid.for_each_near(p, r, |j| {
                    if j as usize != i {
                        best = best.min((points[j as usize] - p).length());
                    }
                });
                if best <= r || r > (max - min).length() + cell {
                    return best;
                }
                r *= 2.0;
            }
        })
        .collect()
}

/// Normalized minimum distance `rho = d_min / sqrt(2 / (sqrt(3) * density))`: 1 for a
/// hexagonal lattice, about 0.75 for good Poisson-disk sets, near 0 for white noise.
pub fn rho(points: &[DVec2], density: f64) -> Option<f64> {
    min_distance(points).map(|d| d / hex_spacing(density))
}
