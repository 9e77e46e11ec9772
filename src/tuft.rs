//! Tufts: K blades merged into one mesh, drawn once per instance at a K-th of the density,
//! so that a field draws as many blades with a K-th of the instances (`gpu_bench --tuft K`).
//!
//! A GPU may shade a small instanced mesh's vertices in groups that do not span instances:
//! then a 10-vertex blade fills a third of a 32-lane group, and each instance costs the
//! front end a batch of its own. Whether that is what bounds the grass's frame (rather than its
//! vertices' work or its pixels) is what the same case with and without `--tuft` tells.
//! The blades of a tuft stand within [`RADIUS`] of its root, each turned its own way; they
//! sway, grow and thin together, as one instance.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology, VertexAttributeValues};
use bevy::prelude::*;

/// Radius around a tuft's root within which its blades stand, metres.
pub const RADIUS: f32 = 0.3;

/// `blade` (positions, normals and `u32` indices) `count` times, each copy turned and moved
/// within [`RADIUS`] of the root by a fixed sequence: the same for every mesh, so that a
/// near blade's tuft and a far blade's stand alike.
///
/// # Panics
///
/// If `blade` lacks three-float positions or normals, or `u32` indices (as
/// [`blade_mesh`](bevy_rwt::look::blade_mesh) makes them).
pub fn tuft(blade: &Mesh, count: u32) -> Mesh {
    let positions = float3(blade, Mesh::ATTRIBUTE_POSITION);
    let normals = float3(blade, Mesh::ATTRIBUTE_NORMAL);
    let Some(Indices::U32(indices)) = blade.indices() else {
        panic!("a blade mesh has u32 indices");
    };
    let mut out_positions = Vec::new();
    let mut out_normals = Vec::new();
    let mut out_indices = Vec::new();
    for i in 0..count {
        let place = Place::nth(i, count);
        let base = out_positions.len() as u32;
        out_positions.extend(positions.iter().map(|p| place.point(*p).to_array()));
        out_normals.extend(normals.iter().map(|n| place.turn(*n).to_array()));
        out_indices.extend(indices.iter().map(|k| base + k));
    }
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, out_positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, out_normals)
    .with_inserted_indices(Indices::U32(out_indices))
}

/// `mesh`'s three-float attribute `attribute`.
fn float3(mesh: &Mesh, attribute: bevy::mesh::MeshVertexAttribute) -> Vec<Vec3> {
    match mesh.attribute(attribute) {
        Some(VertexAttributeValues::Float32x3(values)) => {
            values.iter().map(|v| Vec3::from_array(*v)).collect()
        }
        _ => panic!("a blade mesh has {} as three floats", attribute.name),
    }
}

/// Where one blade of a tuft stands: its turn about the vertical and its root.
struct Place {
    turn: Quat,
    root: Vec3,
}

impl Place {
    /// The `i`-th of `count` blades: the first at the root, the others on a golden-angle
    /// spiral (evenly spread over the disc), each turned by the golden angle once more.
    fn nth(i: u32, count: u32) -> Self {
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let angle = golden * i as f32;
        let r = RADIUS * (i as f32 / count.max(1) as f32).sqrt();
        Self {
            turn: Quat::from_rotation_y(angle * 2.0),
            root: Vec3::new(r * angle.cos(), 0.0, r * angle.sin()),
        }
    }

    fn point(&self, p: Vec3) -> Vec3 {
        self.root + self.turn * p
    }

    fn turn(&self, n: Vec3) -> Vec3 {
        self.turn * n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grass_field;

    #[test]
    fn a_tuft_holds_count_blades_within_its_radius() {
        let blade = grass_field::blade();
        let tuft = tuft(&blade, 8);
        assert_eq!(tuft.count_vertices(), 8 * blade.count_vertices());
        assert_eq!(
            tuft.indices().unwrap().len(),
            8 * blade.indices().unwrap().len()
        );
        let reach = RADIUS + 0.2;
        for p in float3(&tuft, Mesh::ATTRIBUTE_POSITION) {
            assert!(p.xz().length() <= reach, "{p} is outside the tuft");
        }
        // Blades stand apart: no two copies share a root.
        let roots: Vec<Vec3> = (0..8).map(|i| Place::nth(i, 8).root).collect();
        for (a, p) in roots.iter().enumerate() {
            for q in &roots[a + 1..] {
                assert!(p.distance(*q) > 0.05);
            }
        }
    }
}
