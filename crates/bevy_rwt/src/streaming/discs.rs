//! Points as discs of a radius per class, bucketed on a grid for the test "does any disc
//! cover this point": how keep-out clears a layer around another's instances.

use bevy::platform::collections::HashMap;
use glam::DVec2;
use rwt_core::query::Point;

/// The other layer's instances as discs, bucketed by a grid of the largest radius.
pub(super) struct Discs {
    cell: f64,
    buckets: HashMap<(i64, i64), Vec<(DVec2, f64)>>,
}

impl Discs {
    pub fn new(points: &[Point], radii: &[f32], reach: f64) -> Self {
        let mut buckets: HashMap<(i64, i64), Vec<(DVec2, f64)>> = HashMap::new();
        for p in points {
            let r = radii.get(p.class as usize).copied().unwrap_or(0.0) as f64;
            if r > 0.0 {
                let key = Self::key(p.position, reach);
                buckets.entry(key).or_default().push((p.position, r * r));
            }
        }
        Self {
            cell: reach,
            buckets,
        }
    }

    fn key(p: DVec2, cell: f64) -> (i64, i64) {
        ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)
    }

    /// Whether `p` lies strictly within a disc.
    pub fn covers(&self, p: DVec2) -> bool {
        let (x, y) = Self::key(p, self.cell);
        (x - 1..=x + 1).any(|i| {
            (y - 1..=y + 1).any(|j| {
                self.buckets
                    .get(&(i, j))
                    .is_some_and(|discs| discs.iter().any(|(c, r2)| c.distance_squared(p) < *r2))
            })
        })
    }
}
