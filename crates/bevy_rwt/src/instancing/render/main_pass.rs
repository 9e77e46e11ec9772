//! The main pass: chunks in the opaque 3-D phase, lit by Bevy's PBR lighting.

use super::draw::DrawInstancedChunk;
use super::{
    ChunkBindings, ExtractedChunk, InstancedChunk, Queued, ReportedMeshes, instance_layout,
    specialize, topology_key,
};
use bevy::asset::UntypedAssetId;
use bevy::core_pipeline::core_3d::{Opaque3d, Opaque3dBatchSetKey, Opaque3dBinKey};
use bevy::mesh::MeshVertexBufferLayoutRef;
use bevy::pbr::{MeshPipeline, MeshPipelineKey, ViewKeyCache};
use bevy::prelude::*;
use bevy::render::mesh::RenderMesh;
use bevy::render::mesh::allocator::MeshSlabs;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_phase::{DrawFunctions, ViewBinnedRenderPhases};
use bevy::render::render_resource::*;
use bevy::render::view::{ExtractedView, RenderVisibleEntities};
use bevy::shader::ShaderDefVal;

/// The main-pass pipeline: Bevy's mesh pipeline (view bindings, lights, shadows, fog) with
/// our shader, the instance buffer and the chunk's bind group.
#[derive(Resource)]
pub(in crate::instancing) struct InstancedPipeline {
    mesh_pipeline: MeshPipeline,
    bindings: ChunkBindings,
}

pub(in crate::instancing) fn init_main_pipeline(
    mut commands: Commands,
    mesh_pipeline: Res<MeshPipeline>,
    bindings: Res<ChunkBindings>,
) {
    commands.insert_resource(InstancedPipeline {
        mesh_pipeline: mesh_pipeline.clone(),
        bindings: bindings.clone(),
    });
}

impl SpecializedMeshPipeline for InstancedPipeline {
    type Key = MeshPipelineKey;

    fn specialize(
        &self,
        key: Self::Key,
        layout: &MeshVertexBufferLayoutRef,
    ) -> Result<RenderPipelineDescriptor, SpecializedMeshPipelineError> {
        let mut descriptor = self.mesh_pipeline.specialize(key, layout)?;
        let mut attributes = vec![Mesh::ATTRIBUTE_POSITION.at_shader_location(0)];
        let mut defs = vec![ShaderDefVal::UInt("MATERIAL_BIND_GROUP".into(), 3)];
        if layout.0.contains(Mesh::ATTRIBUTE_NORMAL) {
            attributes.push(Mesh::ATTRIBUTE_NORMAL.at_shader_location(1));
            defs.push("RWT_NORMALS".into());
        }
        descriptor.vertex.buffers = vec![layout.0.get_layout(&attributes)?, instance_layout()];
        descriptor.vertex.shader = self.bindings.shader.clone();
        descriptor.vertex.shader_defs.extend(defs.iter().cloned());
        if let Some(fragment) = descriptor.fragment.as_mut() {
            fragment.shader = self.bindings.shader.clone();
            fragment.shader_defs.extend(defs);
        }
        descriptor.layout.truncate(2);
        descriptor.layout.push(self.bindings.layout.clone());
        // Blades are seen from both sides.
        descriptor.primitive.cull_mode = None;
        descriptor.label = Some("rwt_instanced_pipeline".into());
        Ok(descriptor)
    }
}

/// The bin of a chunk's mesh in the binned phases.
pub(super) fn mesh_bin(mesh: AssetId<Mesh>) -> UntypedAssetId {
    mesh.untyped()
}

/// Bins every chunk visible from each view (culled by its `Aabb`) into the opaque phase.
#[allow(clippy::too_many_arguments)]
pub(in crate::instancing) fn queue_main(
    draw_functions: Res<DrawFunctions<Opaque3d>>,
    pipeline: Res<InstancedPipeline>,
    mut pipelines: ResMut<SpecializedMeshPipelines<InstancedPipeline>>,
    cache: Res<PipelineCache>,
    meshes: Res<RenderAssets<RenderMesh>>,
    chunks: Query<&ExtractedChunk>,
    mut phases: ResMut<ViewBinnedRenderPhases<Opaque3d>>,
    views: Query<(&ExtractedView, &RenderVisibleEntities)>,
    view_keys: Res<ViewKeyCache>,
    mut reported: ResMut<ReportedMeshes>,
    mut queued: ResMut<Queued<Opaque3d>>,
) {
    let draw = draw_functions.read().id::<DrawInstancedChunk>();
    for (view, visible) in &views {
        let Some(phase) = phases.get_mut(&view.retained_view_entity) else {
            continue;
        };
        let view_key = view_keys.get(&view.retained_view_entity).copied();
        let visible = visible
            .get::<InstancedChunk>()
            .map(|v| v.entities_cpu_culling.as_slice())
            .unwrap_or_default();
        let items = visible.iter().filter_map(|&(entity, main_entity)| {
            let chunk = chunks.get(entity).ok()?;
            let mesh = meshes.get(chunk.mesh)?;
            let key = view_key? | topology_key(mesh);
            let id = specialize(
                &mut pipelines,
                &cache,
                &pipeline,
                key,
                (chunk.mesh, mesh),
                &mut reported,
            )?;
            let batch_set = Opaque3dBatchSetKey {
                draw_function: draw,
                pipeline: id,
                material_bind_group_index: None,
                slabs: MeshSlabs::default(),
                lightmap_slab: None,
            };
            let bin = Opaque3dBinKey {
                asset_id: mesh_bin(chunk.mesh),
            };
            Some((batch_set, bin, (entity, main_entity)))
        });
        queued.rebin(view.retained_view_entity, phase, items.collect::<Vec<_>>());
    }
    queued.end_frame();
}
