//! Progressive toroidal source tiles (paper section 4, after McCool and Fiume 1992).
//!
//! Dart throwing with a slowly shrinking radius: a dart is accepted when it is farther than
//! the current radius from every accepted point (on the torus); after a run of consecutive
//! failures the radius shrinks by `shrink`. The acceptance order is the point's rank, so any
//! prefix of the sequence is itself a Poisson-disk set. Source tiles are the raw material the
//! Wang tiles are cut from.

use crate::geometry::{BucketGrid, hex_spacing, torus_delta};
use crate::rng::Rng;
use glam::DVec2;

/// Parameters of progressive dart throwing.
#[derive(Clone, Copy, Debug)]
pub struct DartThrowing {
    /// Number of points to produce.
    pub points: usize,
    /// Consecutive rejected darts before the radius shrinks. Higher saturates each radius
    /// better (higher minimum distance for every prefix) at a linear cost in time.
    pub failures_before_shrink: u32,
    /// Radius factor applied after a run of failures (paper: 0.99).
    pub shrink: f64,
}

impl DartThrowing {
    /// The settings used for the shipped tile set.
    pub fn new(points: usize) -> Self {
        Self {
            points,
            failures_before_shrink: 2000,
            shrink: 0.995,
        }
    }

    /// Runs dart throwing on the unit torus; the returned order is the progressive rank.
    pub fn run(&self, rng: &mut Rng) -> Vec<DVec2> {
        let n = self.points;
        let mut points: Vec<DVec2> = Vec::with_capacity(n);
        if n == 0 {
            return points;
        }
        // A grid sized for the final radius; early (large) radii scan the point list instead.
        let final_radius = 0.6 * hex_spacing(n as f64);
        let mut grid = BucketGrid::new(DVec2::ZERO, DVec2::ONE, final_radius);
        let mut radius = 0.9 * hex_spacing(1.0);
        let mut failures = 0;
        while points.len() < n {
            let p = DVec2::new(rng.next_f64(), rng.next_f64());
            let r2 = radius * radius;
            let free = if radius > 4.0 * final_radius {
                points
                    .iter()
                    .all(|&q| torus_delta(p, q).length_squared() >= r2)
            } else {
                let mut ok = true;
                for shift in torus_shifts(p, radius) {
                    grid.for_each_near(p + shift, radius, |i| {
                        ok &= (points[i as usize] - (p + shift)).length_squared() >= r2;
                    });
                    if !ok {
                        break;
                    }
                }
                ok
            };
            if free {
                grid.insert(p, points.len() as u32);
                points.push(p);
                failures = 0;
            } else {
                failures += 1;
                if failures >= self.failures_before_shrink {
                    radius *= self.shrink;
                    failures = 0;
                }
            }
        }
        points
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn min_torus_distance(points: &[DVec2]) -> f64 {
        let mut best = f64::MAX;
        for i in 0..points.len() {
            for j in i + 1..points.len() {
                best = best.min(torus_delta(points[i], points[j]).length());
            }
        }
        best
    }

    #[test]
    fn every_prefix_is_well_spaced() {
        let pts = DartThrowing::new(512).run(&mut Rng::new(3, 0));
        assert_eq!(pts.len(), 512);
        for k in [16, 64, 256, 512] {
            let rho = min_torus_distance(&pts[..k]) / hex_spacing(k as f64);
            assert!(rho > 0.66, "prefix {k}: rho {rho}");
        }
    }

    #[test]
    fn deterministic_for_a_seed() {
        let a = DartThrowing::new(100).run(&mut Rng::new(9, 0));
        let b = DartThrowing::new(100).run(&mut Rng::new(9, 0));
        assert_eq!(a, b);
    }
}
