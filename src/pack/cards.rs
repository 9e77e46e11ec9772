//! Leaf cards: quads mapped to a whole cut-out texture, lit by normals that face out of
//! the plant (so that a crown of cards shades as one volume), and the mesh helpers the
//! pack shares.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
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

/// A triangle list of these attributes.
pub fn mesh(
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
) -> Mesh {
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, uvs)
    .with_inserted_indices(Indices::U32(indices))
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
        indices.extend([first, first + 3, first + 2, first, first + 2, first + 1]);
    }
    mesh(positions, normals, uvs, indices)
}
