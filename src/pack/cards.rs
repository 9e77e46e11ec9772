//! Leaf cards: quads mapped to a whole cut-out texture, lit by normals that face out of
//! the plant (so that a crown of cards shades as one volume), both faces of each drawn.

use crate::foliage::uv_mesh;
use bevy::prelude::*;

/// One card: its centre, its half-size axes (the texture's top along `up`), and the normal
/// its four corners are lit with.
#[derive(Clone, Copy, Debug)]
pub struct Card {
    /// Centre.
    pub centre: Vec3,
    /// From the centre to the texture's top edge, times two.
    pub up: Vec3,
    /// From the centre to the texture's right edge, times two.
    pub right: Vec3,
    /// The lighting normal.
    pub normal: Vec3,
}

/// A deterministic hash of (item, field) to 0..1.
#[derive(Clone, Copy, Debug)]
pub struct Hash(pub u32);

impl Hash {
    /// The number of field `k` of item `i`.
    pub fn get(&self, i: u32, k: u32) -> f32 {
        let mut x = i.wrapping_mul(0x9E37_79B9) ^ k.wrapping_mul(0x85EB_CA6B) ^ self.0;
        x ^= x >> 15;
        x = x.wrapping_mul(0x2C1B_3C6D);
        x ^= x >> 12;
        x = x.wrapping_mul(0x297A_2D39);
        x ^= x >> 15;
        (x >> 8) as f32 / (1u32 << 24) as f32
    }
}

/// The cards as one mesh.
pub fn cards_mesh(cards: &[Card]) -> Mesh {
    let (mut positions, mut normals, mut uvs, mut indices) = (vec![], vec![], vec![], vec![]);
    for card in cards {
        let first = positions.len() as u32;
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            let at = card.centre + card.right * (u - 0.5) + card.up * (0.5 - v);
            positions.push(at.to_array());
            normals.push(card.normal.to_array());
            uvs.push([u, v]);
        }
        // Both faces, each lit by the outward normal: a double-sided material would turn
        // the back's normal round, into the crown, and shade it as if in the dark.
        indices.extend([first, first + 3, first + 2, first, first + 2, first + 1]);
        indices.extend([first, first + 2, first + 3, first, first + 1, first + 2]);
    }
    uv_mesh(positions, normals, uvs, indices)
}
