//! What the instanced path needs of a class's mesh, checked once per mesh (and again when it
//! changes): its bounds for culling and fading, or the reason it cannot be drawn.

use super::chunk::InstancedChunk;
use crate::layers::{ScatterLayer, ScatterLayerStatus};
use crate::look::{
    ClassLook, GroundPlane, InstancedClassError, InstancedFar, InstancedLook, check_instanced_mesh,
    check_texture,
};
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

    /// Bounds holding a class's near and far meshes (a chunk's `Aabb` holds either).
    pub fn class_bounds(
        &mut self,
        (near, far): &(Handle<Mesh>, Option<InstancedFar>),
        meshes: Option<&Assets<Mesh>>,
    ) -> (Vec3, Vec3) {
        let (lo, hi) = self.bounds(near, meshes);
        match far {
            Some(far) => {
                let (far_lo, far_hi) = self.bounds(&far.mesh, meshes);
                (lo.min(far_lo), hi.max(far_hi))
            }
            None => (lo, hi),
        }
    }

    /// Whether a class has a far mesh as tall as its near one (within a thousandth), both
    /// checked: then a chunk may draw either under the same uniform.
    pub fn far_as_tall(
        &mut self,
        (near, far): &(Handle<Mesh>, Option<InstancedFar>),
        meshes: Option<&Assets<Mesh>>,
    ) -> bool {
        let Some(far) = far else {
            return false;
        };
        let mut top = |mesh| match self.check(mesh, meshes) {
            Some(Ok((_, hi))) => Some(hi.y),
            _ => None,
        };
        let (Some(near), Some(far)) = (top(near), top(&far.mesh)) else {
            return false;
        };
        (near - far).abs() <= 1e-3 * near.abs().max(1e-3)
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
    // An asset's parts are bounded by the whole asset: redrawn when it is resolved again.
    for (mut chunk, mut aabb) in chunks.iter_mut().filter(|(c, _)| c.surface.is_none()) {
        let (near, far) = &chunk.meshes;
        let drawn = far.as_ref().map(|f| &f.mesh).into_iter().chain([near]);
        if drawn.into_iter().any(|m| changed.contains(&m.id())) {
            let top = checked.bounds(&chunk.mesh, meshes.as_deref()).1.y;
            chunk.mesh_top = top.max(1e-3);
            let bounds = checked.class_bounds(&chunk.meshes, meshes.as_deref());
            *aabb = chunk.aabb(bounds);
            chunk.far_per_instance = checked.far_as_tall(&chunk.meshes, meshes.as_deref());
        }
    }
}

/// The assets a class check reads (absent in apps without them).
#[derive(bevy::ecs::system::SystemParam)]
pub(super) struct ClassAssets<'w> {
    meshes: Option<Res<'w, Assets<Mesh>>>,
    images: Option<Res<'w, Assets<Image>>>,
    server: Option<Res<'w, AssetServer>>,
    #[cfg(feature = "gltf")]
    assets: Option<Res<'w, super::ResolvedAssets>>,
}

impl ClassAssets<'_> {
    /// Why `look`'s texture cannot be drawn with its mesh, if it cannot.
    fn texture_error(&self, look: &InstancedLook) -> Option<InstancedClassError> {
        let texture = look.material.texture.as_ref()?;
        let mesh = self.meshes.as_deref().and_then(|m| m.get(&look.mesh));
        // Render-world-only meshes keep no attributes here; the renderer skips them instead.
        if let Some(mesh) = mesh.filter(|m| m.try_attributes().is_ok())
            && !mesh.contains_attribute(Mesh::ATTRIBUTE_UV_0)
        {
            return Some(InstancedClassError::MissingUvs);
        }
        if let Some(image) = self.images.as_deref().and_then(|i| i.get(texture)) {
            let d = &image.texture_descriptor;
            return check_texture(d.dimension, d.size.depth_or_array_layers, d.format).err();
        }
        let failed = self
            .server
            .as_deref()
            .and_then(|s| s.get_load_state(texture))
            .is_some_and(|state| state.is_failed());
        failed.then_some(InstancedClassError::TextureNotLoaded)
    }
}

/// Puts each layer's instanced-class errors in its [`ScatterLayerStatus`].
pub(super) fn report_class_errors(
    mut layers: Query<(&ScatterLayer, &mut ScatterLayerStatus)>,
    mut checked: ResMut<InstancedMeshes>,
    assets: ClassAssets,
) {
    for (layer, mut status) in &mut layers {
        let errors: Vec<(u16, InstancedClassError)> = layer
            .classes
            .iter()
            .enumerate()
            .filter_map(|(i, class)| {
                let look = match &class.look {
                    ClassLook::Instanced(look) => look,
                    #[cfg(feature = "gltf")]
                    ClassLook::Asset(look) if layer.plane == GroundPlane::Xz => {
                        let resolved = assets.assets.as_deref()?.get(look)?;
                        let e = resolved.as_ref().err()?.clone();
                        return Some((i as u16, InstancedClassError::Asset(Box::new(e))));
                    }
                    #[cfg(feature = "gltf")]
                    ClassLook::Asset(_) => {
                        return Some((i as u16, InstancedClassError::Plane(layer.plane)));
                    }
                    _ => return None,
                };
                if layer.plane != GroundPlane::Xz {
                    return Some((i as u16, InstancedClassError::Plane(layer.plane)));
                }
                let far = look.far.as_ref().map(|f| &f.mesh);
                for mesh in std::iter::once(&look.mesh).chain(far) {
                    if let Some(Err(e)) = checked.check(mesh, assets.meshes.as_deref()) {
                        return Some((i as u16, e.clone()));
                    }
                }
                assets.texture_error(look).map(|e| (i as u16, e))
            })
            .collect();
        if status.class_errors != errors {
            status.class_errors = errors;
        }
    }
}
