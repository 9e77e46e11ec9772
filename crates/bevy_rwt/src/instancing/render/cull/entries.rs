//! What culling reads of the render world, and the frame's entries: every mesh of every
//! chunk binned into a view's phases that culling may thin, in a stable order.

use super::culler::{ARGS_WORDS, INSTANCE_BYTES};
use super::lods::{self, Part};
use super::pyramids::{Occluding, PyramidQuery};
use super::views::ViewCulling;
use super::whole;
use crate::instancing::render::extract::ExtractedChunk;
use crate::instancing::render::prepare::{GpuChunk, MainViewer};
use crate::instancing::render::receivers::CascadeReceivers;
use crate::instancing::render::retained::Queued;
use crate::instancing::render::slab::InstanceSlab;
use crate::instancing::render::slices::MeshSlices;
use crate::instancing::settings::InstanceCulling;
use bevy::camera::primitives::Frustum;
use bevy::core_pipeline::core_3d::Opaque3d;
use bevy::core_pipeline::prepass::Opaque3dPrepass;
use bevy::pbr::{LightEntity, Shadow};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::mesh::RenderMesh;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::render_asset::RenderAssets;
use bevy::render::view::{ExtractedView, RetainedViewEntity};

/// Each mesh's draw arguments before culling, found once a frame.
pub(super) type MeshArgs = HashMap<AssetId<Mesh>, Option<[u32; ARGS_WORDS as usize]>>;

/// One mesh of one chunk in one view, as the CPU lays it out: it becomes a record of the
/// view's dispatch ([`CullRecord`](super::params::CullRecord)) and a culled draw.
pub(super) struct CullEntry<'a> {
    pub view: &'a ViewCulling,
    pub chunk: Entity,
    pub extracted: &'a ExtractedChunk,
    pub gpu: &'a GpuChunk,
    /// The mesh and the instances it draws.
    pub part: Part,
    /// The chunk's first instance in the slab.
    pub first_instance: u32,
    /// The draw's arguments before culling (the instance count 0).
    pub args: [u32; ARGS_WORDS as usize],
}

impl CullEntry<'_> {
    /// The bytes of the chunk's instances: of each range of the pool it keeps into.
    pub fn bytes(&self) -> u64 {
        u64::from(self.gpu.count) * INSTANCE_BYTES
    }

    /// Last frame's and this frame's clip space from world space, where the entry
    /// occludes in two phases.
    pub fn occludes(&self) -> Option<(Mat4, Mat4)> {
        let occluding = self.view.occluding?;
        Some((occluding.previous?, occluding.current))
    }
}

/// What culling reads of a view: its frustum, whether it is a shadow view, its pyramid.
pub(super) type ViewData = (
    Entity,
    &'static ExtractedView,
    Option<&'static Frustum>,
    Has<LightEntity>,
    PyramidQuery,
);

/// What the culling pass reads of the render world.
#[derive(bevy::ecs::system::SystemParam)]
pub(in crate::instancing) struct CullInputs<'w, 's> {
    pub(super) setting: Option<Res<'w, InstanceCulling>>,
    pub(super) main: Res<'w, Queued<Opaque3d>>,
    pub(super) prepass: Res<'w, Queued<Opaque3dPrepass>>,
    pub(super) shadow: Res<'w, Queued<Shadow>>,
    pub(super) views: Query<'w, 's, ViewData>,
    pub(super) chunks: Query<'w, 's, (&'static ExtractedChunk, &'static GpuChunk)>,
    pub(super) meshes: Res<'w, RenderAssets<RenderMesh>>,
    pub(super) allocator: Res<'w, MeshAllocator>,
    pub(super) viewer: Res<'w, MainViewer>,
    pub(super) slab: Res<'w, InstanceSlab>,
    pub(super) receivers: Res<'w, CascadeReceivers>,
}

impl CullInputs<'_, '_> {
    /// How each view culls this frame.
    pub(super) fn views(
        &self,
        occluding: &HashMap<Entity, Occluding>,
    ) -> HashMap<RetainedViewEntity, ViewCulling> {
        self.views
            .iter()
            .map(|(entity, view, frustum, shadow, _)| {
                let eye = match (shadow, self.viewer.0) {
                    (true, Some(eye)) => eye,
                    _ => view.world_from_view.translation(),
                };
                let planes =
                    frustum.map_or([Vec4::W; 6], |f| f.0.half_spaces.map(|h| h.normal_d()));
                let culling = ViewCulling {
                    entity,
                    planes,
                    eye,
                    shadow,
                    receivers: self.receivers.of(entity).copied(),
                    occluding: occluding.get(&entity).copied(),
                };
                (view.retained_view_entity, culling)
            })
            .collect()
    }

    /// Every (view, chunk) binned this frame in one of `views`, once each, in a stable
    /// order (a view's entries together).
    pub(super) fn entries<'a>(
        &'a self,
        views: &'a HashMap<RetainedViewEntity, ViewCulling>,
    ) -> Vec<CullEntry<'a>> {
        // Every (view, chunk) binned in any phase, once each: the camera's chunks are in
        // its main pass and its prepass.
        let mut pairs: Vec<(&ViewCulling, Entity)> = Vec::new();
        let mut add = |retained: &RetainedViewEntity,
                       entities: &mut dyn Iterator<Item = Entity>| {
            if let Some(view) = views.get(retained) {
                pairs.extend(entities.map(|entity| (view, entity)));
            }
        };
        self.main.binned().for_each(|(r, mut e)| add(r, &mut e));
        self.prepass.binned().for_each(|(r, mut e)| add(r, &mut e));
        self.shadow.binned().for_each(|(r, mut e)| add(r, &mut e));
        pairs.sort_unstable_by_key(|(view, chunk)| (view.entity, *chunk));
        pairs.dedup_by_key(|(view, chunk)| (view.entity, *chunk));
        let mut args = HashMap::default();
        pairs
            .into_iter()
            .filter_map(|(view, chunk)| {
                let (extracted, gpu) = self.chunks.get(chunk).ok()?;
                let culls = gpu.count > 0
                    && (whole::may_drop(view, &extracted.bounds, &gpu.uniform, extracted.shadows)
                        || lods::across(view, extracted));
                culls.then_some((view, chunk, extracted, gpu))
            })
            .flat_map(|(view, chunk, extracted, gpu)| {
                self.parts(view, chunk, extracted, gpu, &mut args)
            })
            .flatten()
            .collect()
    }

    /// The entries of one chunk in one view, a mesh each; none unless every mesh is
    /// ready and the chunk's instances are in the slab (then it is drawn whole).
    fn parts<'a>(
        &'a self,
        view: &'a ViewCulling,
        chunk: Entity,
        extracted: &'a ExtractedChunk,
        gpu: &'a GpuChunk,
        args: &mut MeshArgs,
    ) -> [Option<CullEntry<'a>>; 2] {
        let first = self.slab.range(chunk).filter(|_| gpu.own.is_none());
        let Some(first_instance) = first.map(|r| r.start) else {
            return [None, None];
        };
        let parts = lods::parts(view, extracted, &self.meshes);
        let entry = |part: Option<Part>| {
            let part = part?;
            Some(CullEntry {
                view,
                chunk,
                extracted,
                gpu,
                part,
                first_instance,
                args: *args
                    .entry(part.mesh)
                    .or_insert_with(|| self.args(part.mesh))
                    .as_ref()?,
            })
        };
        let entries = parts.map(entry);
        let ready = parts
            .iter()
            .zip(&entries)
            .all(|(p, d)| p.is_none() == d.is_none());
        if ready { entries } else { [None, None] }
    }

    /// A mesh's draw arguments before culling, as the direct draw would give them.
    fn args(&self, mesh: AssetId<Mesh>) -> Option<[u32; ARGS_WORDS as usize]> {
        MeshSlices::of(&self.meshes, &self.allocator, mesh).map(|s| s.args)
    }
}
