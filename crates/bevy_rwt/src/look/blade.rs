//! A grass blade mesh for instanced classes: a tapered strip that curves forward.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;

/// Rows of vertices along [`blade_mesh`]'s blade, root to tip.
const ROWS: usize = 5;

/// A grass blade standing on its root at the origin: `width` at the root, tapering to a tip
/// `height` above it, curving `bend` forward (+z) at the tip. Seen from both sides (the
/// instanced pipeline does not cull back faces); normals lean up a little so that a meadow
/// catches the sun like grass rather than like a field of cards.
pub fn blade_mesh(width: f32, height: f32, bend: f32) -> Mesh {
    blade_mesh_with_rows(width, height, bend, ROWS)
}

/// [`blade_mesh`]'s blade for far chunks ([`InstancedFar`](crate::look::InstancedFar)): the
/// same bounds with three rows of vertices instead of five (6 vertices instead of 10), so
/// that nothing pops at the switch but the curve's few pixels.
pub fn far_blade_mesh(width: f32, height: f32, bend: f32) -> Mesh {
    blade_mesh_with_rows(width, height, bend, FAR_ROWS)
}

/// Rows of vertices along [`far_blade_mesh`]'s blade.
const FAR_ROWS: usize = 3;

/// [`blade_mesh`]'s blade with `rows` rows of two vertices (2 to 64), root to tip: fewer
/// for a far level of detail ([`InstancedFar`](crate::look::InstancedFar)), where the
/// curve's few pixels do not need five.
pub fn blade_mesh_with_rows(width: f32, height: f32, bend: f32, rows: usize) -> Mesh {
    let rows = rows.clamp(2, 64);
    let mut positions = Vec::with_capacity(2 * rows);
    let mut normals = Vec::with_capacity(2 * rows);
    for row in 0..rows {
        let t = row as f32 / (rows - 1) as f32;
        // Full width to about halfway, then a pointed tip.
        let half = 0.5 * width * (1.0 - t.powf(2.5));
        let forward = bend * t * t;
        // Normal of the curve y = t h, z = bend t^2 in the y-z plane, facing +z.
        let slope = 2.0 * bend * t / height.max(1e-6);
        let normal = Vec3::new(0.0, -slope, 1.0).normalize() + Vec3::new(0.0, 0.35, 0.0);
        for side in [-1.0f32, 1.0] {
            positions.push([side * half, t * height, forward]);
            normals.push(normal.normalize().to_array());
        }
    }
    let mut indices = Vec::with_capacity(6 * (rows - 1));
    for r in 0..rows as u32 - 1 {
        let (a, b, c, d) = (2 * r, 2 * r + 1, 2 * r + 2, 2 * r + 3);
        indices.extend([a, b, d, a, d, c]);
    }
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, normals)
    .with_inserted_indices(Indices::U32(indices))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::look::check_instanced_mesh;

    #[test]
    fn a_blade_stands_on_its_root_and_can_be_drawn() {
        let blade = blade_mesh(0.1, 0.7, 0.12);
        let (lo, hi) = check_instanced_mesh(&blade).unwrap().unwrap();
        assert!((lo.y - 0.0).abs() < 1e-6 && (hi.y - 0.7).abs() < 1e-6);
        assert!((hi.x - 0.05).abs() < 1e-6 && (lo.x + 0.05).abs() < 1e-6);
        assert!((hi.z - 0.12).abs() < 1e-6 && lo.z.abs() < 1e-6);
        let Some(bevy::mesh::VertexAttributeValues::Float32x3(n)) =
            blade.attribute(Mesh::ATTRIBUTE_NORMAL)
        else {
            panic!("normals");
        };
        assert!(n.iter().all(|n| n[2] > 0.5 && n[1] > 0.0), "{n:?}");
    }

    #[test]
    fn a_far_blade_has_the_same_bounds_with_fewer_vertices() {
        let near = blade_mesh(0.1, 0.7, 0.12);
        let far = far_blade_mesh(0.1, 0.7, 0.12);
        let bounds = |m: &Mesh| check_instanced_mesh(m).unwrap().unwrap();
        assert_eq!(bounds(&near), bounds(&far));
        assert_eq!((near.count_vertices(), far.count_vertices()), (10, 6));
        // Fewer than two rows would be no strip at all; more than 64 nothing a blade needs.
        assert_eq!(blade_mesh_with_rows(0.1, 0.7, 0.12, 0).count_vertices(), 4);
        let most = blade_mesh_with_rows(0.1, 0.7, 0.12, usize::MAX);
        assert_eq!(most.count_vertices(), 128);
    }
}
