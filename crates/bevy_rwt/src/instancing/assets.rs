//! Asset classes' side of the instanced path: each [`AssetLook`] of a layer is resolved once
//! its file has loaded with everything it names, again when the file changes (hot reload),
//! and its chunks drawn again then ([`ResolvedAssets::generation`]); its impostor is baked
//! from its last level once resolved, and again when the file changes.

use crate::impostor::ImpostorAtlases;
use crate::layers::ScatterLayer;
use crate::look::ClassLook;
use crate::look::asset::{
    AssetLook, AssetLookError, AssetRoot, GltfAssets, MsftLodTable, ResolvedAsset,
};
use bevy::asset::LoadState;
use bevy::ecs::message::MessageCursor;
use bevy::gltf::{Gltf, GltfMaterial, GltfMesh, GltfNode};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use std::sync::Arc;

/// A look resolved, or why it cannot be drawn.
type Resolved = Result<Arc<ResolvedAsset>, AssetLookError>;

/// Every asset look of the layers, resolved (or why it cannot be drawn), by file and root.
#[derive(Resource, Default)]
pub struct ResolvedAssets {
    looks: HashMap<AssetId<Gltf>, HashMap<AssetRoot, Resolved>>,
    generation: u64,
}

impl ResolvedAssets {
    /// `look` resolved: `None` while its file loads.
    pub fn get(&self, look: &AssetLook) -> Option<&Resolved> {
        self.looks.get(&look.gltf.id())?.get(&look.root)
    }

    /// `look` ready to draw, if it is.
    pub fn ready(&self, look: &AssetLook) -> Option<&Arc<ResolvedAsset>> {
        self.get(look)?.as_ref().ok()
    }

    /// Counts the changes: chunks drawn before a change are drawn again after it.
    pub fn generation(&self) -> u64 {
        self.generation
    }
}

/// What resolving reads and writes.
#[derive(bevy::ecs::system::SystemParam)]
pub(super) struct AssetSources<'w> {
    server: Res<'w, AssetServer>,
    files: Res<'w, Assets<Gltf>>,
    nodes: Res<'w, Assets<GltfNode>>,
    gltf_meshes: Res<'w, Assets<GltfMesh>>,
    materials: Res<'w, Assets<GltfMaterial>>,
    lods: Option<Res<'w, MsftLodTable>>,
    meshes: ResMut<'w, Assets<Mesh>>,
}

impl AssetSources<'_> {
    /// `look` resolved, or `None` while its file (or something it names) is loading.
    fn resolve(&mut self, look: &AssetLook) -> Option<Resolved> {
        let id = look.gltf.id();
        if let Some(LoadState::Failed(e)) = self.server.get_load_state(id) {
            return Some(Err(AssetLookError::Load(e.to_string())));
        }
        let loaded = self.server.is_loaded_with_dependencies(id);
        let gltf = self.files.get(id).filter(|_| loaded)?;
        // What the loader's handler read of the file (nothing: a file added in code).
        let path = self.server.get_path(id);
        let lods = path.zip(self.lods.as_ref()).and_then(|(p, t)| t.get(&p));
        let from = GltfAssets {
            nodes: &self.nodes,
            meshes: &self.gltf_meshes,
            materials: &self.materials,
            lods: lods.as_deref(),
        };
        let resolved = crate::look::asset::resolve_asset(gltf, &look.root, from, &mut self.meshes);
        if let Err(e) = &resolved {
            error!("asset class {:?} cannot be drawn: {e}", look.gltf.path());
        }
        Some(resolved.map(Arc::new))
    }
}

/// Resolves the layers' asset looks that are not yet, and again those whose file changed.
pub(super) fn resolve_asset_looks(
    layers: Query<&ScatterLayer>,
    events: Option<Res<Messages<AssetEvent<Gltf>>>>,
    mut cursor: Local<MessageCursor<AssetEvent<Gltf>>>,
    sources: Option<AssetSources>,
    mut resolved: ResMut<ResolvedAssets>,
    mut atlases: Option<ResMut<ImpostorAtlases>>,
) {
    let Some(mut sources) = sources else { return };
    if let Some(events) = events {
        for event in cursor.read(&events) {
            if let AssetEvent::Modified { id } | AssetEvent::Removed { id } = event
                && resolved.looks.remove(id).is_some()
            {
                resolved.generation += 1;
                if let Some(atlases) = atlases.as_mut() {
                    atlases.forget_file(*id);
                }
            }
        }
    }
    let looks = layers
        .iter()
        .flat_map(|l| &l.classes)
        .filter_map(|c| match &c.look {
            ClassLook::Asset(look) => Some(look),
            _ => None,
        });
    for look in looks {
        if resolved.get(look).is_some() {
            continue;
        }
        if let Some(result) = sources.resolve(look) {
            let file = resolved.looks.entry(look.gltf.id()).or_default();
            file.insert(look.root.clone(), result);
            resolved.generation += 1;
        }
    }
}

/// Starts baking the impostors of asset classes that have one, once their look is resolved.
pub(super) fn bake_asset_impostors(
    layers: Query<&ScatterLayer>,
    resolved: Res<ResolvedAssets>,
    atlases: Option<ResMut<ImpostorAtlases>>,
    meshes: Option<Res<Assets<Mesh>>>,
    images: Option<Res<Assets<Image>>>,
) {
    let (Some(mut atlases), Some(meshes), Some(images)) = (atlases, meshes, images) else {
        return;
    };
    for class in layers.iter().flat_map(|l| &l.classes) {
        let (ClassLook::Asset(look), Some(impostor)) = (&class.look, &class.impostor) else {
            continue;
        };
        if let Some(asset) = resolved.ready(look) {
            atlases.bake_asset((look, asset), impostor, &meshes, &images);
        }
    }
}
