//! Preparation: the resources every chunk shares (the frame uniform, the bend field, the
//! bind group layout) and each chunk's own ([`GpuChunk`]: its instances in the slab or a
//! buffer of their own, its uniform, its bind group).

use super::extract::ExtractedChunk;
use super::slab::InstanceSlab;
use super::uniforms::{ChunkUniform, FrameUniform, uniform_bytes};
use crate::instancing::bend::{BEND_FIELD_TEXELS, BendField};
use crate::instancing::chunk::InstanceBuffer;
use crate::instancing::settings::{RwtFadeIn, RwtWind};
use crate::look::check_texture;
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::binding_types::{sampler, texture_2d, uniform_buffer_sized};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::texture::{FallbackImage, GpuImage};
use bevy::render::view::ExtractedView;
use std::sync::Arc;

/// Adds the instanced and culling shaders to the app's embedded assets, and the level of
/// detail they share (`rwt::fade`) to its shader library.
pub(in crate::instancing) fn embed_shader(app: &mut App) {
    bevy::shader::load_shader_library!(app, "fade.wgsl");
    bevy::asset::embedded_asset!(app, "instanced.wgsl");
    bevy::asset::embedded_asset!(app, "cull/cull.wgsl");
}

/// A chunk's GPU resources.
#[derive(Component)]
pub(in crate::instancing) struct GpuChunk {
    /// The main world's buffer these were made from.
    pub(super) source: Arc<InstanceBuffer>,
    /// The instances' own buffer, where [`InstanceSlab`] could not hold them (then drawn
    /// whole, never culled per instance); `None`: in the slab.
    pub(super) own: Option<Buffer>,
    pub(super) count: u32,
    pub(super) uniform: ChunkUniform,
    pub(super) uniform_buffer: Buffer,
    pub(super) bind_group: BindGroup,
    /// The texture views bound (the fallback's until a texture is ready).
    pub(super) texture_views: [TextureViewId; 5],
}

/// What every instanced pipeline shares: the shader and the layout of group 2 (the chunk's
/// uniform, the frame's, the bend field and its sampler, then five textures and their
/// samplers: base colour, and an asset's normal, metallic-roughness, emissive and occlusion
/// maps), and the shared resources.
#[derive(Resource, Clone)]
pub(in crate::instancing) struct ChunkBindings {
    pub(super) shader: Handle<Shader>,
    pub(super) layout: BindGroupLayoutDescriptor,
    pub(super) frame: Buffer,
    pub(super) bend: Texture,
    pub(super) bend_view: TextureView,
    pub(super) bend_sampler: Sampler,
}

/// The main camera's position as the shadow passes see it, and the shared frame uniform.
#[derive(Resource, Default)]
pub(in crate::instancing) struct MainViewer(pub(super) Option<Vec3>);

pub(in crate::instancing) fn init_bindings(
    mut commands: Commands,
    device: Res<RenderDevice>,
    asset_server: Res<AssetServer>,
) {
    let texture = || texture_2d(TextureSampleType::Float { filterable: true });
    let filtering = || sampler(SamplerBindingType::Filtering);
    let entries = BindGroupLayoutEntries::sequential(
        ShaderStages::VERTEX_FRAGMENT,
        (
            uniform_buffer_sized(false, None),
            uniform_buffer_sized(false, None),
            texture(),
            filtering(),
            texture(),
            filtering(),
            texture(),
            filtering(),
            texture(),
            filtering(),
            texture(),
            filtering(),
            texture(),
            filtering(),
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
pub(in crate::instancing) fn prepare_frame(
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
pub(in crate::instancing) struct ChunkTextures<'w> {
    images: Res<'w, RenderAssets<GpuImage>>,
    fallback: Res<'w, FallbackImage>,
}

impl ChunkTextures<'_> {
    /// The textures `chunk` binds: each where it is ready and drawable, the fallback image
    /// (white) otherwise.
    fn of(&self, chunk: &ExtractedChunk) -> [&GpuImage; 5] {
        chunk.textures.map(|texture| {
            texture
                .and_then(|id| self.images.get(id))
                .filter(|image| {
                    let d = &image.texture_descriptor;
                    check_texture(d.dimension, d.size.depth_or_array_layers, d.format).is_ok()
                })
                .unwrap_or(&self.fallback.d2)
        })
    }
}

/// The ids of the views of `textures`.
fn view_ids(textures: &[&GpuImage; 5]) -> [TextureViewId; 5] {
    textures.map(|t| t.texture_view.id())
}

/// Makes the GPU resources of new or changed chunks (and the bind group again when the
/// class's texture became ready or changed); updates the uniform when the wind or the
/// fade-in setting changes.
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub(in crate::instancing) fn prepare_chunks(
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
                if gpu.texture_views != view_ids(&texture) {
                    gpu.bind_group =
                        bind_chunk(&device, &bindings, &cache, &gpu.uniform_buffer, &texture);
                    gpu.texture_views = view_ids(&texture);
                }
            }
            _ => {
                let own = (!slab.place(entity, &chunk.buffer, &device, &queue))
                    .then(|| own_buffer(&device, chunk));
                let gpu = upload(&device, &bindings, &cache, (chunk, uniform), &texture, own);
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
    textures: &[&GpuImage; 5],
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
        bind_group: bind_chunk(device, bindings, cache, &uniform_buffer, textures),
        uniform_buffer,
        texture_views: view_ids(textures),
    }
}

/// A chunk's bind group: its uniform, the frame's, the bend field, its textures.
fn bind_chunk(
    device: &RenderDevice,
    bindings: &ChunkBindings,
    cache: &PipelineCache,
    uniform: &Buffer,
    textures: &[&GpuImage; 5],
) -> BindGroup {
    let [base, normal, metallic_roughness, emissive, occlusion] = textures;
    device.create_bind_group(
        "rwt_instanced_chunk",
        &cache.get_bind_group_layout(&bindings.layout),
        &BindGroupEntries::sequential((
            uniform.as_entire_binding(),
            bindings.frame.as_entire_binding(),
            &bindings.bend_view,
            &bindings.bend_sampler,
            &base.texture_view,
            &base.sampler,
            &normal.texture_view,
            &normal.sampler,
            &metallic_roughness.texture_view,
            &metallic_roughness.sampler,
            &emissive.texture_view,
            &emissive.sampler,
            &occlusion.texture_view,
            &occlusion.sampler,
        )),
    )
}
