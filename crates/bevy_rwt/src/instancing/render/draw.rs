//! The draw of one chunk: its bind group, its mesh once per instance: the instances culling
//! kept for the view, drawn indirectly, or all of them.
//!
//! A camera or light with Bevy's `OcclusionCulling` draws its depth prepass or shadow maps
//! twice: early, then late, for what its depth pyramid hid from the early phase
//! ([`LatePasses`]). A chunk drawn whole is drawn whole in the early pass and not again; a
//! culled chunk draws what culling's late phase kept.

use super::cull::InstanceCuller;
use super::extract::ExtractedChunk;
use super::prepare::GpuChunk;
use super::slab::InstanceSlab;
use super::slices::MeshSlices;
use bevy::ecs::system::{SystemParamItem, lifetimeless::*};
use bevy::pbr::{SetMeshViewBindGroup, SetMeshViewBindingArrayBindGroup};
use bevy::prelude::{Entity, ResMut, Resource};
use bevy::render::mesh::RenderMesh;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_phase::{
    PhaseItem, RenderCommand, RenderCommandResult, SetItemPipeline, TrackedRenderPass,
};

/// The draw of one chunk in the main pass.
pub(in crate::instancing) type DrawInstancedChunk = (
    SetItemPipeline,
    SetMeshViewBindGroup<0>,
    SetMeshViewBindingArrayBindGroup<1>,
    SetChunkBindGroup<2>,
    DrawChunkInstances,
);

/// Binds a chunk's uniforms.
pub(in crate::instancing) struct SetChunkBindGroup<const I: usize>;

impl<P: PhaseItem, const I: usize> RenderCommand<P> for SetChunkBindGroup<I> {
    type Param = ();
    type ViewQuery = ();
    type ItemQuery = Read<GpuChunk>;

    fn render<'w>(
        _: &P,
        _: (),
        gpu: Option<&'w GpuChunk>,
        _: SystemParamItem<'w, '_, Self::Param>,
        pass: &mut TrackedRenderPass<'w>,
    ) -> RenderCommandResult {
        let Some(gpu) = gpu else {
            return RenderCommandResult::Skip;
        };
        pass.set_bind_group(I, &gpu.bind_group, &[]);
        RenderCommandResult::Success
    }
}

/// Whether Bevy's late passes are being encoded: the late prepass and the late shadow
/// passes (set before them, cleared after them and before the main pass).
#[derive(Resource, Default)]
pub(in crate::instancing) struct LatePasses(bool);

/// Before the late passes.
pub(in crate::instancing) fn begin_late_passes(mut late: ResMut<LatePasses>) {
    late.0 = true;
}

/// After the late passes.
pub(in crate::instancing) fn end_late_passes(mut late: ResMut<LatePasses>) {
    late.0 = false;
}

/// Draws a chunk's mesh once per instance: those culling kept for the view (for each mesh
/// it chose, in each of its ranges; in a late pass, the late range only), or all (nothing
/// in a late pass).
pub(in crate::instancing) struct DrawChunkInstances;

impl<P: PhaseItem> RenderCommand<P> for DrawChunkInstances {
    type Param = (
        SRes<RenderAssets<RenderMesh>>,
        SRes<MeshAllocator>,
        SRes<InstanceSlab>,
        Option<SRes<InstanceCuller>>,
        SRes<LatePasses>,
    );
    type ViewQuery = Entity;
    type ItemQuery = (Read<ExtractedChunk>, Read<GpuChunk>);

    fn render<'w>(
        item_of: &P,
        view: Entity,
        item: Option<(&'w ExtractedChunk, &'w GpuChunk)>,
        (meshes, allocator, slab, culler, late): SystemParamItem<'w, '_, Self::Param>,
        pass: &mut TrackedRenderPass<'w>,
    ) -> RenderCommandResult {
        let (meshes, allocator) = (meshes.into_inner(), allocator.into_inner());
        let culled = culler.and_then(|c| c.into_inner().draw(view, item_of.entity()));
        let late = late.0;
        let Some((chunk, gpu)) = item else {
            return RenderCommandResult::Skip;
        };
        if let Some((draws, kept, args)) = culled {
            for draw in draws.iter() {
                let Some(slices) = MeshSlices::of(meshes, allocator, draw.mesh) else {
                    return RenderCommandResult::Skip;
                };
                slices.bind(pass);
                let early = (!late).then_some(&draw.early);
                for range in early.into_iter().chain(&draw.late) {
                    pass.set_vertex_buffer(1, kept.slice(range.kept.clone()));
                    if slices.indices.is_some() {
                        pass.draw_indexed_indirect(args, range.args);
                    } else {
                        pass.draw_indirect(args, range.args);
                    }
                }
            }
            return RenderCommandResult::Success;
        }
        if late {
            return RenderCommandResult::Success;
        }
        let Some(slices) = MeshSlices::of(meshes, allocator, chunk.mesh) else {
            return RenderCommandResult::Skip;
        };
        let instances = match &gpu.own {
            Some(own) => own.slice(..),
            None => match slab.into_inner().slice(item_of.entity()) {
                Some((buffer, bytes)) => buffer.slice(bytes),
                None => return RenderCommandResult::Skip,
            },
        };
        slices.bind(pass);
        pass.set_vertex_buffer(1, instances);
        let [count, _, first, base, _] = slices.args;
        if slices.indices.is_some() {
            pass.draw_indexed(first..first + count, base as i32, 0..gpu.count);
        } else {
            pass.draw(first..first + count, 0..gpu.count);
        }
        RenderCommandResult::Success
    }
}
