//! What the instanced path needs of a class's mesh, checked once per mesh (and again when it
//! changes): its bounds for culling and fading, or the reason it cannot be drawn.

use super::InstancedChunk;
use crate::layers::{ScatterLayer, ScatterLayerStatus};
use crate::look::{ClassLook, GroundPlane, InstancedClassError, check_instanced_mesh};
use bevy::camera::primitives::Aabb;
use bevy::ecs::message::MessageCursor;
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;

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
