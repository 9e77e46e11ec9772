//! Culling per instance on the GPU ([`InstanceCulling`]).
//!
//! After queueing, each (view, chunk) binned into any of the view's phases gets one compute
//! dispatch (`cull.wgsl`): each instance is tested against the view and, when it may be
//! seen, copied into the frame's pool of kept instances, and counted in the draw's indirect
//! arguments. The chunk's draws in that view then read their instances from the pool and
//! their count from the arguments ([`CulledDraw`]). The compute work is submitted before
//! the frame's passes, so every pass of the view (prepasses, main pass, shadow map) reads
//! what it wrote. A chunk without a culled draw (culling off, the adapter unable, the pool
//! full) is drawn directly, whole.

use super::draw::MeshSlices;
use super::{ExtractedChunk, GpuChunk, MainViewer, Queued};
#[cfg(any(test, feature = "testing"))]
use crate::instancing::GpuInstance;
use crate::instancing::{GPU_BYTES_PER_INSTANCE, InstanceCulling};
use crate::look::InstancedShadows;
use bevy::camera::primitives::Frustum;
use bevy::core_pipeline::core_3d::Opaque3d;
use bevy::core_pipeline::prepass::Opaque3dPrepass;
use bevy::pbr::{LightEntity, Shadow};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::mesh::RenderMesh;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::binding_types::{
    storage_buffer_read_only_sized, storage_buffer_sized, uniform_buffer,
};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderAdapter, RenderDevice, RenderQueue};
use bevy::render::sync_world::MainEntity;
use bevy::render::view::{ExtractedView, RetainedViewEntity};
use std::num::NonZero;
use std::ops::Range;

/// Invocations per workgroup (`cull.wgsl`'s `workgroup_size`).
const WORKGROUP: u32 = 64;
/// Words of one draw's indirect arguments (indexed: count, instances, first index, base
/// vertex, first instance; direct draws read the first four the same way).
pub(super) const ARGS_WORDS: u32 = 5;
/// Bytes of one instance.
const INSTANCE_BYTES: u64 = GPU_BYTES_PER_INSTANCE as u64;

/// One dispatch's settings, as `cull.wgsl` reads them.
#[derive(Clone, Copy, Debug, ShaderType)]
pub(super) struct CullUniform {
    /// The view's half-spaces (normal, distance).
    planes: [Vec4; 6],
    /// Chunk corner (xyz), reach of an instance of scale 1 (w).
    origin: Vec4,
    /// Where the level of detail is measured from (xyz); the shadow distance (w, negative:
    /// none).
    eye: Vec4,
    /// Fall-off near, far, 1 when the fade is on, floor.
    falloff: Vec4,
    /// Fade band (x).
    fade: Vec4,
    /// Far thinning: its distance, its floor, 1 when on.
    thinning: Vec4,
    /// Instances, the word of the draw's instance count, workgroups along x.
    slots: UVec4,
}

#[cfg(any(test, feature = "testing"))]
impl CullUniform {
    /// Whether `instance` may be seen: `cull.wgsl`'s test, on the CPU.
    pub(super) fn keeps(&self, instance: &GpuInstance) -> bool {
        let root = self.origin.truncate() + Vec3::from(instance.offset);
        let appear = f32::from(instance.appear) / 65535.0;
        let kept = self.kept_fraction(root);
        let scale = instance.scale * self.growth(root, appear, kept);
        if scale <= 0.0 {
            return false;
        }
        let radius = self.origin.w * scale / kept;
        if self.eye.w >= 0.0 && root.distance(self.eye.truncate()) - radius > self.eye.w {
            return false;
        }
        self.planes
            .iter()
            .all(|p| p.truncate().dot(root) + p.w + radius > 0.0)
    }

    /// `cull.wgsl`'s fraction kept by far thinning.
    fn kept_fraction(&self, root: Vec3) -> f32 {
        if self.thinning.z == 0.0 {
            return 1.0;
        }
        let ratio = self.thinning.x / (root.xz() - self.eye.xz()).length().max(1e-3);
        (ratio * ratio).clamp(self.thinning.y, 1.0)
    }

    /// `cull.wgsl`'s growth.
    fn growth(&self, root: Vec3, appear: f32, kept: f32) -> f32 {
        let band = self.fade.x;
        let thinned = ((kept * (1.0 + band) - appear) / band).clamp(0.0, 1.0);
        if self.falloff.z == 0.0 {
            return thinned;
        }
        let distance = (root.xz() - self.eye.xz()).length();
        let span = (self.falloff.y - self.falloff.x).max(1e-3);
        let near = (1.0 - (distance - self.falloff.x) / span).clamp(0.0, 1.0);
        let factor = self.falloff.w.max(near);
        ((factor - appear) / band).clamp(0.0, 1.0) * thinned
    }
}

/// Where one chunk's culled draw in one view reads: its arguments (a byte offset into
/// [`InstanceCuller::args`]) and its kept instances (a byte range of the pool).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::instancing) struct CulledDraw {
    pub args: u64,
    pub kept: Range<u64>,
}

/// A chunk's cull bind group, and the buffers it was made with.
struct ChunkCull {
    made_with: [BufferId; 4],
    kept_binding: u64,
    bind_group: BindGroup,
}

/// The culling pass: its pipeline, this frame's buffers and the culled draws.
#[derive(Resource)]
pub(in crate::instancing) struct InstanceCuller {
    /// The pipeline, where the adapter runs compute shaders and indirect draws.
    pipeline: Option<CachedComputePipelineId>,
    layout: BindGroupLayoutDescriptor,
    uniforms: DynamicUniformBuffer<CullUniform>,
    /// The pool of kept instances.
    kept: Option<Buffer>,
    /// Every draw's indirect arguments.
    args: Option<Buffer>,
    chunks: HashMap<Entity, ChunkCull>,
    /// This frame's culled draws, by (view, chunk) render entity.
    draws: HashMap<(Entity, Entity), CulledDraw>,
    /// This frame's dispatches, in the order of their arguments, for the check.
    #[cfg(feature = "testing")]
    checked: Vec<super::cull_check::Checked>,
}

impl InstanceCuller {
    /// The culled draw of `chunk` in `view` this frame, with the buffers it reads.
    pub fn draw(&self, view: Entity, chunk: Entity) -> Option<(&CulledDraw, &Buffer, &Buffer)> {
        let draw = self.draws.get(&(view, chunk))?;
        Some((draw, self.kept.as_ref()?, self.args.as_ref()?))
    }

    /// This frame's dispatches (uniform and instances), in the order of their arguments.
    #[cfg(feature = "testing")]
    pub(super) fn checked(&self) -> &[super::cull_check::Checked] {
        &self.checked
    }

    /// The indirect arguments.
    #[cfg(feature = "testing")]
    pub(super) fn args(&self) -> Option<&Buffer> {
        self.args.as_ref()
    }
}

pub(in crate::instancing) fn init_culler(
    mut commands: Commands,
    device: Res<RenderDevice>,
    adapter: Res<RenderAdapter>,
    asset_server: Res<AssetServer>,
    cache: Res<PipelineCache>,
) {
    let layout = BindGroupLayoutDescriptor::new(
        "rwt_cull",
        &BindGroupLayoutEntries::sequential(
            ShaderStages::COMPUTE,
            (
                storage_buffer_read_only_sized(false, None),
                uniform_buffer::<CullUniform>(true),
                storage_buffer_sized(true, NonZero::new(INSTANCE_BYTES)),
                storage_buffer_sized(false, None),
            ),
        ),
    );
    let pipeline = culls_on(&device, &adapter).then(|| {
        cache.queue_compute_pipeline(ComputePipelineDescriptor {
            label: Some("rwt_cull".into()),
            layout: vec![layout.clone()],
            shader: bevy::asset::load_embedded_asset!(asset_server.as_ref(), "cull.wgsl"),
            entry_point: Some("cull_instances".into()),
            ..default()
        })
    });
    commands.insert_resource(InstanceCuller {
        pipeline,
        layout,
        uniforms: DynamicUniformBuffer::default(),
        kept: None,
        args: None,
        chunks: HashMap::default(),
        draws: HashMap::default(),
        #[cfg(feature = "testing")]
        checked: Vec::new(),
    });
}

/// Whether the adapter runs the culling pass: compute shaders (not WebGL2-class adapters,
/// nor limits that emulate them), indirect draws, and storage buffers enough.
fn culls_on(device: &RenderDevice, adapter: &RenderAdapter) -> bool {
    let limits = device.limits();
    let flags = adapter.get_downlevel_capabilities().flags;
    flags.contains(DownlevelFlags::COMPUTE_SHADERS | DownlevelFlags::INDIRECT_EXECUTION)
        && limits.max_compute_workgroup_size_x >= WORKGROUP
        && limits.max_compute_invocations_per_workgroup >= WORKGROUP
        && limits.max_storage_buffers_per_shader_stage >= 3
        && limits.max_dynamic_storage_buffers_per_pipeline_layout >= 1
}

/// How each view culls: its half-spaces, and where its level of detail is measured from.
#[derive(Clone, Copy)]
struct ViewCull {
    entity: Entity,
    planes: [Vec4; 6],
    eye: Vec3,
    shadow: bool,
}

/// One dispatch: a chunk in a view.
struct Dispatch<'a> {
    view: ViewCull,
    chunk: Entity,
    extracted: &'a ExtractedChunk,
    gpu: &'a GpuChunk,
    /// The draw's arguments before culling (the instance count 0).
    args: [u32; ARGS_WORDS as usize],
}

/// What the culling pass reads of the render world.
#[derive(bevy::ecs::system::SystemParam)]
pub(in crate::instancing) struct CullInputs<'w, 's> {
    setting: Option<Res<'w, InstanceCulling>>,
    main: Res<'w, Queued<Opaque3d>>,
    prepass: Res<'w, Queued<Opaque3dPrepass>>,
    shadow: Res<'w, Queued<Shadow>>,
    views: Query<
        'w,
        's,
        (
            Entity,
            &'static ExtractedView,
            Option<&'static Frustum>,
            Has<LightEntity>,
        ),
    >,
    chunks: Query<
        'w,
        's,
        (
            Entity,
            &'static MainEntity,
            &'static ExtractedChunk,
            &'static GpuChunk,
        ),
    >,
    meshes: Res<'w, RenderAssets<RenderMesh>>,
    allocator: Res<'w, MeshAllocator>,
    viewer: Res<'w, MainViewer>,
}

/// Culls the instances of every chunk binned into every view, and submits the work before
/// the frame's passes.
pub(in crate::instancing) fn cull_instances(
    mut culler: ResMut<InstanceCuller>,
    inputs: CullInputs,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    cache: Res<PipelineCache>,
) {
    culler.draws.clear();
    #[cfg(feature = "testing")]
    culler.checked.clear();
    let on = inputs.setting.as_deref().copied().unwrap_or_default() != InstanceCulling::PerChunk;
    let Some(pipeline) = culler.pipeline.filter(|_| on) else {
        return;
    };
    let Some(pipeline) = cache.get_compute_pipeline(pipeline) else {
        return;
    };
    let dispatches = inputs.dispatches();
    if dispatches.is_empty() {
        return;
    }
    let culler = culler.as_mut();
    let Some(mut offsets) = culler.lay_out(&dispatches, &device) else {
        return;
    };
    culler.write(&dispatches, &mut offsets, &device, &queue);
    culler.bind(&dispatches, &device, &cache);
    let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor {
        label: Some("rwt_cull"),
    });
    {
        let mut pass = encoder.begin_compute_pass(&ComputePassDescriptor {
            label: Some("rwt_cull"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        for (d, o) in dispatches.iter().zip(&offsets) {
            let Some(chunk) = culler.chunks.get(&d.chunk) else {
                continue;
            };
            pass.set_bind_group(0, &chunk.bind_group, &[o.uniform, o.kept as u32]);
            let (x, y) = workgroups(d.gpu.count);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
    queue.submit([encoder.finish()]);
    for (d, o) in dispatches.iter().zip(offsets) {
        #[cfg(feature = "testing")]
        culler
            .checked
            .push((uniform(d, &o), d.extracted.buffer.clone()));
        if !culler.chunks.contains_key(&d.chunk) {
            // Not dispatched (no bind group): its arguments count nothing; drawn whole.
            continue;
        }
        let kept = o.kept..o.kept + u64::from(d.gpu.count) * INSTANCE_BYTES;
        let args = u64::from(o.draw * ARGS_WORDS * 4);
        culler
            .draws
            .insert((d.view.entity, d.chunk), CulledDraw { args, kept });
    }
}

/// Workgroups covering `count` instances (x, y): at most 65 535 along x.
fn workgroups(count: u32) -> (u32, u32) {
    let groups = count.div_ceil(WORKGROUP).max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}

/// Where one dispatch's data lies: its uniform, its kept instances (bytes), its draw.
struct Offsets {
    uniform: u32,
    kept: u64,
    draw: u32,
}

impl CullInputs<'_, '_> {
    /// Every (view, chunk) binned this frame, once each, in a stable order.
    fn dispatches(&self) -> Vec<Dispatch<'_>> {
        let views: HashMap<RetainedViewEntity, ViewCull> = self
            .views
            .iter()
            .map(|(entity, view, frustum, shadow)| {
                let eye = match (shadow, self.viewer.0) {
                    (true, Some(eye)) => eye,
                    _ => view.world_from_view.translation(),
                };
                let planes =
                    frustum.map_or([Vec4::W; 6], |f| f.0.half_spaces.map(|h| h.normal_d()));
                let cull = ViewCull {
                    entity,
                    planes,
                    eye,
                    shadow,
                };
                (view.retained_view_entity, cull)
            })
            .collect();
        let chunks: HashMap<MainEntity, _> = self
            .chunks
            .iter()
            .map(|(entity, main, extracted, gpu)| (*main, (entity, extracted, gpu)))
            .collect();
        let mut pairs: Vec<(ViewCull, Entity, &ExtractedChunk, &GpuChunk)> = Vec::new();
        let binned = self
            .main
            .binned()
            .chain(self.prepass.binned())
            .chain(self.shadow.binned());
        for (retained, binned) in binned {
            let Some(view) = views.get(retained) else {
                continue;
            };
            for main in binned {
                if let Some(&(entity, extracted, gpu)) = chunks.get(main) {
                    pairs.push((*view, entity, extracted, gpu));
                }
            }
        }
        pairs.sort_by_key(|(view, chunk, ..)| (view.entity, *chunk));
        pairs.dedup_by_key(|(view, chunk, ..)| (view.entity, *chunk));
        pairs
            .into_iter()
            .filter(|(.., gpu)| gpu.count > 0)
            .filter_map(|(view, chunk, extracted, gpu)| {
                let args = self.args(extracted)?;
                Some(Dispatch {
                    view,
                    chunk,
                    extracted,
                    gpu,
                    args,
                })
            })
            .collect()
    }

    /// A chunk's draw arguments before culling, as the direct draw would give them.
    fn args(&self, chunk: &ExtractedChunk) -> Option<[u32; ARGS_WORDS as usize]> {
        MeshSlices::of(&self.meshes, &self.allocator, chunk.mesh).map(|s| s.args)
    }
}

impl InstanceCuller {
    /// Places each dispatch's kept instances in the pool (at the storage offset alignment)
    /// and makes the pool and argument buffers large enough; `None` when the pool would
    /// pass the device's largest buffer (the frame draws directly).
    fn lay_out(&mut self, dispatches: &[Dispatch], device: &RenderDevice) -> Option<Vec<Offsets>> {
        let limits = device.limits();
        let align = u64::from(limits.min_storage_buffer_offset_alignment.max(4));
        let binding = self.kept_binding(dispatches);
        if binding > limits.max_storage_buffer_binding_size {
            warn_once!(
                "rwt: a chunk holds more instances than a GPU binding; drawing chunks whole"
            );
            return None;
        }
        let mut offsets = Vec::with_capacity(dispatches.len());
        let mut end = 0u64;
        for (i, d) in dispatches.iter().enumerate() {
            let kept = end.next_multiple_of(align);
            end = kept + u64::from(d.gpu.count) * INSTANCE_BYTES;
            offsets.push(Offsets {
                uniform: 0,
                kept,
                draw: i as u32,
            });
        }
        let last = offsets.last().map_or(0, |o| o.kept);
        let size = (last + binding).max(end);
        if size > limits.max_buffer_size || last > u64::from(u32::MAX) {
            warn_once!(
                "rwt: the instances kept by culling pass the GPU's largest buffer; drawing chunks whole"
            );
            return None;
        }
        grow(
            &mut self.kept,
            device,
            size,
            "rwt_kept_instances",
            BufferUsages::VERTEX | BufferUsages::STORAGE,
        );
        let args = dispatches.len() as u64 * u64::from(ARGS_WORDS) * 4;
        // Copied from by the check (`testing`).
        let usage = BufferUsages::INDIRECT
            | BufferUsages::STORAGE
            | BufferUsages::COPY_DST
            | BufferUsages::COPY_SRC;
        grow(&mut self.args, device, args, "rwt_cull_args", usage);
        Some(offsets)
    }

    /// The size every chunk's binding of the pool has: the largest chunk's instances.
    fn kept_binding(&self, dispatches: &[Dispatch]) -> u64 {
        let most = dispatches.iter().map(|d| d.gpu.count).max().unwrap_or(1);
        let size = u64::from(most.max(1)) * INSTANCE_BYTES;
        // Grown in steps, so that bind groups are not made anew for every new largest chunk.
        size.next_power_of_two()
    }

    /// Writes the uniforms (their offsets into `offsets`) and the arguments.
    fn write(
        &mut self,
        dispatches: &[Dispatch],
        offsets: &mut [Offsets],
        device: &RenderDevice,
        queue: &RenderQueue,
    ) {
        self.uniforms.clear();
        let mut args = Vec::with_capacity(dispatches.len() * ARGS_WORDS as usize);
        for (d, o) in dispatches.iter().zip(offsets.iter_mut()) {
            o.uniform = self.uniforms.push(&uniform(d, o));
            args.extend_from_slice(&d.args);
        }
        self.uniforms.write_buffer(device, queue);
        if let Some(buffer) = &self.args {
            queue.write_buffer(buffer, 0, bytemuck::cast_slice(&args));
        }
    }

    /// Makes the bind group of each dispatched chunk whose buffers changed; forgets those of
    /// chunks not dispatched.
    fn bind(&mut self, dispatches: &[Dispatch], device: &RenderDevice, cache: &PipelineCache) {
        let (Some(kept), Some(args), Some(uniforms), Some(uniform)) = (
            &self.kept,
            &self.args,
            self.uniforms.buffer(),
            self.uniforms.binding(),
        ) else {
            return;
        };
        let binding = self.kept_binding(dispatches);
        let layout = cache.get_bind_group_layout(&self.layout);
        let mut chunks = HashMap::default();
        for d in dispatches {
            if chunks.contains_key(&d.chunk) {
                continue;
            }
            let made_with = [d.gpu.instances.id(), uniforms.id(), kept.id(), args.id()];
            let chunk = match self.chunks.remove(&d.chunk) {
                Some(c) if c.made_with == made_with && c.kept_binding == binding => c,
                _ => ChunkCull {
                    made_with,
                    kept_binding: binding,
                    bind_group: device.create_bind_group(
                        "rwt_cull",
                        &layout,
                        &BindGroupEntries::sequential((
                            d.gpu.instances.as_entire_binding(),
                            uniform.clone(),
                            BufferBinding {
                                buffer: kept,
                                offset: 0,
                                size: NonZero::new(binding),
                            },
                            args.as_entire_binding(),
                        )),
                    ),
                },
            };
            chunks.insert(d.chunk, chunk);
        }
        self.chunks = chunks;
    }
}

/// Makes `buffer` anew, of at least `size` bytes (grown by halves), when it is smaller.
fn grow(
    buffer: &mut Option<Buffer>,
    device: &RenderDevice,
    size: u64,
    label: &str,
    usage: BufferUsages,
) {
    if buffer.as_ref().is_some_and(|b| b.size() >= size) {
        return;
    }
    let size = (size + size / 2).next_multiple_of(256);
    *buffer = Some(device.create_buffer(&BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    }));
}

/// The uniform of one dispatch.
fn uniform(d: &Dispatch, o: &Offsets) -> CullUniform {
    let u = &d.gpu.uniform;
    let shadow_distance = match (d.view.shadow, d.extracted.shadows) {
        (true, InstancedShadows::Within(distance)) => distance,
        _ => -1.0,
    };
    let (x, _) = workgroups(d.gpu.count);
    CullUniform {
        planes: d.view.planes,
        origin: Vec3::from_slice(&u.origin).extend(d.extracted.reach),
        eye: d.view.eye.extend(shadow_distance),
        falloff: Vec4::from_array(u.falloff),
        fade: Vec4::new(u.params[3], 0.0, 0.0, 0.0),
        thinning: Vec4::from_array(u.thinning),
        slots: UVec4::new(d.gpu.count, o.draw * ARGS_WORDS + 1, x, 0),
    }
}

#[cfg(test)]
mod tests {
    use super::super::reach;
    use super::super::shader_check::{bare_cache, struct_layout};
    use super::*;
    use bevy::asset::uuid::Uuid;
    use bevy::camera::primitives::Aabb;
    use bevy::render::render_resource::encase::UniformBuffer;
    use bevy::shader::Shader;

    #[test]
    fn the_cull_shader_validates_and_reads_the_uniform_as_rust_writes_it() {
        let mut cache = bare_cache();
        let id = AssetId::from(Uuid::from_u128(7));
        cache.set_shader(
            id,
            Shader::from_wgsl(include_str!("cull.wgsl"), "cull.wgsl"),
        );
        let types = cache
            .get(0, id, &[])
            .expect("cull.wgsl composes and validates");
        // Each member's first word marked, then found in encase's bytes.
        let marked = CullUniform {
            planes: [Vec4::new(1.0, 0.0, 0.0, 0.0); 6],
            origin: Vec4::new(2.0, 0.0, 0.0, 0.0),
            eye: Vec4::new(3.0, 0.0, 0.0, 0.0),
            falloff: Vec4::new(4.0, 0.0, 0.0, 0.0),
            fade: Vec4::new(5.0, 0.0, 0.0, 0.0),
            thinning: Vec4::new(7.0, 0.0, 0.0, 0.0),
            slots: UVec4::new(6, 0, 0, 0),
        };
        let mut bytes = UniformBuffer::new(Vec::<u8>::new());
        bytes.write(&marked).expect("encase writes it");
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(bytes.as_ref());
        let at = |word: u32| 4 * words.iter().position(|w| *w == word).expect("a marker");
        let ours: Vec<(String, usize)> = [
            ("planes", at(1.0f32.to_bits())),
            ("origin", at(2.0f32.to_bits())),
            ("eye", at(3.0f32.to_bits())),
            ("falloff", at(4.0f32.to_bits())),
            ("fade", at(5.0f32.to_bits())),
            ("thinning", at(7.0f32.to_bits())),
            ("slots", at(6)),
        ]
        .into_iter()
        .map(|(n, o)| (n.to_string(), o))
        .collect();
        let size = CullUniform::min_size().get() as usize;
        assert_eq!(struct_layout(&types, "Cull"), (ours, size));
    }

    /// An instance at `offset` (from the chunk corner) of scale 1.
    fn at(offset: Vec3, appear: f32) -> GpuInstance {
        GpuInstance {
            offset: offset.to_array(),
            scale: 1.0,
            appear: (appear * 65535.0) as u16,
            ..default()
        }
    }

    #[test]
    fn an_instance_is_kept_where_its_sphere_meets_the_view_and_it_has_grown() {
        // A view looking down +x from the origin: half-spaces x > 0 and |z| < x.
        let planes = [
            Vec4::new(1.0, 0.0, 0.0, 0.0),
            Vec4::new(1.0, 0.0, 1.0, 0.0).normalize(),
            Vec4::new(1.0, 0.0, -1.0, 0.0).normalize(),
            Vec4::W,
            Vec4::W,
            Vec4::W,
        ];
        let uniform = CullUniform {
            planes,
            origin: Vec4::new(0.0, 0.0, 0.0, 0.5),
            eye: Vec4::new(0.0, 0.0, 0.0, -1.0),
            falloff: Vec4::new(10.0, 20.0, 1.0, 0.0),
            fade: Vec4::new(0.1, 0.0, 0.0, 0.0),
            thinning: Vec4::ZERO,
            slots: UVec4::ZERO,
        };
        assert!(uniform.keeps(&at(Vec3::new(5.0, 0.0, 0.0), 0.5)));
        // Behind the eye, or beside the view by more than its reach: culled.
        assert!(!uniform.keeps(&at(Vec3::new(-1.0, 0.0, 0.0), 0.0)));
        assert!(!uniform.keeps(&at(Vec3::new(3.0, 0.0, 4.0), 0.0)));
        // Beside it by less than its reach: kept.
        assert!(uniform.keeps(&at(Vec3::new(3.0, 0.0, 3.3), 0.0)));
        // At 15 m the factor is 0.5: the instances of rank above it have not grown.
        assert!(uniform.keeps(&at(Vec3::new(15.0, 0.0, 0.0), 0.45)));
        assert!(!uniform.keeps(&at(Vec3::new(15.0, 0.0, 0.0), 0.55)));
        // Without the fade every rank is drawn.
        let no_fade = CullUniform {
            falloff: Vec4::ZERO,
            ..uniform
        };
        assert!(no_fade.keeps(&at(Vec3::new(15.0, 0.0, 0.0), 0.95)));
        // In a shadow view, beyond the class's shadow distance from the camera: culled.
        let shadow = CullUniform {
            eye: Vec4::new(0.0, 0.0, 0.0, 8.0),
            ..no_fade
        };
        assert!(shadow.keeps(&at(Vec3::new(8.4, 0.0, 0.0), 0.0)));
        assert!(!shadow.keeps(&at(Vec3::new(8.6, 0.0, 0.0), 0.0)));
        // Thinned from 20 m: at 40 m a quarter is kept, the lowest ranks; nearer, all.
        let thinned = CullUniform {
            thinning: Vec4::new(20.0, 0.1, 1.0, 0.0),
            ..no_fade
        };
        assert!(thinned.keeps(&at(Vec3::new(40.0, 0.0, 0.0), 0.2)));
        assert!(!thinned.keeps(&at(Vec3::new(40.0, 0.0, 0.0), 0.3)));
        assert!(thinned.keeps(&at(Vec3::new(15.0, 0.0, 0.0), 0.99)));
        // Down to the floor, however far.
        assert!(thinned.keeps(&at(Vec3::new(900.0, 0.0, 0.0), 0.09)));
        assert!(!thinned.keeps(&at(Vec3::new(900.0, 0.0, 0.0), 0.13)));
        // A widened instance is kept by a view it reaches into only widened (a fraction of
        // a quarter at 40 m: four times as wide).
        let beside = Vec3::new(40.0, 0.0, 40.0 + 1.2 * std::f32::consts::SQRT_2);
        assert!(thinned.keeps(&at(beside, 0.0)));
        assert!(!no_fade.keeps(&at(beside, 0.0)));
    }

    #[test]
    fn the_reach_holds_every_vertex_turned_tilted_and_swaying() {
        // A blade 0.1 wide and 0.7 tall; instances up to 1.5 times its size.
        let (mesh_lo, mesh_hi) = (Vec3::new(-0.05, 0.0, -0.01), Vec3::new(0.05, 0.7, 0.04));
        let roots = (Vec3::new(0.0, -2.0, 0.0), Vec3::new(16.0, 3.0, 16.0));
        let max_scale = 1.5;
        // The chunk's bounds as `InstancedChunk::aabb` makes them.
        let reach_xz = mesh_lo.abs().max(mesh_hi.abs());
        let across = reach_xz.x.max(reach_xz.z) * std::f32::consts::SQRT_2;
        let horizontal = (across + reach_xz.y) * max_scale;
        let below = (mesh_lo.y.min(0.0) - across) * max_scale;
        let local = Aabb::from_min_max(
            roots.0 + Vec3::new(-horizontal, below, -horizontal),
            roots.1 + Vec3::new(horizontal, mesh_hi.y * max_scale, horizontal),
        );
        let r = reach(&local, roots, max_scale, true);
        let corners = (0..8).map(|i| {
            let pick = |bit: u32, lo: f32, hi: f32| if i >> bit & 1 == 1 { hi } else { lo };
            Vec3::new(
                pick(0, mesh_lo.x, mesh_hi.x),
                pick(1, mesh_lo.y, mesh_hi.y),
                pick(2, mesh_lo.z, mesh_hi.z),
            )
        });
        let corners: Vec<Vec3> = corners.collect();
        for k in 0..64u16 {
            // Tilted any way (up to 75 degrees), or upright and swaying by up to its height.
            let tilted = k % 2 == 1;
            let up = Vec3::new((k as f32 * 0.7).sin(), 1.0, (k as f32 * 1.3).cos()).normalize();
            let g = GpuInstance {
                yaw: k * 1021,
                tilt: if tilted { GpuInstance::pack_up(up) } else { 0 },
                ..default()
            };
            let sway = if tilted {
                Vec3::ZERO
            } else {
                Vec3::X * mesh_hi.y
            };
            for &c in &corners {
                let placed = g.rotation() * c + sway * (c.y / mesh_hi.y);
                assert!(placed.length() <= r, "{placed} beyond {r}");
            }
        }
        assert!(r < 2.0, "a reach of {r} culls nothing");
        assert_eq!(reach(&local, roots, max_scale, false), f32::MAX);
    }
}
