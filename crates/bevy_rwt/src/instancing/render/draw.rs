//! The draw of one chunk: its bind group, its mesh once per instance: the instances culling
//! kept for the view, drawn indirectly, or all of them.

use super::{ExtractedChunk, GpuChunk, InstanceCuller};
use bevy::ecs::system::{SystemParamItem, lifetimeless::*};
use bevy::pbr::{SetMeshViewBindGroup, SetMeshViewBindingArrayBindGroup};
use bevy::prelude::Entity;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::mesh::{RenderMesh, RenderMeshBufferInfo};
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

/// Draws a chunk's mesh once per instance: those culling kept for the view, or all.
pub(in crate::instancing) struct DrawChunkInstances;

impl<P: PhaseItem> RenderCommand<P> for DrawChunkInstances {
    type Param = (
        SRes<RenderAssets<RenderMesh>>,
        SRes<MeshAllocator>,
        Option<SRes<InstanceCuller>>,
    );
    type ViewQuery = Entity;
    type ItemQuery = (Read<ExtractedChunk>, Read<GpuChunk>);

    fn render<'w>(
        item_of: &P,
        view: Entity,
        item: Option<(&'w ExtractedChunk, &'w GpuChunk)>,
        (meshes, allocator, culler): SystemParamItem<'w, '_, Self::Param>,
        pass: &mut TrackedRenderPass<'w>,
    ) -> RenderCommandResult {
        let (meshes, allocator) = (meshes.into_inner(), allocator.into_inner());
        let culled = culler.and_then(|c| c.into_inner().draw(view, item_of.entity()));
        let Some((chunk, gpu)) = item else {
            return RenderCommandResult::Skip;
        };
        let (Some(mesh), Some(vertices)) = (
            meshes.get(chunk.mesh),
            allocator.mesh_vertex_slice(&chunk.mesh),
        ) else {
            return RenderCommandResult::Skip;
        };
        pass.set_vertex_buffer(0, vertices.buffer.slice(..));
        if let Some((draw, kept, args)) = culled {
            pass.set_vertex_buffer(1, kept.slice(draw.kept.clone()));
            match &mesh.buffer_info {
                RenderMeshBufferInfo::Indexed { index_format, .. } => {
                    let Some(indices) = allocator.mesh_index_slice(&chunk.mesh) else {
                        return RenderCommandResult::Skip;
                    };
                    pass.set_index_buffer(indices.buffer.slice(..), *index_format);
                    pass.draw_indexed_indirect(args, draw.args);
                }
                RenderMeshBufferInfo::NonIndexed => pass.draw_indirect(args, draw.args),
            }
            return RenderCommandResult::Success;
        }
        pass.set_vertex_buffer(1, gpu.instances.slice(..));
        match &mesh.buffer_info {
            RenderMeshBufferInfo::Indexed {
                index_format,
                count,
            } => {
                let Some(indices) = allocator.mesh_index_slice(&chunk.mesh) else {
                    return RenderCommandResult::Skip;
                };
                pass.set_index_buffer(indices.buffer.slice(..), *index_format);
                pass.draw_indexed(
                    indices.range.start..indices.range.start + count,
                    vertices.range.start as i32,
                    0..gpu.count,
                );
            }
            RenderMeshBufferInfo::NonIndexed => {
                pass.draw(vertices.range, 0..gpu.count);
            }
        }
        RenderCommandResult::Success
    }
}
