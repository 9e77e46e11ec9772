//! A point from its identity alone: the tile it belongs to is found by walking down the
//! subdivision from its base tile, so a stored [`PointId`] is enough to place it again.

use super::{MAX_LEVEL, PointId, Rect, Sampler};
use crate::tiling::base_tile;
use glam::DVec2;

impl Sampler {
    /// Where point `id` lies: bit for bit the position every query that yields it gives.
    /// `None` when this sampler's tiling has no such point (a level past [`MAX_LEVEL`], an
    /// index past the tile's points). Whether a query yields it depends on the density.
    pub fn locate(&self, id: &PointId) -> Option<DVec2> {
        let level = id.level as u32;
        if level > MAX_LEVEL {
            return None;
        }
        let tile = &self.tiles[self.tile_at(level, id.x, id.y) as usize];
        let frac = tile.points.get(id.index as usize)?;
        let side = self.side(level);
        Some(self.placement.world(DVec2::new(
            (id.x as f64 + frac[0]) * side,
            (id.y as f64 + frac[1]) * side,
        )))
    }

    /// The world square of the tile that point `id` belongs to, whatever its index: it
    /// holds the tile's points (on its sides too, where rounding puts one there).
    pub fn tile_rect(&self, id: &PointId) -> Option<Rect> {
        let side = self.side((id.level as u32).min(MAX_LEVEL));
        let min = DVec2::new(id.x as f64, id.y as f64) * side;
        let max = min + DVec2::splat(side);
        (min.is_finite() && max.is_finite()).then(|| self.placement.world_rect(min, max))
    }

    /// Side of the tiles of `level`, divided down as the traversal divides it.
    fn side(&self, level: u32) -> f64 {
        (0..level).fold(self.tile_size, |s, _| s / self.n as f64)
    }

    /// The tile at lattice cell `(x, y)` of `level`: the base tile over it, then the
    /// children that hold it, level by level.
    fn tile_at(&self, level: u32, x: i64, y: i64) -> u16 {
        let shift = (self.n as u32).trailing_zeros();
        let mask = self.n - 1;
        let total = shift * level;
        let mut t = base_tile(
            self.seed,
            self.colors,
            floor_shr(x, total),
            floor_shr(y, total),
        );
        for l in 1..=level {
            let s = shift * (level - l);
            let a = (floor_shr(x, s) & mask) as usize;
            let b = (floor_shr(y, s) & mask) as usize;
            t = self.tiles[t as usize].children[b * self.n as usize + a];
        }
        t
    }
}

/// `v / 2^s` rounded down, for any shift.
fn floor_shr(v: i64, s: u32) -> i64 {
    if s >= 64 { v >> 63 } else { v >> s }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::Constant;
    use crate::tileset::TileSet;

    #[test]
    fn every_point_is_found_where_the_query_put_it() {
        let set = TileSet::embedded();
        // Dense enough for several subdivision levels; negative coordinates included.
        for (seed, size) in [(1, 8.0), (7, 0.37), (99, 1e3)] {
            let sampler = Sampler::new(&set, seed).with_tile_size(size);
            let rect = Rect::new(DVec2::splat(-1.3 * size), DVec2::splat(0.9 * size)).unwrap();
            let density = Constant(40_000.0 / (size * size));
            let mut points = Vec::new();
            sampler.query(rect, &density, &mut points).unwrap();
            assert!(points.iter().any(|p| p.id.level >= 2), "{seed}");
            for p in &points {
                assert_eq!(sampler.locate(&p.id), Some(p.position), "{:?}", p.id);
                assert!(sampler.tile_rect(&p.id).unwrap().contains(p.position));
            }
        }
    }

    #[test]
    fn identities_the_tiling_lacks_are_none() {
        let set = TileSet::embedded();
        let sampler = Sampler::new(&set, 3);
        let id = |level, index| PointId {
            level,
            x: -5,
            y: 2,
            index,
        };
        assert!(sampler.locate(&id(0, 0)).is_some());
        assert_eq!(sampler.locate(&id(0, set.points_per_tile as u16)), None);
        assert_eq!(sampler.locate(&id(MAX_LEVEL as u8 + 1, 0)), None);
        let far = PointId {
            level: MAX_LEVEL as u8,
            x: i64::MIN,
            y: i64::MAX,
            index: 1,
        };
        assert!(sampler.locate(&far).is_some());
    }
}
