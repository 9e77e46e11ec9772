//! Progressive toroidal source tiles (paper section 4, after McCool and Fiume 1992).
//!
//! Dart throwing with a slowly shrinking radius: a dart is accepted when it is farther than
//! the current radius from every accepted point (on the torus), and the radius shrinks by
//! `shrink` once no dart fits. The acceptance order is the point's rank, so any prefix of the
//! sequence is itself a Poisson-disk set.
//!
//! Darts come from a fixed pool of uniformly random positions (`pool_factor` per output
//! point), visited in random order. Knowing every dart in advance lets each radius be
//! *saturated* exactly (no dart of the pool fits any more) before it shrinks, which random
//! darts with a failure counter only approximate: every prefix then stays close to the
//! jamming limit of random packing (normalized minimum distance about 0.75).

use crate::geometry::{BucketGrid, hex_spacing, torus_delta, torus_shifts};
use crate::rng::Rng;
use glam::DVec2;

/// Parameters of progressive dart throwing.
#[derive(Clone, Copy, Debug)]
pub struct DartThrowing {
    /// Number of points to produce.
    pub points: usize,
    /// Darts in the pool per output point.
    pub pool_factor: usize,
    /// Radius factor applied once a radius is saturated (paper: 0.99).
    pub shrink: f64,
}

impl DartThrowing {
    /// The settings used for the shipped tile set.
    pub fn new(points: usize) -> Self {
        Self {
            points,
            pool_factor: 40,
            shrink: 0.9,
        }
    }

    /// Runs dart throwing on the unit torus; the returned order is the progressive rank.
    pub fn run(&self, rng: &mut Rng) -> Vec<DVec2> {
        let n = self.points;
        let mut points: Vec<DVec2> = Vec::with_capacity(n);
        if n == 0 {
            return points;
        }
        let pool_len = (n * self.pool_factor.max(2)).max(64);
        let pool: Vec<DVec2> = (0..pool_len)
            .map(|_| DVec2::new(rng.next_f64(), rng.next_f64()))
            .collect();
        let cell = hex_spacing(pool_len as f64);
        let mut grid = BucketGrid::new(DVec2::ZERO, DVec2::ONE, cell);
        for (i, &p) in pool.iter().enumerate() {
            grid.insert(p, i as u32);
        }
        // Squared distance from every dart to the nearest accepted point.
        let mut clearance = vec![f64::INFINITY; pool_len];
        let mut alive: Vec<u32> = (0..pool_len as u32).collect();
        let mut radius = 0.9 * hex_spacing(1.0);
        while points.len() < n && !alive.is_empty() {
            let r2 = radius * radius;
            rng.shuffle(&mut alive);
            for &c in &alive {
                if clearance[c as usize] < r2 {
                    continue;
                }
                let p = pool[c as usize];
                points.push(p);
                if points.len() == n {
                    break;
                }
                // Darts near the new point lose clearance (toroidally; the disc can wrap).
                let reach = radius.min(0.5);
                for shift in torus_shifts(p, reach) {
                    let q = p + shift;
                    grid.for_each_near(q, reach, |j| {
                        let d = (pool[j as usize] - q).length_squared();
                        if d < clearance[j as usize] {
                            clearance[j as usize] = d;
                        }
                    });
                }
                if radius >= 0.5 {
                    // Discs wider than the torus: measure the rest directly.
                    for (j, &d) in pool.iter().enumerate() {
                        clearance[j] = clearance[j].min(torus_delta(p, d).length_squared());
                    }
                }
            }
            // Accepted darts have zero clearance; the rest may fit a smaller radius.
            alive.retain(|&c| clearance[c as usize] > 0.0);
            let widest = alive
                .iter()
                .map(|&c| clearance[c as usize])
                .fold(0.0f64, f64::max);
            radius = (radius * self.shrink).min(widest.sqrt());
        }
        points
    }
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
            assert!(rho > 0.65, "prefix {k}: rho {rho}");
        }
    }

    #[test]
    fn deterministic_for_a_seed() {
        let a = DartThrowing::new(100).run(&mut Rng::new(9, 0));
        let b = DartThrowing::new(100).run(&mut Rng::new(9, 0));
        assert_eq!(a, b);
    }
}
