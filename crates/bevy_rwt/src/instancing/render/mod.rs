//! Render world: each visible [`InstancedChunk`] is drawn with one instanced draw of its
//! class's mesh, from a vertex buffer made once per instance buffer (kept while the main
//! world's buffer is the same one) and a small uniform with the chunk's corner, shading,
//! fall-off and wind.

use super::{GpuInstance, InstanceBuffer, InstancedChunk, RwtFadeIn, RwtWind};
use crate::look::check_topology;
use bevy::core_pipeline::core_3d::{Transparent3d, TransparentSortingInfo3d};
use bevy::ecs::query::QueryItem;
use bevy::ecs::system::{SystemParamItem, lifetimeless::*};
use bevy::mesh::{MeshVertexBufferLayoutRef, VertexBufferLayout};
use bevy::pbr::{
    MeshPipeline, MeshPipelineKey, SetMeshViewBindGroup, SetMeshViewBindingArrayBindGroup,
    ViewKeyCache,
};
use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::extract_resource::ExtractResource;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::mesh::{RenderMesh, RenderMeshBufferInfo};
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_phase::{
    DrawFunctions, PhaseItem, PhaseItemExtraIndex, RenderCommand, RenderCommandResult,
    SetItemPipeline, TrackedRenderPass, ViewSortedRenderPhases,
};
use bevy::render::render_resource::binding_types::uniform_buffer_sized;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::sync_component::SyncComponent;
use bevy::render::view::{ExtractedView, RenderVisibleEntities};
use bevy::shader::ShaderDefVal;
use bytemuck::{Pod, Zeroable};
use std::sync::Arc;

/// Shader locations of the instance attributes (after every mesh attribute).
const INSTANCE_LOCATIONS: [u32; 2] = [8, 9];

/// The per-chunk uniform, as the shader reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
struct ChunkUniform {
    /// Chunk corner (xyz) and the mesh's top (w).
    origin: [f32; 4],
    base_color: [f32; 4],
    tip_color: [f32; 4],
    /// Colour variation, roughness, wind response, fade band.
    params: [f32; 4],
    /// Fall-off near, far, 1 when the layer has one, and its floor.
    falloff: [f32; 4],
    /// Wind direction (x, z), strength, frequency.
    wind: [f32; 4],
    /// Wind speed.
    wind_motion: [f32; 4],
    /// Height fraction where the tip colour starts, unused.
    shading: [f32; 4],
}

/// A chunk as the render world sees it (its extraction is part of [`InstancedChunk`]'s
/// render-world interface; nothing to use directly).
#[derive(Component, Clone)]
pub struct ExtractedChunk {
    buffer: Arc<InstanceBuffer>,
    mesh: AssetId<Mesh>,
    uniform: ChunkUniform,
    /// World-space centre of the instances, for sorting.
    centre: Vec3,
}

impl SyncComponent for InstancedChunk {
    type Target = ExtractedChunk;
}

impl ExtractComponent for InstancedChunk {
    type QueryData = (&'static InstancedChunk, &'static GlobalTransform);
    type QueryFilter = ();
    type Out = ExtractedChunk;

    fn extract_component(
        (chunk, transform): QueryItem<'_, '_, Self::QueryData>,
    ) -> Option<Self::Out> {
        let origin = transform.translation();
        let m = &chunk.material;
        let (lo, hi) = chunk.buffer.bounds;
        let (near, far, on, floor) = chunk
            .falloff
            .map_or((0.0, 1.0, 0.0, 0.0), |(n, f, floor)| (n, f, 1.0, floor));
        Some(ExtractedChunk {
            buffer: chunk.buffer.clone(),
            mesh: chunk.mesh.id(),
            uniform: ChunkUniform {
                origin: origin.extend(chunk.mesh_top).to_array(),
                base_color: m.base_color.to_linear().to_f32_array(),
                tip_color: m.tip_color.to_linear().to_f32_array(),
                params: [
                    m.color_variation,
                    m.roughness,
                    m.wind_response,
                    m.fade_band.max(1e-3),
                ],
                falloff: [near, far, on, floor],
                shading: [m.tip_from.clamp(0.0, 0.99), 0.0, 0.0, 0.0],
                ..default()
            },
            centre: origin + (lo + hi) * 0.5,
        })
    }
}

impl ExtractResource for RwtWind {
    type Source = RwtWind;

    fn extract_resource(source: &Self::Source) -> Self {
        *source
    }
}

impl ExtractResource for RwtFadeIn {
    type Source = RwtFadeIn;

    fn extract_resource(source: &Self::Source) -> Self {
        *source
    }
}

/// A chunk's GPU resources.
#[derive(Component)]
pub(super) struct GpuChunk {
    /// The main world's buffer these were made from.
    source: Arc<InstanceBuffer>,
    instances: Buffer,
    count: u32,
    uniform: ChunkUniform,
    uniform_buffer: Buffer,
    bind_group: BindGroup,
}

/// The instanced pipeline: Bevy's mesh pipeline (view bindings, lights, shadows, fog) with
/// our shader, the instance buffer and the chunk uniform.
#[derive(Resource)]
pub(super) struct InstancedPipeline {
    mesh_pipeline: MeshPipeline,
    shader: Handle<Shader>,
    chunk_layout: BindGroupLayoutDescriptor,
}

/// Meshes that cannot be drawn, reported once each.
#[derive(Resource, Default)]
pub(super) struct ReportedMeshes(HashSet<AssetId<Mesh>>);

impl ReportedMeshes {
    /// Logs why `mesh` cannot be drawn, the first time only.
    fn once(&mut self, mesh: AssetId<Mesh>, reason: &str) {
        if self.0.insert(mesh) {
            error!("instanced class mesh {mesh:?} cannot be drawn: {reason}");
        }
    }
}

pub(super) fn init_pipeline(
    mut commands: Commands,
    mesh_pipeline: Res<MeshPipeline>,
    asset_server: Res<AssetServer>,
) {
    let entries = BindGroupLayoutEntries::single(
        ShaderStages::VERTEX_FRAGMENT,
        uniform_buffer_sized(false, None),
    );
    commands.insert_resource(InstancedPipeline {
        mesh_pipeline: mesh_pipeline.clone(),
        shader: bevy::asset::load_embedded_asset!(asset_server.as_ref(), "instanced.wgsl"),
        chunk_layout: BindGroupLayoutDescriptor::new("rwt_instanced_chunk", &entries),
    });
}

/// The instance buffer's layout: offset and scale, then yaw, appearance and tint.
fn instance_layout() -> VertexBufferLayout {
    VertexBufferLayout {
        array_stride: size_of::<GpuInstance>() as u64,
        step_mode: VertexStepMode::Instance,
        attributes: vec![
            VertexAttribute {
                format: VertexFormat::Float32x4,
                offset: 0,
                shader_location: INSTANCE_LOCATIONS[0],
            },
            VertexAttribute {
                format: VertexFormat::Unorm16x4,
                offset: 16,
                shader_location: INSTANCE_LOCATIONS[1],
            },
        ],
    }
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
        descriptor.vertex.shader = self.shader.clone();
        descriptor.vertex.shader_defs.extend(defs.iter().cloned());
        if let Some(fragment) = descriptor.fragment.as_mut() {
            fragment.shader = self.shader.clone();
            fragment.shader_defs.extend(defs);
        }
        descriptor.layout.truncate(2);
        descriptor.layout.push(self.chunk_layout.clone());
        // Blades are seen from both sides.
        descriptor.primitive.cull_mode = None;
        descriptor.label = Some("rwt_instanced_pipeline".into());
        Ok(descriptor)
    }
}

/// Makes the GPU resources of new or changed chunks; updates the uniform when the wind or
/// the fade-in setting changes.
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub(super) fn prepare_chunks(
    mut commands: Commands,
    mut chunks: Query<(Entity, &ExtractedChunk, Option<&mut GpuChunk>)>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    pipeline: Res<InstancedPipeline>,
    cache: Res<PipelineCache>,
    wind: Option<Res<RwtWind>>,
    fade: Option<Res<RwtFadeIn>>,
) {
    let wind = wind.map(|w| *w).unwrap_or_default();
    let fade = fade.map(|f| *f).unwrap_or_default();
    for (entity, chunk, gpu) in &mut chunks {
        let mut uniform = chunk.uniform;
        uniform.wind = [
            wind.direction.x,
            wind.direction.y,
            wind.strength,
            wind.frequency,
        ];
        uniform.wind_motion = [wind.speed, 0.0, 0.0, 0.0];
        if !fade.0 {
            uniform.falloff[2] = 0.0;
        }
        match gpu {
            Some(mut gpu) if Arc::ptr_eq(&gpu.source, &chunk.buffer) => {
                if gpu.uniform != uniform {
                    queue.write_buffer(&gpu.uniform_buffer, 0, bytemuck::bytes_of(&uniform));
                    gpu.uniform = uniform;
                }
            }
            _ => {
                let gpu = upload(&device, &pipeline, &cache, chunk, uniform);
                commands.entity(entity).insert(gpu);
            }
        }
    }
}

/// The GPU resources of one chunk.
fn upload(
    device: &RenderDevice,
    pipeline: &InstancedPipeline,
    cache: &PipelineCache,
    chunk: &ExtractedChunk,
    uniform: ChunkUniform,
) -> GpuChunk {
    let instances = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("rwt_instances"),
        contents: bytemuck::cast_slice(&chunk.buffer.instances),
        usage: BufferUsages::VERTEX,
    });
    let uniform_buffer = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("rwt_instanced_chunk"),
        contents: bytemuck::bytes_of(&uniform),
        usage: BufferUsages::UNIFORM | BufferUsages::COPY_DST,
    });
    let bind_group = device.create_bind_group(
        "rwt_instanced_chunk",
        &cache.get_bind_group_layout(&pipeline.chunk_layout),
        &BindGroupEntries::single(uniform_buffer.as_entire_binding()),
    );
    GpuChunk {
        source: chunk.buffer.clone(),
        instances,
        count: chunk.buffer.instances.len() as u32,
        uniform,
        uniform_buffer,
        bind_group,
    }
}

/// Queues every chunk visible from each view (culled by its `Aabb`), sorted with the
/// transparent phase so that no batching state of Bevy's meshes is involved.
#[allow(clippy::too_many_arguments)]
pub(super) fn queue_chunks(
    draw_functions: Res<DrawFunctions<Transparent3d>>,
    pipeline: Res<InstancedPipeline>,
    mut pipelines: ResMut<SpecializedMeshPipelines<InstancedPipeline>>,
    cache: Res<PipelineCache>,
    meshes: Res<RenderAssets<RenderMesh>>,
    chunks: Query<&ExtractedChunk>,
    mut phases: ResMut<ViewSortedRenderPhases<Transparent3d>>,
    views: Query<(&ExtractedView, &RenderVisibleEntities)>,
    view_keys: Res<ViewKeyCache>,
    mut reported: ResMut<ReportedMeshes>,
) {
    let draw = draw_functions.read().id::<DrawInstancedChunk>();
    for (view, visible) in &views {
        let Some(phase) = phases.get_mut(&view.retained_view_entity) else {
            continue;
        };
        let (Some(&view_key), Some(visible)) = (
            view_keys.get(&view.retained_view_entity),
            visible.get::<InstancedChunk>(),
        ) else {
            continue;
        };
        for &(entity, main_entity) in &visible.entities_cpu_culling {
            let Ok(chunk) = chunks.get(entity) else {
                continue;
            };
            let Some(mesh) = meshes.get(chunk.mesh) else {
                continue;
            };
            let key = view_key
                | MeshPipelineKey::from_primitive_topology_and_strip_index(
                    mesh.primitive_topology(),
                    mesh.index_format(),
                );
            let id = check_topology(mesh.primitive_topology())
                .map_err(|e| e.to_string())
                .and_then(|()| {
                    pipelines
                        .specialize(&cache, &pipeline, key, &mesh.layout)
                        .map_err(|e| e.to_string())
                });
            let id = match id {
                Ok(id) => id,
                Err(e) => {
                    reported.once(chunk.mesh, &e);
                    continue;
                }
            };
            phase.add_retained(Transparent3d {
                sorting_info: TransparentSortingInfo3d::Sorted {
                    mesh_center: chunk.centre,
                    depth_bias: 0.0,
                },
                entity: (entity, main_entity),
                pipeline: id,
                draw_function: draw,
                distance: 0.0,
                batch_range: 0..1,
                extra_index: PhaseItemExtraIndex::None,
                indexed: mesh.indexed(),
            });
        }
    }
}

/// The draw of one chunk.
pub(super) type DrawInstancedChunk = (
    SetItemPipeline,
    SetMeshViewBindGroup<0>,
    SetMeshViewBindingArrayBindGroup<1>,
    SetChunkBindGroup<2>,
    DrawChunkInstances,
);

/// Binds a chunk's uniform.
pub(super) struct SetChunkBindGroup<const I: usize>;

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

/// Draws a chunk's mesh once per instance.
pub(super) struct DrawChunkInstances;

impl<P: PhaseItem> RenderCommand<P> for DrawChunkInstances {
    type Param = (SRes<RenderAssets<RenderMesh>>, SRes<MeshAllocator>);
    type ViewQuery = ();
    type ItemQuery = (Read<ExtractedChunk>, Read<GpuChunk>);

    fn render<'w>(
        _: &P,
        _: (),
        item: Option<(&'w ExtractedChunk, &'w GpuChunk)>,
        (meshes, allocator): SystemParamItem<'w, '_, Self::Param>,
        pass: &mut TrackedRenderPass<'w>,
    ) -> RenderCommandResult {
        let (meshes, allocator) = (meshes.into_inner(), allocator.into_inner());
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
