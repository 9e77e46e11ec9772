//! The far level of detail of instanced classes: each chunk draws its class's far mesh
//! while its bounds lie farther than the class's distance from every camera.

use super::chunk::{InstancedChunk, distance_to_box};
use super::mesh::InstancedMeshes;
use bevy::camera::primitives::Aabb;
use bevy::prelude::*;

/// Gives every chunk of a class with a far mesh the mesh its distance to the nearest
/// active 3-D camera (else the nearest viewer) calls for.
pub(super) fn choose_chunk_meshes(
    // Chunk entities are never parented: their `Transform` is their corner.
    mut chunks: Query<(&mut InstancedChunk, &Transform, &Aabb)>,
    cameras: Query<(&Camera, &GlobalTransform), With<Camera3d>>,
    viewers: Query<&GlobalTransform, With<crate::RwtViewer>>,
    mut checked: ResMut<InstancedMeshes>,
    meshes: Option<Res<Assets<Mesh>>>,
) {
    let mut eyes: Vec<Vec3> = cameras
        .iter()
        .filter(|(c, _)| c.is_active)
        .map(|(_, at)| at.translation())
        .collect();
    if eyes.is_empty() {
        eyes = viewers.iter().map(GlobalTransform::translation).collect();
    }
    if eyes.is_empty() {
        return;
    }
    for (mut chunk, at, aabb) in &mut chunks {
        let Some(far) = chunk.meshes.1.clone() else {
            continue;
        };
        let bounds = Aabb {
            center: aabb.center + at.translation.to_vec3a(),
            half_extents: aabb.half_extents,
        };
        let distance = eyes
            .iter()
            .map(|eye| distance_to_box(&bounds, *eye))
            .fold(f32::INFINITY, f32::min);
        let far_now = chunk.mesh == far.mesh && chunk.mesh != chunk.meshes.0;
        let wanted = if far.is_far(distance, far_now) {
            far.mesh.clone()
        } else {
            chunk.meshes.0.clone()
        };
        if chunk.mesh != wanted {
            let top = checked.bounds(&wanted, meshes.as_deref()).1.y;
            chunk.mesh_top = top.max(1e-3);
            chunk.mesh = wanted;
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::look::InstancedFar;

    #[test]
    fn a_chunk_turns_far_past_the_distance_and_near_again_within_it() {
        let far = InstancedFar {
            mesh: Default::default(),
            distance: 100.0,
        };
        assert!(!far.is_far(100.0, false));
        assert!(!far.is_far(104.0, false));
        assert!(far.is_far(106.0, false));
        // Once far, it stays so down to the distance over the hysteresis.
        assert!(far.is_far(96.0, true));
        assert!(!far.is_far(95.0, true));
    }
}
