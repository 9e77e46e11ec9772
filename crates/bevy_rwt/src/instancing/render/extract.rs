//! Extraction: each [`InstancedChunk`] becomes an [`ExtractedChunk`] in the render world,
//! made again only when the chunk, its transform or its bounds changed.

use super::uniforms::ChunkUniform;
use crate::instancing::chunk::{InstanceBuffer, InstancedChunk};
use crate::look::InstancedShadows;
use crate::look::asset::InstancedSurface;
use bevy::camera::primitives::Aabb;
use bevy::ecs::query::QueryItem;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::render_resource::Face;
use bevy::render::sync_component::SyncComponent;
use std::sync::Arc;

/// A chunk as the render world sees it (its extraction is part of [`InstancedChunk`]'s
/// render-world interface; nothing to use directly).
#[derive(Component, Clone)]
pub struct ExtractedChunk {
    pub(super) buffer: Arc<InstanceBuffer>,
    pub(super) mesh: AssetId<Mesh>,
    /// The class's near and far meshes, where culling per instance may choose between them
    /// by each instance's distance.
    pub(super) lods: Option<MeshLods>,
    pub(super) uniform: ChunkUniform,
    /// World-space bounds of the drawn instances, for culling shadow views.
    pub(super) bounds: Aabb,
    /// Distance from an instance's root (at scale 1) that its mesh reaches, turned, tilted
    /// or swaying any way: the radius culling per instance tests.
    pub(super) reach: f32,
    pub(super) shadows: InstancedShadows,
    /// The textures, in binding order: base colour (the class's texture), then an asset
    /// surface's normal map, metallic-roughness, emissive and occlusion.
    pub(super) textures: [Option<AssetId<Image>>; 5],
    /// What an asset's surface compiles in (`None`: a class's own instanced look).
    pub(super) surface: Option<SurfaceFeatures>,
}

impl ExtractedChunk {
    /// What its class's pipelines compile in: a texture, and a bend response other than 0.
    pub(super) fn features(&self) -> ClassFeatures {
        let textured = self.textures.iter().any(Option::is_some);
        ClassFeatures {
            textured,
            bends: self.uniform.bend_response != 0.0,
            impostor: self.uniform.impostor_views != 0 && textured,
            fades_out: self.uniform.fade_out_to > 0.0,
            fades_in: self.uniform.fade_in_to > 0.0 && self.uniform.impostor_views == 0,
            surface: self.surface,
        }
    }
}

impl ClassFeatures {
    /// The faces not drawn: none of blades (seen from both sides) and of double-sided
    /// surfaces, the back of other surfaces.
    pub(super) fn cull_mode(&self) -> Option<Face> {
        match self.surface {
            Some(s) if !s.double_sided => Some(Face::Back),
            _ => None,
        }
    }
}

/// What an asset's surface compiles in: its normal map (and the mesh's tangents), whether
/// both sides are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub(super) struct SurfaceFeatures {
    /// `RWT_NORMAL_MAP`.
    pub(super) normal_map: bool,
    /// `RWT_DOUBLE_SIDED`, and no face culled.
    pub(super) double_sided: bool,
}

impl SurfaceFeatures {
    fn of(surface: &InstancedSurface) -> Self {
        Self {
            normal_map: surface.normal_map.is_some(),
            double_sided: surface.double_sided,
        }
    }
}

/// A class's near and far meshes, and the distance from the eye from which an instance
/// draws the far one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MeshLods {
    pub(super) near: AssetId<Mesh>,
    pub(super) far: AssetId<Mesh>,
    pub(super) distance: f32,
}

impl MeshLods {
    /// The meshes of `chunk`'s class, where it may choose by each instance's distance.
    fn of(chunk: &InstancedChunk) -> Option<Self> {
        let far = chunk.meshes.1.as_ref().filter(|_| chunk.far_per_instance)?;
        Some(Self {
            near: chunk.meshes.0.id(),
            far: far.mesh.id(),
            distance: far.distance,
        })
    }
}

/// What a class's pipelines compile in, as shader definitions rather than branches on
/// uniforms (a branch on uniforms alone makes lavapipe recompile at each draw; a feature a
/// class lacks costs nothing): UVs and the alpha cut-out for a textured class, the bend
/// field's fetch for a class that bends.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub(super) struct ClassFeatures {
    /// The class has a base-colour texture (`RWT_TEXTURE`).
    pub(super) textured: bool,
    /// The class leans away from benders (`RWT_BEND`).
    pub(super) bends: bool,
    /// The chunk draws impostors, cards showing its texture's atlas (`RWT_IMPOSTOR`).
    pub(super) impostor: bool,
    /// The chunk's meshes fade out where its class's impostors or a farther level of detail
    /// take over (`RWT_FADE_OUT`).
    pub(super) fades_out: bool,
    /// The chunk's meshes fade in where a nearer level of detail hands over (`RWT_FADE_IN`).
    pub(super) fades_in: bool,
    /// The chunk draws an asset's primitive (`RWT_SURFACE`).
    pub(super) surface: Option<SurfaceFeatures>,
}

impl SyncComponent for InstancedChunk {
    type Target = ExtractedChunk;
}

/// Extracted when it changed: the render world keeps a chunk's extraction until then (its
/// render entity lives as long as the component), so a frame costs what changed, not every
/// chunk.
impl ExtractComponent for InstancedChunk {
    type QueryData = (
        &'static InstancedChunk,
        &'static GlobalTransform,
        Option<&'static Aabb>,
    );
    type QueryFilter = Or<(
        Changed<InstancedChunk>,
        Changed<GlobalTransform>,
        Changed<Aabb>,
    )>;
    type Out = ExtractedChunk;

    fn extract_component(
        (chunk, transform, aabb): QueryItem<'_, '_, Self::QueryData>,
    ) -> Option<Self::Out> {
        let origin = transform.translation();
        let local = aabb.copied().unwrap_or_else(|| {
            let (lo, hi) = chunk.buffer.bounds;
            Aabb::from_min_max(lo, hi)
        });
        Some(ExtractedChunk {
            reach: reach(&local, chunk.buffer.bounds, chunk.max_scale, aabb.is_some()),
            buffer: chunk.buffer.clone(),
            mesh: chunk.mesh.id(),
            lods: MeshLods::of(chunk),
            uniform: ChunkUniform::new(origin, chunk.mesh_top, &chunk.material, chunk.falloff)
                .with_impostor(chunk.impostor.as_ref(), chunk.fade_in, chunk.fade_out)
                .with_surface(chunk.surface.as_ref()),
            bounds: Aabb {
                center: local.center + origin.to_vec3a(),
                half_extents: local.half_extents,
            },
            shadows: chunk.material.shadows,
            textures: textures(chunk),
            surface: chunk.surface.as_ref().map(SurfaceFeatures::of),
        })
    }
}

/// The textures a chunk binds: its class's texture, and its surface's maps.
fn textures(chunk: &InstancedChunk) -> [Option<AssetId<Image>>; 5] {
    match &chunk.surface {
        Some(surface) => surface.textures().map(|t| t.map(Handle::id)),
        None => [
            chunk.material.texture.as_ref().map(Handle::id),
            None,
            None,
            None,
            None,
        ],
    }
}

/// The radius around an instance's root (at scale 1) that holds its mesh however it turns
/// and sways: from the chunk's bounds `local` around its instances' roots `roots` at the
/// class's largest scale (infinite when the chunk has no bounds).
pub(super) fn reach(local: &Aabb, roots: (Vec3, Vec3), max_scale: f32, bounded: bool) -> f32 {
    if !bounded || max_scale <= 0.0 {
        return f32::MAX;
    }
    let (min, max) = (Vec3::from(local.min()), Vec3::from(local.max()));
    let (lo, hi) = roots;
    let below = (lo - min).max(Vec3::ZERO);
    let above = (max - hi).max(Vec3::ZERO);
    let across = below.x.max(below.z).max(above.x).max(above.z);
    let up = below.y.max(above.y);
    (2.0 * across * across + up * up).sqrt() / max_scale
}
