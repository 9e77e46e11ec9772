//! Direct stochastic tiling (after Lagae and Dutré 2005) with a complete tile set.
//!
//! Every edge of the base lattice gets a colour from a hash of its position: horizontal
//! edges (the south edge of cell `(i, j)`) and vertical edges (the west edge of cell
//! `(i, j)`) are hashed apart. A cell's tile is the one whose four colours are those of its
//! four edges, so adjacent tiles always match and any tile is found in O(1) without
//! building its surroundings. Deeper levels follow the subdivision rules from the base tile.

use crate::rng::hash_words;
use crate::tileset::TileSet;

/// A tiling of the plane by a tile set, fixed by a seed.
#[derive(Clone, Copy, Debug)]
pub struct Tiling<'a> {
    set: &'a TileSet,
    seed: u64,
    shift: u32,
}

impl<'a> Tiling<'a> {
    /// The tiling of `set` for `seed`.
    pub fn new(set: &'a TileSet, seed: u64) -> Self {
        Self {
            set,
            seed,
            shift: set.subdivision.trailing_zeros(),
        }
    }

    /// The tile set.
    pub fn set(&self) -> &'a TileSet {
        self.set
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The base (level 0) tile at lattice cell `(i, j)`.
    #[inline]
    pub fn base_tile(&self, i: i64, j: i64) -> u16 {
        base_tile(self.seed, self.set.colors, i, j)
    }

    /// The tile at cell `(i, j)` of level `level` (cells of side `n^-level` base tiles).
    /// Walks down from the base tile: O(level).
    pub fn tile_at(&self, level: u32, i: i64, j: i64) -> u16 {
        let n_mask = (self.set.subdivision as i64) - 1;
        let total = self.shift * level;
        let mut t = self.base_tile(shr(i, total), shr(j, total));
        for l in 1..=level {
            let s = self.shift * (level - l);
            let a = (shr(i, s) & n_mask) as usize;
            let b = (shr(j, s) & n_mask) as usize;
            t = self.set.tiles[t as usize].children[b * self.set.subdivision as usize + a];
        }
        t
    }
}

#[inline]
fn edge_color(seed: u64, colors: u8, i: i64, j: i64, vertical: u64) -> u8 {
    let h = hash_words(seed, &[i as u64, j as u64, vertical]);
    (((h >> 32) * colors as u64) >> 32) as u8
}

/// The base tile of a complete set of `colors` colours at lattice cell `(i, j)` for `seed`:
/// the tile whose four edge colours are the hashes of its four edges.
#[inline]
pub fn base_tile(seed: u64, colors: u8, i: i64, j: i64) -> u16 {
    let k = colors as usize;
    let north = edge_color(seed, colors, i, j.wrapping_add(1), 0) as usize;
    let east = edge_color(seed, colors, i.wrapping_add(1), j, 1) as usize;
    let south = edge_color(seed, colors, i, j, 0) as usize;
    let west = edge_color(seed, colors, i, j, 1) as usize;
    (((north * k + east) * k + south) * k + west) as u16
}

/// Floor division by `2^s` for any `s` (arithmetic shift saturating at 63).
#[inline]
fn shr(v: i64, s: u32) -> i64 {
    v >> s.min(63)
}
