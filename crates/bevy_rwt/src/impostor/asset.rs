//! Impostors of asset classes: the primitives of an asset's last level of detail baked
//! together, each with its own material, into one atlas.

use super::{
    ImpostorAtlas, ImpostorAtlases, ImpostorKey, LookKey, OwnedPart, OwnedSource, bake::BakeColor,
    loaded_texture,
};
use crate::look::Impostor;
use crate::look::asset::{AssetLook, AssetPart, ResolvedAsset, SurfaceAlpha};
use bevy::gltf::Gltf;
use bevy::prelude::*;
use std::hash::{Hash, Hasher};

impl ImpostorAtlases {
    /// The impostor atlas of an asset class drawn from `asset`, once baked.
    pub fn of_asset(
        &self,
        look: &AssetLook,
        asset: &ResolvedAsset,
        impostor: &Impostor,
    ) -> Option<&ImpostorAtlas> {
        self.ready(&asset_key(look, asset, impostor)?)
    }

    /// Starts baking the impostor of an asset class drawn from `asset`, unless it is baked
    /// or baking, once its meshes and textures are loaded.
    pub(crate) fn bake_asset(
        &mut self,
        (look, asset): (&AssetLook, &ResolvedAsset),
        impostor: &Impostor,
        meshes: &Assets<Mesh>,
        images: &Assets<Image>,
    ) {
        let Some(key) = asset_key(look, asset, impostor) else {
            return;
        };
        if self.atlases.contains_key(&key) {
            return;
        }
        let Some(last) = asset.levels.last() else {
            return;
        };
        let Some(source) = source_of(last, meshes, images) else {
            return;
        };
        self.start(key, source, *impostor);
    }

    /// Forgets the atlases of the assets of a file (it changed: they are baked again).
    pub(crate) fn forget_file(&mut self, gltf: AssetId<Gltf>) {
        self.atlases
            .retain(|key, _| !matches!(key.look, LookKey::Asset { gltf: g, .. } if g == gltf));
    }
}

/// What an asset's atlas is baked from: its file, its root, its last level's first mesh.
fn asset_key(look: &AssetLook, asset: &ResolvedAsset, impostor: &Impostor) -> Option<ImpostorKey> {
    let first = asset.levels.last()?.first()?;
    let mut root = std::hash::DefaultHasher::new();
    look.root.hash(&mut root);
    Some(ImpostorKey {
        mesh: first.mesh.id(),
        look: LookKey::Asset {
            gltf: look.gltf.id(),
            root: root.finish(),
        },
        views: impostor.clamped(),
    })
}

/// The bake's source for an asset's level: each primitive with its surface's base colour,
/// texture and cut-out, lit with the first one's roughness.
fn source_of(
    level: &[AssetPart],
    meshes: &Assets<Mesh>,
    images: &Assets<Image>,
) -> Option<OwnedSource> {
    let parts = level
        .iter()
        .map(|part| {
            let surface = &part.surface;
            Some(OwnedPart {
                mesh: meshes.get(&part.mesh)?.clone(),
                color: BakeColor::Plain(surface.base_color.to_linear()),
                vertex_colors: true,
                lean: 0.0,
                texture: loaded_texture(surface.base_color_texture.as_ref(), images)?,
                alpha_cutoff: match surface.alpha {
                    SurfaceAlpha::Opaque => None,
                    SurfaceAlpha::Mask(cutoff) => Some(cutoff),
                },
            })
        })
        .collect::<Option<Vec<_>>>()?;
    let roughness = level.first()?.surface.perceptual_roughness;
    Some(OwnedSource { parts, roughness })
}
