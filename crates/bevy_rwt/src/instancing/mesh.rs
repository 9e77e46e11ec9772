//! What the instanced path needs of a class's mesh, checked once per mesh (and again when it
//! changes): its bounds for culling and fading, or the reason it cannot be drawn.

use super::InstancedChunk;
use crate::layers::{ClassLook, GroundPlane, ScatterLayer, ScatterLayerStatus};
use bevy::camera::primitives::{Aabb, MeshAabb};
use bevy::ecs::message::MessageCursor;
use bevy::mesh::{MeshAccessError, PrimitiveTopology};
use bevy::platform::collections::{HashMap, HashSet};
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

/// The checks of every instanced class's mesh, made when the mesh loads and dropped when it
/// changes; a failed check is logged once.
#[derive(Resource, Default)]
pub struct InstancedMeshes(HashMap<AssetId<Mesh>, Result<(Vec3, Vec3), InstancedClassError>>);

impl InstancedMeshes {
    /// The check of `mesh`, made now if it is loaded and was not checked yet.
    pub fn check(
        &mut self,
        mesh: &Handle<Mesh>,
        meshes: Option<&Assets<Mesh>>,
    ) -> Option<&Result<(Vec3, Vec3), InstancedClassError>> {
        let id = mesh.id();
        if !self.0.contains_key(&id) {
            let checked = check_instanced_mesh(meshes?.get(id)?)?;
            if let Err(e) = &checked {
                error!("instanced class mesh {mesh:?} cannot be drawn: {e}");
            }
            self.0.insert(id, checked);
        }
        self.0.get(&id)
    }

    /// Bounds of `mesh` (a unit box standing on the ground while it is not loaded or cannot
    /// be drawn).
    pub fn bounds(&mut self, mesh: &Handle<Mesh>, meshes: Option<&Assets<Mesh>>) -> (Vec3, Vec3) {
        match self.check(mesh, meshes) {
            Some(Ok(bounds)) => *bounds,
            _ => (Vec3::new(-1.0, 0.0, -1.0), Vec3::ONE),
        }
    }
}

/// Drops the checks of meshes that changed or went away, and fits the bounds of the chunks
/// drawing a mesh that loaded or changed (chunks handed over before their mesh loaded were
/// given a unit box). Apps without meshes have no mesh events.
pub(super) fn refit_changed_meshes(
    events: Option<Res<Messages<AssetEvent<Mesh>>>>,
    mut cursor: Local<MessageCursor<AssetEvent<Mesh>>>,
    mut checked: ResMut<InstancedMeshes>,
    meshes: Option<Res<Assets<Mesh>>>,
    mut chunks: Query<(&mut InstancedChunk, &mut Aabb)>,
) {
    let Some(events) = events else {
        return;
    };
    let mut changed = HashSet::new();
    for event in cursor.read(&events) {
        match event {
            AssetEvent::Modified { id }
            | AssetEvent::Removed { id }
            | AssetEvent::Unused { id } => {
                checked.0.remove(id);
                changed.insert(*id);
            }
            AssetEvent::Added { id } | AssetEvent::LoadedWithDependencies { id } => {
                changed.insert(*id);
            }
        }
    }
    if changed.is_empty() {
        return;
    }
    for (mut chunk, mut aabb) in &mut chunks {
        if changed.contains(&chunk.mesh.id()) {
            let bounds = checked.bounds(&chunk.mesh, meshes.as_deref());
            chunk.mesh_top = bounds.1.y.max(1e-3);
            *aabb = chunk.aabb(bounds);
        }
    }
}

/// Puts each layer's instanced-class errors in its [`ScatterLayerStatus`].
pub(super) fn report_class_errors(
    mut layers: Query<(&ScatterLayer, &mut ScatterLayerStatus)>,
    mut checked: ResMut<InstancedMeshes>,
    meshes: Option<Res<Assets<Mesh>>>,
) {
    for (layer, mut status) in &mut layers {
        let errors: Vec<(u16, InstancedClassError)> = layer
            .classes
            .iter()
            .enumerate()
            .filter_map(|(i, class)| {
                let ClassLook::Instanced(look) = &class.look else {
                    return None;
                };
                if layer.plane != GroundPlane::Xz {
                    return Some((i as u16, InstancedClassError::Plane(layer.plane)));
                }
                match checked.check(&look.mesh, meshes.as_deref()) {
                    Some(Err(e)) => Some((i as u16, e.clone())),
                    _ => None,
                }
            })
            .collect();
        if status.class_errors != errors {
            status.class_errors = errors;
        }
    }
}
