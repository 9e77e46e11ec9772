//! Wang tile edge colours for a *complete* tile set.
//!
//! We build the complete set of `K^4` tiles (one tile for every combination of north, east,
//! south and west colour) rather than the paper's compact `2K^2` set. Reasons:
//! - the direct stochastic tiling becomes a pure edge hash: every edge of the lattice gets a
//!   colour from a hash of its position, and the tile with those four colours always exists,
//!   so any tile anywhere is found in O(1) with no constraint solving;
//! - subdivision interiors are always solvable (any interior edge colouring names existing
//!   tiles), so every level of the recursion matches, provably;
//! - with `K = 2` the set has 16 tiles, twice the variety of the paper's 8-tile set.
//!
//! Horizontal edges (north/south) and vertical edges (east/west) use separate colour
//! alphabets and separate source tiles, so a horizontal colour never has to agree with a
//! vertical one.

use serde::{Deserialize, Serialize};

/// The four sides of a tile, in the order the construction merges them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Side {
    /// `y = 1`.
    North,
    /// `x = 1`.
    East,
    /// `y = 0`.
    South,
    /// `x = 0`.
    West,
}

impl Side {
    /// All sides in merge order.
    pub const ALL: [Side; 4] = [Side::North, Side::East, Side::South, Side::West];

    /// Whether the side is a horizontal edge (north or south).
    pub fn is_horizontal(self) -> bool {
        matches!(self, Side::North | Side::South)
    }
}

/// Edge colours of one tile.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct EdgeColors {
    /// Colour of the north edge (horizontal alphabet).
    pub north: u8,
    /// Colour of the east edge (vertical alphabet).
    pub east: u8,
    /// Colour of the south edge (horizontal alphabet).
    pub south: u8,
    /// Colour of the west edge (vertical alphabet).
    pub west: u8,
}

impl EdgeColors {
    /// Colour of one side.
    pub fn side(&self, side: Side) -> u8 {
        match side {
            Side::North => self.north,
            Side::East => self.east,
            Side::South => self.south,
            Side::West => self.west,
        }
    }

    /// Index of the tile with these colours in a complete set of `k` colours.
    pub fn complete_index(&self, k: u8) -> usize {
        let k = k as usize;
        ((self.north as usize * k + self.east as usize) * k + self.south as usize) * k
            + self.west as usize
    }

    /// Inverse of [`EdgeColors::complete_index`].
    pub fn from_complete_index(index: usize, k: u8) -> Self {
        let k = k as usize;
        Self {
            west: (index % k) as u8,
            south: (index / k % k) as u8,
            east: (index / (k * k) % k) as u8,
            north: (index / (k * k * k) % k) as u8,
        }
    }
}

/// Number of tiles in a complete set of `k` colours.
pub fn complete_set_size(k: u8) -> usize {
    (k as usize).pow(4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn complete_index_round_trips() {
        for k in 1..=4u8 {
            for i in 0..complete_set_size(k) {
                assert_eq!(EdgeColors::from_complete_index(i, k).complete_index(k), i);
            }
        }
    }
}
