//! Points of a query and their stable identities.

use crate::rng::{hash_words, unit_f64};
use glam::DVec2;
use serde::{Deserialize, Serialize};

/// Stable identity of a point: the tile it first appears in and its index there.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[cfg_attr(feature = "bevy_reflect", derive(bevy_reflect::Reflect))]
pub struct PointId {
    /// Subdivision level (0 = base tiles).
    pub level: u8,
    /// Lattice column of the tile at that level.
    pub x: i64,
    /// Lattice row of the tile at that level.
    pub y: i64,
    /// Index of the point in its tile.
    pub index: u16,
}

impl PointId {
    /// A 64-bit hash of the identity and a salt: the source of every derived attribute.
    #[inline]
    pub fn hash(&self, seed: u64, salt: u64) -> u64 {
        hash_words(
            seed,
            &[
                salt,
                self.level as u64,
                self.x as u64,
                self.y as u64,
                self.index as u64,
            ],
        )
    }

    /// A number in `[0, 1)` hashed from the identity (same on every platform).
    #[inline]
    pub fn unit(&self, seed: u64, salt: u64) -> f64 {
        unit_f64(self.hash(seed, salt))
    }

    /// A rotation angle in `[0, 2 pi)`, hashed from the identity.
    #[inline]
    pub fn rotation(&self, seed: u64) -> f64 {
        self.unit(seed, 0x0107) * std::f64::consts::TAU
    }

    /// A scale factor in `[1 - variation, 1 + variation]`, hashed from the identity.
    #[inline]
    pub fn scale(&self, seed: u64, variation: f64) -> f64 {
        1.0 + variation * (2.0 * self.unit(seed, 0x05ca) - 1.0)
    }
}

/// A point of a query.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// World position.
    pub position: DVec2,
    /// Stable identity.
    pub id: PointId,
    /// The point is present wherever the density at its position exceeds this (points per
    /// unit area): use it to fade points in, or to pick a level of detail. Thresholds of one
    /// base tile's points are `(rank + offset) / area` (see the module docs).
    pub threshold: f64,
    /// Class index (see [`Sampler::query_classes`](super::Sampler::query_classes)); 0 for single-density queries.
    pub class: u16,
}
