//! The main pass: chunks in the opaque 3-D phase, lit by Bevy's PBR lighting.

use super::draw::DrawInstancedChunk;
use super::extract::{ClassFeatures, ExtractedChunk};
use super::pipelines::{ChunkPipelines, instance_layout};
use super::prepare::ChunkBindings;
use super::retained::{Queued, rebin_cameras};
use bevy::asset::UntypedAssetId;
use bevy::core_pipeline::core_3d::{Opaque3d, Opaque3dBatchSetKey, Opaque3dBinKey};
use bevy::mesh::{MeshVertexBufferLayoutRef, VertexAttributeDescriptor};
use bevy::pbr::{MeshPipeline, MeshPipelineKey, ViewKeyCache};
use bevy::prelude::*;
use bevy::render::mesh::allocator::MeshSlabs;
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

/// A main-pass pipeline's key: the view's and mesh's bits, and the class's features.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(in crate::instancing) struct InstancedKey {
    mesh: MeshPipelineKey,
    features: ClassFeatures,
}

impl SpecializedMeshPipeline for InstancedPipeline {
    type Key = InstancedKey;

    fn specialize(
        &self,
        key: Self::Key,
        layout: &MeshVertexBufferLayoutRef,
    ) -> Result<RenderPipelineDescriptor, SpecializedMeshPipelineError> {
        let mut descriptor = self.mesh_pipeline.specialize(key.mesh, layout)?;
        let mut defs = vec![ShaderDefVal::UInt("MATERIAL_BIND_GROUP".into(), 3)];
        let attributes = mesh_attributes(layout, key.features, &mut defs);
        descriptor.vertex.buffers = vec![layout.0.get_layout(&attributes)?, instance_layout()];
        descriptor.vertex.shader = self.bindings.shader.clone();
        descriptor.vertex.shader_defs.extend(defs.iter().cloned());
        if let Some(fragment) = descriptor.fragment.as_mut() {
            fragment.shader = self.bindings.shader.clone();
            fragment.shader_defs.extend(defs);
        }
        descriptor.layout.truncate(2);
        descriptor.layout.push(self.bindings.layout.clone());
        descriptor.primitive.cull_mode = key.features.cull_mode();
        descriptor.label = Some("rwt_instanced_pipeline".into());
        Ok(descriptor)
    }
}

/// The mesh attributes a pipeline reads (position; normals when the mesh has them; UVs when
/// the class is textured), with the shader definitions they and the class's features need.
pub(super) fn mesh_attributes(
    layout: &MeshVertexBufferLayoutRef,
    features: ClassFeatures,
    defs: &mut Vec<ShaderDefVal>,
) -> Vec<VertexAttributeDescriptor> {
    let mut attributes = vec![Mesh::ATTRIBUTE_POSITION.at_shader_location(0)];
    if layout.0.contains(Mesh::ATTRIBUTE_NORMAL) {
        attributes.push(Mesh::ATTRIBUTE_NORMAL.at_shader_location(1));
        defs.push("RWT_NORMALS".into());
    }
    if features.bends {
        defs.push("RWT_BEND".into());
    }
    if features.textured {
        // A mesh without UVs fails the layout, and the class is reported once.
        attributes.push(Mesh::ATTRIBUTE_UV_0.at_shader_location(2));
        defs.push("RWT_TEXTURE".into());
    }
    if features.impostor {
        defs.push("RWT_IMPOSTOR".into());
    }
    if features.fades_out {
        defs.push("RWT_FADE_OUT".into());
    }
    if features.fades_in {
        defs.push("RWT_FADE_IN".into());
    }
    if let Some(surface) = features.surface {
        defs.push("RWT_SURFACE".into());
        if surface.normal_map {
            // A mesh without tangents fails the layout, and the class is reported once.
            attributes.push(Mesh::ATTRIBUTE_TANGENT.at_shader_location(3));
            defs.push("RWT_NORMAL_MAP".into());
        }
        if surface.double_sided {
            defs.push("RWT_DOUBLE_SIDED".into());
        }
        if layout.0.contains(Mesh::ATTRIBUTE_COLOR) {
            attributes.push(Mesh::ATTRIBUTE_COLOR.at_shader_location(4));
            defs.push("RWT_VERTEX_COLORS".into());
        }
    }
    attributes
}

/// The bin of a chunk's mesh in the binned phases.
pub(super) fn mesh_bin(mesh: AssetId<Mesh>) -> UntypedAssetId {
    mesh.untyped()
}

/// Bins every chunk visible from each view (culled by its `Aabb`) into the opaque phase.
pub(in crate::instancing) fn queue_main(
    draw_functions: Res<DrawFunctions<Opaque3d>>,
    mut pipelines: ChunkPipelines<InstancedPipeline>,
    chunks: Query<&ExtractedChunk>,
    mut phases: ResMut<ViewBinnedRenderPhases<Opaque3d>>,
    views: Query<(&ExtractedView, &RenderVisibleEntities)>,
    view_keys: Res<ViewKeyCache>,
    mut queued: ResMut<Queued<Opaque3d>>,
) {
    let draw = draw_functions.read().id::<DrawInstancedChunk>();
    let key_of = |view: &_| view_keys.get(view).copied();
    rebin_cameras(
        &mut phases,
        &mut queued,
        &views,
        key_of,
        |view_key, entity, main| {
            let chunk = chunks.get(entity).ok()?;
            let id = pipelines.of(chunk, |topology| InstancedKey {
                mesh: view_key | topology,
                features: chunk.features(),
            })?;
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
            Some((batch_set, bin, (entity, main)))
        },
    );
}
