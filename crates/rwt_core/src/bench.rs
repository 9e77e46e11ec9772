//! Throughput references that benchmarks print beside query figures.

use crate::query::{Point, PointId};
use crate::rng::{mix64, unit_f64};
use glam::DVec2;

/// The throughput floor of a query: `count` hashed white-noise points written to `out`
/// as query results, in the square `[0, side)^2`. Benchmarks compare queries with this.
pub fn white_noise_floor(count: usize, side: f64, out: &mut Vec<Point>) {
    for i in 0..count as u64 {
        let h = mix64(i);
        out.push(Point {
            position: DVec2::new(unit_f64(h), unit_f64(h.rotate_left(32))) * side,
            id: PointId {
                level: 0,
                x: 0,
                y: 0,
                index: i as u16,
            },
            threshold: 0.0,
            class: 0,
        });
    }
}
