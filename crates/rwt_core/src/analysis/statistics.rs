//! Nearest-neighbour statistics and the normalized minimum distance.

use crate::geometry::{hex_spacing, nearest_neighbours};
use glam::DVec2;

/// Smallest distance between two distinct points, or `None` with fewer than two points.
pub fn min_distance(points: &[DVec2]) -> Option<f64> {
    nearest_neighbour_distances(points)
        .into_iter()
        .reduce(f64::min)
}

/// Distance from every point to its nearest other point (plane, no wrapping). Points
/// without any other point get `f64::INFINITY`. Linear in the number of points (a bucket
/// grid), coincident points included.
pub fn nearest_neighbour_distances(points: &[DVec2]) -> Vec<f64> {
    nearest_neighbours(points)
        .into_iter()
        .map(|n| n.map_or(f64::INFINITY, |(_, d)| d))
        .collect()
}

/// Normalized minimum distance `rho = d_min / sqrt(2 / (sqrt(3) * density))`: 1 for a
/// hexagonal lattice, about 0.75 for good Poisson-disk sets, near 0 for white noise.
pub fn rho(points: &[DVec2], density: f64) -> Option<f64> {
    min_distance(points).map(|d| d / hex_spacing(density))
}
