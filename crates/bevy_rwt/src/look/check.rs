//! What the instanced path requires of a class's mesh.

use super::GroundPlane;
use bevy::camera::primitives::MeshAabb;
use bevy::mesh::{MeshAccessError, PrimitiveTopology};
use bevy::prelude::*;

/// Why an instanced class cannot be drawn. Its chunks still stream and are counted; the
/// renderer skips them until the mesh is fixed (a reloaded or edited mesh is checked again).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum InstancedClassError {
    /// The mesh has no `Mesh::ATTRIBUTE_POSITION`.
    #[error("the mesh has no vertex positions")]
    MissingPositions,
    /// The mesh has positions but no vertex.
    #[error("the mesh has no vertices")]
    Empty,
    /// Points and lines cannot be shaded as surfaces.
    #[error("the mesh's topology is {0:?}; instanced classes draw triangle lists or strips")]
    Topology(PrimitiveTopology),
    /// An attribute does not have one value per vertex.
    #[error("the mesh's {attribute} has {len} values for {vertices} vertices")]
    AttributeLength {
        /// The attribute's name.
        attribute: String,
        /// Its values.
        len: usize,
        /// The positions.
        vertices: usize,
    },
    /// The layer lies on a plane the instanced path does not draw.
    #[error("instanced classes are drawn on GroundPlane::Xz only, not {0:?}")]
    Plane(GroundPlane),
}

/// Bounds of a mesh that the instanced path can draw (min, max), or why it cannot; `None`
/// while the mesh's data is not in the main world.
pub fn check_instanced_mesh(mesh: &Mesh) -> Option<Result<(Vec3, Vec3), InstancedClassError>> {
    if let Err(e) = check_topology(mesh.primitive_topology()) {
        return Some(Err(e));
    }
    let positions = match mesh.try_attribute(Mesh::ATTRIBUTE_POSITION) {
        Ok(p) => p.len(),
        Err(MeshAccessError::NotFound) => return Some(Err(InstancedClassError::MissingPositions)),
        // Render-world-only meshes keep only their bounds in the main world.
        Err(MeshAccessError::ExtractedToRenderWorld) => {
            return mesh
                .compute_aabb()
                .map(|a| Ok((a.min().into(), a.max().into())));
        }
    };
    if positions == 0 {
        return Some(Err(InstancedClassError::Empty));
    }
    for (attribute, values) in mesh.try_attributes().ok()? {
        if values.len() != positions {
            return Some(Err(InstancedClassError::AttributeLength {
                attribute: attribute.name.to_string(),
                len: values.len(),
                vertices: positions,
            }));
        }
    }
    let aabb = mesh.compute_aabb()?;
    Some(Ok((aabb.min().into(), aabb.max().into())))
}

/// Whether the instanced path draws meshes of this topology.
pub(crate) fn check_topology(topology: PrimitiveTopology) -> Result<(), InstancedClassError> {
    match topology {
        PrimitiveTopology::TriangleList | PrimitiveTopology::TriangleStrip => Ok(()),
        other => Err(InstancedClassError::Topology(other)),
    }
}
