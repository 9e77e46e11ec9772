//! Render world: each [`InstancedChunk`] is drawn with one instanced draw of its class's
//! mesh, from a vertex buffer made once per instance buffer (kept while the main world's
//! buffer is the same one) and a small uniform with the chunk's corner, shading, fall-off
//! and wind.
//!
//! A chunk takes part in Bevy's passes as a mesh does: the opaque 3-D phase
//! ([`main_pass`]), the depth, normal and motion-vector prepasses of views that have them,
//! and the shadow maps of shadow-casting lights ([`depth`]), each culled by the chunk's
//! bounds per view. The phases are binned and retained; [`retained`] keeps our items in
//! them true frame by frame.

mod cull;
#[cfg(feature = "testing")]
mod cull_check;
mod depth;
mod draw;
#[cfg(test)]
mod extract_tests;
mod main_pass;
mod receivers;
mod retained;
#[cfg(test)]
mod shader_check;
mod slab;
mod uniforms;

pub(super) use cull::{InstanceCuller, cull_instances, cull_late, encode_cull, init_culler};
#[cfg(feature = "testing")]
pub use cull_check::{CullingCheck, CullingReport};
#[cfg(feature = "testing")]
pub(super) use cull_check::{FrameCheck, check_culling, extract_culling_check};
pub(super) use depth::{
    DrawInstancedDepth, InstancedDepthPipeline, init_depth_pipeline, queue_prepass, queue_shadows,
};
pub(super) use draw::{DrawInstancedChunk, LatePasses, begin_late_passes, end_late_passes};
pub(super) use main_pass::{InstancedPipeline, init_main_pipeline, queue_main};
pub(super) use receivers::{CascadeReceivers, find_receivers};
use retained::BinnedChunk;
pub(super) use retained::Queued;
pub(super) use slab::InstanceSlab;
use uniforms::{ChunkUniform, FrameUniform, uniform_bytes};

use super::bend::{BEND_FIELD_TEXELS, BendField};
use super::{
    CascadeCasters, GpuInstance, InstanceBuffer, InstanceCulling, InstancedChunk, RwtFadeIn,
    RwtWind,
};
use crate::look::{InstancedShadows, check_texture, check_topology};
use bevy::camera::primitives::Aabb;
use bevy::ecs::query::QueryItem;
use bevy::mesh::VertexBufferLayout;
use bevy::pbr::MeshPipelineKey;
use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::extract_resource::ExtractResource;
use bevy::render::mesh::RenderMesh;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_phase::{BinnedPhaseItem, ViewBinnedRenderPhases};
use bevy::render::render_resource::binding_types::{sampler, texture_2d, uniform_buffer_sized};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::sync_component::SyncComponent;
use bevy::render::sync_world::MainEntity;
use bevy::render::texture::{FallbackImage, GpuImage};
use bevy::render::view::{ExtractedView, RenderVisibleEntities, RetainedViewEntity};
use std::sync::Arc;

/// Shader locations of the instance attributes (after every mesh attribute).
const INSTANCE_LOCATIONS: [u32; 2] = [8, 9];

/// Adds the instanced and culling shaders to the app's embedded assets, and the level of
/// detail they share (`rwt::fade`) to its shader library.
pub(super) fn embed_shader(app: &mut App) {
    bevy::shader::load_shader_library!(app, "fade.wgsl");
    bevy::asset::embedded_asset!(app, "instanced.wgsl");
    bevy::asset::embedded_asset!(app, "cull/cull.wgsl");
}

/// A chunk as the render world sees it (its extraction is part of [`InstancedChunk`]'s
/// render-world interface; nothing to use directly).
#[derive(Component, Clone)]
pub struct ExtractedChunk {
    buffer: Arc<InstanceBuffer>,
    mesh: AssetId<Mesh>,
    /// The class's near and far meshes, where culling per instance may choose between them
    /// by each instance's distance.
    lods: Option<MeshLods>,
    uniform: ChunkUniform,
    /// World-space bounds of the drawn instances, for culling shadow views.
    bounds: Aabb,
    /// Distance from an instance's root (at scale 1) that its mesh reaches, turned, tilted
    /// or swaying any way: the radius culling per instance tests.
    reach: f32,
    shadows: InstancedShadows,
    /// The base-colour texture, if the class has one.
    texture: Option<AssetId<Image>>,
}

impl ExtractedChunk {
    /// What its class's pipelines compile in: a texture, and a bend response other than 0.
    fn features(&self) -> ClassFeatures {
        ClassFeatures {
            textured: self.texture.is_some(),
            bends: self.uniform.bend_response != 0.0,
            impostor: self.uniform.impostor_views != 0 && self.texture.is_some(),
            fades_out: self.uniform.fade_out_to > 0.0,
        }
    }
}

/// A class's near and far meshes, and the distance from the eye from which an instance
/// draws the far one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct MeshLods {
    near: AssetId<Mesh>,
    far: AssetId<Mesh>,
    distance: f32,
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
pub(in crate::instancing) struct ClassFeatures {
    /// The class has a base-colour texture (`RWT_TEXTURE`).
    textured: bool,
    /// The class leans away from benders (`RWT_BEND`).
    bends: bool,
    /// The chunk draws impostors, cards showing its texture's atlas (`RWT_IMPOSTOR`).
    impostor: bool,
    /// The chunk's meshes fade out where its class's impostors take over (`RWT_FADE_OUT`).
    fades_out: bool,
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
                .with_impostor(chunk.impostor.as_ref(), chunk.fade_out),
            bounds: Aabb {
                center: local.center + origin.to_vec3a(),
                half_extents: local.half_extents,
            },
            shadows: chunk.material.shadows,
            texture: chunk.material.texture.as_ref().map(Handle::id),
        })
    }
}

/// The radius around an instance's root (at scale 1) that holds its mesh however it turns
/// and sways: from the chunk's bounds `local` around its instances' roots `roots` at the
/// class's largest scale (infinite when the chunk has no bounds).
fn reach(local: &Aabb, roots: (Vec3, Vec3), max_scale: f32, bounded: bool) -> f32 {
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

impl ExtractResource for RwtWind {
    type Source = RwtWind;

    fn extract_resource(source: &Self::Source) -> Self {
        *source
    }
}

impl ExtractResource for BendField {
    type Source = BendField;

    fn extract_resource(source: &Self::Source) -> Self {
        source.clone()
    }
}

impl ExtractResource for RwtFadeIn {
    type Source = RwtFadeIn;

    fn extract_resource(source: &Self::Source) -> Self {
        *source
    }
}

impl ExtractResource for InstanceCulling {
    type Source = InstanceCulling;

    fn extract_resource(source: &Self::Source) -> Self {
        *source
    }
}

impl ExtractResource for CascadeCasters {
    type Source = CascadeCasters;

    fn extract_resource(source: &Self::Source) -> Self {
        *source
    }
}

/// A chunk's GPU resources.
#[derive(Component)]
pub(super) struct GpuChunk {
    /// The main world's buffer these were made from.
    source: Arc<InstanceBuffer>,
    /// The instances' own buffer, where [`InstanceSlab`] could not hold them (then drawn
    /// whole, never culled per instance); `None`: in the slab.
    own: Option<Buffer>,
    count: u32,
    uniform: ChunkUniform,
    uniform_buffer: Buffer,
    bind_group: BindGroup,
    /// The texture view bound (the fallback's until the class's texture is ready).
    texture_view: TextureViewId,
}

/// What every instanced pipeline shares: the shader and the layout of group 2 (the chunk's
/// uniform, the frame's, the bend field and its sampler), and the shared resources.
#[derive(Resource, Clone)]
pub(super) struct ChunkBindings {
    shader: Handle<Shader>,
    layout: BindGroupLayoutDescriptor,
    frame: Buffer,
    bend: Texture,
    bend_view: TextureView,
    bend_sampler: Sampler,
}

/// The main camera's position as the shadow passes see it, and the shared frame uniform.
#[derive(Resource, Default)]
pub(super) struct MainViewer(Option<Vec3>);

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

pub(super) fn init_bindings(
    mut commands: Commands,
    device: Res<RenderDevice>,
    asset_server: Res<AssetServer>,
) {
    let entries = BindGroupLayoutEntries::sequential(
        ShaderStages::VERTEX_FRAGMENT,
        (
            uniform_buffer_sized(false, None),
            uniform_buffer_sized(false, None),
            texture_2d(TextureSampleType::Float { filterable: true }),
            sampler(SamplerBindingType::Filtering),
            texture_2d(TextureSampleType::Float { filterable: true }),
            sampler(SamplerBindingType::Filtering),
        ),
    );
    let frame = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("rwt_instanced_frame"),
        contents: &uniform_bytes(&FrameUniform::default()),
        usage: BufferUsages::UNIFORM | BufferUsages::COPY_DST,
    });
    let bend = device.create_texture(&TextureDescriptor {
        label: Some("rwt_bend_field"),
        size: bend_extent(),
        mip_level_count: 1,
        sample_count: 1,
        dimension: TextureDimension::D2,
        format: TextureFormat::Rg8Snorm,
        usage: TextureUsages::TEXTURE_BINDING | TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let bend_sampler = device.create_sampler(&SamplerDescriptor {
        label: Some("rwt_bend_field"),
        mag_filter: FilterMode::Linear,
        min_filter: FilterMode::Linear,
        ..default()
    });
    commands.insert_resource(ChunkBindings {
        shader: bevy::asset::load_embedded_asset!(asset_server.as_ref(), "instanced.wgsl"),
        layout: BindGroupLayoutDescriptor::new("rwt_instanced_chunk", &entries),
        frame,
        bend_view: bend.create_view(&TextureViewDescriptor::default()),
        bend,
        bend_sampler,
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

fn bend_extent() -> Extent3d {
    Extent3d {
        width: BEND_FIELD_TEXELS,
        height: BEND_FIELD_TEXELS,
        depth_or_array_layers: 1,
    }
}

/// The main camera (the active 3-D camera of lowest order): the shadow passes grow
/// instances and choose casting chunks as it sees them. Writes the frame uniform, and the
/// bend field when it changed.
pub(super) fn prepare_frame(
    cameras: Query<(&ExtractedView, &ExtractedCamera), With<Camera3d>>,
    bindings: Option<Res<ChunkBindings>>,
    field: Option<Res<BendField>>,
    queue: Res<RenderQueue>,
    mut viewer: ResMut<MainViewer>,
) {
    viewer.0 = cameras
        .iter()
        .min_by_key(|(_, camera)| camera.order)
        .map(|(view, _)| view.world_from_view.translation());
    let Some(bindings) = bindings else { return };
    let uniform = FrameUniform {
        viewer: viewer.0.unwrap_or_default(),
        bends: field.as_ref().map_or(0, |f| u32::from(f.active())),
        bend_min: field.as_ref().map_or(Vec2::ZERO, |f| f.min()),
        bend_scale: field.as_ref().map_or(0.0, |f| 1.0 / f.extent()),
    };
    queue.write_buffer(&bindings.frame, 0, &uniform_bytes(&uniform));
    if let Some(field) = field.filter(|f| f.is_changed()) {
        let texels: Vec<[i8; 2]> = field
            .texels()
            .iter()
            .map(|l| [snorm8(l.x), snorm8(l.y)])
            .collect();
        queue.write_texture(
            TexelCopyTextureInfo {
                texture: &bindings.bend,
                mip_level: 0,
                origin: Origin3d::ZERO,
                aspect: TextureAspect::All,
            },
            bytemuck::cast_slice(&texels),
            TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(2 * BEND_FIELD_TEXELS),
                rows_per_image: None,
            },
            bend_extent(),
        );
    }
}

/// `v` in -1..1 as a signed normalized byte.
fn snorm8(v: f32) -> i8 {
    (v.clamp(-1.0, 1.0) * 127.0).round() as i8
}

/// The textures a chunk's bind group reads.
#[derive(bevy::ecs::system::SystemParam)]
pub(super) struct ChunkTextures<'w> {
    images: Res<'w, RenderAssets<GpuImage>>,
    fallback: Res<'w, FallbackImage>,
}

impl ChunkTextures<'_> {
    /// The texture `chunk` binds: its class's when it is ready and drawable, the fallback
    /// image (white) otherwise.
    fn of(&self, chunk: &ExtractedChunk) -> &GpuImage {
        chunk
            .texture
            .and_then(|id| self.images.get(id))
            .filter(|image| {
                let d = &image.texture_descriptor;
                check_texture(d.dimension, d.size.depth_or_array_layers, d.format).is_ok()
            })
            .unwrap_or(&self.fallback.d2)
    }
}

/// Makes the GPU resources of new or changed chunks (and the bind group again when the
/// class's texture became ready or changed); updates the uniform when the wind or the
/// fade-in setting changes.
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub(super) fn prepare_chunks(
    mut commands: Commands,
    mut chunks: Query<(Entity, &ExtractedChunk, Option<&mut GpuChunk>)>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    bindings: Res<ChunkBindings>,
    cache: Res<PipelineCache>,
    textures: ChunkTextures,
    wind: Option<Res<RwtWind>>,
    fade: Option<Res<RwtFadeIn>>,
    mut slab: ResMut<InstanceSlab>,
) {
    let wind = wind.map(|w| *w).unwrap_or_default();
    let fade = fade.map(|f| *f).unwrap_or_default();
    slab.keep_only(|e| chunks.contains(e));
    for (entity, chunk, gpu) in &mut chunks {
        let mut uniform = chunk.uniform;
        uniform.wind_direction = wind.direction;
        uniform.wind_strength = wind.strength;
        uniform.wind_frequency = wind.frequency;
        uniform.wind_speed = wind.speed;
        if !fade.0 {
            uniform.lod.falloff_on = 0;
        }
        let texture = textures.of(chunk);
        match gpu {
            Some(mut gpu)
                if Arc::ptr_eq(&gpu.source, &chunk.buffer)
                    && (gpu.own.is_some() || slab.range(entity).is_some()) =>
            {
                if gpu.uniform != uniform {
                    queue.write_buffer(&gpu.uniform_buffer, 0, &uniform_bytes(&uniform));
                    gpu.uniform = uniform;
                }
                if gpu.texture_view != texture.texture_view.id() {
                    gpu.bind_group =
                        bind_chunk(&device, &bindings, &cache, &gpu.uniform_buffer, texture);
                    gpu.texture_view = texture.texture_view.id();
                }
            }
            _ => {
                let own = (!slab.place(entity, &chunk.buffer.instances, &device, &queue))
                    .then(|| own_buffer(&device, chunk));
                let gpu = upload(&device, &bindings, &cache, (chunk, uniform), texture, own);
                commands.entity(entity).insert(gpu);
            }
        }
    }
    slab.shrink_to_fit(&device, &queue);
}

/// A buffer of `chunk`'s instances alone, where the slab cannot hold them.
fn own_buffer(device: &RenderDevice, chunk: &ExtractedChunk) -> Buffer {
    device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("rwt_instances"),
        contents: bytemuck::cast_slice(&chunk.buffer.instances),
        usage: BufferUsages::VERTEX,
    })
}

/// The GPU resources of one chunk, its instances placed already (`own`: in a buffer of
/// their own).
fn upload(
    device: &RenderDevice,
    bindings: &ChunkBindings,
    cache: &PipelineCache,
    (chunk, uniform): (&ExtractedChunk, ChunkUniform),
    texture: &GpuImage,
    own: Option<Buffer>,
) -> GpuChunk {
    let uniform_buffer = device.create_buffer_with_data(&BufferInitDescriptor {
        label: Some("rwt_instanced_chunk"),
        contents: &uniform_bytes(&uniform),
        usage: BufferUsages::UNIFORM | BufferUsages::COPY_DST,
    });
    GpuChunk {
        source: chunk.buffer.clone(),
        own,
        count: chunk.buffer.instances.len() as u32,
        uniform,
        bind_group: bind_chunk(device, bindings, cache, &uniform_buffer, texture),
        uniform_buffer,
        texture_view: texture.texture_view.id(),
    }
}

/// A chunk's bind group: its uniform, the frame's, the bend field, its texture.
fn bind_chunk(
    device: &RenderDevice,
    bindings: &ChunkBindings,
    cache: &PipelineCache,
    uniform: &Buffer,
    texture: &GpuImage,
) -> BindGroup {
    device.create_bind_group(
        "rwt_instanced_chunk",
        &cache.get_bind_group_layout(&bindings.layout),
        &BindGroupEntries::sequential((
            uniform.as_entire_binding(),
            bindings.frame.as_entire_binding(),
            &bindings.bend_view,
            &bindings.bend_sampler,
            &texture.texture_view,
            &texture.sampler,
        )),
    )
}

/// What choosing a chunk's pipeline reads: the pipelines of specializer `S`, the meshes,
/// and the meshes already reported as undrawable.
#[derive(bevy::ecs::system::SystemParam)]
pub(super) struct ChunkPipelines<'w, S: SpecializedMeshPipeline + Resource>
where
    S::Key: Send + Sync,
{
    specializer: Option<Res<'w, S>>,
    pipelines: ResMut<'w, SpecializedMeshPipelines<S>>,
    cache: Res<'w, PipelineCache>,
    meshes: Res<'w, RenderAssets<RenderMesh>>,
    reported: ResMut<'w, ReportedMeshes>,
}

impl<S: SpecializedMeshPipeline + Resource> ChunkPipelines<'_, S>
where
    S::Key: Send + Sync,
{
    /// The pipeline drawing `chunk` under the key `key` makes of the mesh's topology bits,
    /// or `None` (the reason logged once when the mesh cannot be drawn; nothing while the
    /// mesh or the specializer is not ready).
    fn of(
        &mut self,
        chunk: &ExtractedChunk,
        key: impl FnOnce(MeshPipelineKey) -> S::Key,
    ) -> Option<CachedRenderPipelineId> {
        let specializer = self.specializer.as_deref()?;
        let mesh = self.meshes.get(chunk.mesh)?;
        let topology = MeshPipelineKey::from_primitive_topology_and_strip_index(
            mesh.primitive_topology(),
            mesh.index_format(),
        );
        let specialized = check_topology(mesh.primitive_topology())
            .map_err(|e| e.to_string())
            .and_then(|()| {
                self.pipelines
                    .specialize(&self.cache, specializer, key(topology), &mesh.layout)
                    .map_err(|e| e.to_string())
            });
        specialized
            .map_err(|e| self.reported.once(chunk.mesh, &e))
            .ok()
    }
}

/// Bins into each camera view's phase the chunks its CPU culling kept (by their `Aabb`)
/// that `item` makes an item of under the view's key (`key_of`; none binned while a view
/// has no key), and takes out what the views no longer show.
fn rebin_cameras<P: BinnedPhaseItem, K: Copy>(
    phases: &mut ViewBinnedRenderPhases<P>,
    queued: &mut Queued<P>,
    views: &Query<(&ExtractedView, &RenderVisibleEntities)>,
    key_of: impl Fn(&RetainedViewEntity) -> Option<K>,
    mut item: impl FnMut(K, Entity, MainEntity) -> Option<BinnedChunk<P>>,
) {
    for (view, visible) in views {
        let Some(phase) = phases.get_mut(&view.retained_view_entity) else {
            continue;
        };
        let key = key_of(&view.retained_view_entity);
        let visible = visible
            .get::<InstancedChunk>()
            .map(|v| v.entities_cpu_culling.as_slice())
            .unwrap_or_default();
        let items: Vec<_> = visible
            .iter()
            .filter_map(|&(entity, main_entity)| item(key?, entity, main_entity))
            .collect();
        queued.rebin_phase(view.retained_view_entity, phase, items);
    }
    queued.end_frame();
}
