//! Culling per instance on the GPU ([`InstanceCulling`]).
//!
//! After queueing, each (view, chunk) binned into any of the view's phases gets one compute
//! dispatch (`cull.wgsl`): each instance is tested against the view and, when it may be
//! seen, copied into the frame's pool of kept instances, and counted in the draw's indirect
//! arguments. The chunk's draws in that view then read their instances from the pool and
//! their count from the arguments ([`CulledDraw`]). The compute work is submitted before
//! the frame's passes, so every pass of the view (prepasses, main pass, shadow map) reads
//! what it wrote. A chunk without a culled draw (culling off, the adapter unable, the pool
//! full, or nothing culling could drop: [`whole`]) is drawn directly, whole.
//!
//! A camera with Bevy's `OcclusionCulling` and `DepthPrepass` also culls what its depth
//! pyramid hides, in two phases ([`occlusion`]): what last frame's depth hid is tested again
//! once this frame's early depth is reduced, and drawn from the late prepass on.

mod occlusion;
mod params;
#[cfg(test)]
mod tests;
mod whole;

pub(in crate::instancing) use occlusion::{cull_late, restore_early};
pub(super) use params::CullParams;

use super::draw::MeshSlices;
use super::{ExtractedChunk, GpuChunk, MainViewer, Queued};
#[cfg(test)]
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
    storage_buffer_read_only, storage_buffer_read_only_sized, storage_buffer_sized,
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

/// Where one culled draw reads: its arguments (a byte offset into
/// [`InstanceCuller::args`]) and its kept instances (a byte range of the pool).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::instancing) struct CulledRange {
    pub args: u64,
    pub kept: Range<u64>,
}

/// One chunk's culled draw in one view: the instances its early phase kept, and in a view
/// that occludes, those its late phase kept.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::instancing) struct CulledDraw {
    pub early: CulledRange,
    pub late: Option<CulledRange>,
}

/// A chunk's cull bind group, and the buffers it was made with.
struct ChunkCull {
    made_with: [BufferId; 5],
    kept_binding: u64,
    bind_group: BindGroup,
}

/// The culling pass: its pipeline, this frame's buffers and the culled draws.
#[derive(Resource)]
pub(in crate::instancing) struct InstanceCuller {
    /// The pipeline, where the adapter runs compute shaders and indirect draws.
    pipeline: Option<CachedComputePipelineId>,
    layout: BindGroupLayoutDescriptor,
    /// Each dispatch's settings, read through a dynamic offset. A storage buffer: lavapipe
    /// specialises a shader on the values of the uniforms its branches read and keeps
    /// every variant, so a uniform that varies by chunk compiled one per chunk, without
    /// end.
    params: DynamicStorageBuffer<CullParams>,
    /// The pool of kept instances.
    kept: Option<Buffer>,
    /// Whether the pool was made this frame and not yet cleared.
    fresh_pool: bool,
    /// Every draw's indirect arguments: the early block, then the late block.
    args: Option<Buffer>,
    /// One bit per instance of an occluding dispatch: hidden in the early phase.
    marks: Option<Buffer>,
    /// The early block put aside during the late prepass, then the early block with no
    /// instances ([`occlusion`]).
    phases: Option<Buffer>,
    /// The pyramids views occlude with.
    pyramids: occlusion::Pyramids,
    chunks: HashMap<Entity, ChunkCull>,
    /// This frame's culled draws, by (view, chunk) render entity.
    draws: HashMap<(Entity, Entity), CulledDraw>,
    /// This frame's late phase, by view.
    late: HashMap<Entity, occlusion::LateWork>,
    /// This frame's draws (records in each block of the arguments).
    draw_count: u32,
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

    /// This frame's dispatches (uniform, instances, whether it occludes), in the order of
    /// their arguments.
    #[cfg(feature = "testing")]
    pub(super) fn checked(&self) -> &[super::cull_check::Checked] {
        &self.checked
    }

    /// The indirect arguments.
    #[cfg(feature = "testing")]
    pub(super) fn args(&self) -> Option<&Buffer> {
        self.args.as_ref()
    }

    /// The pool of kept instances.
    #[cfg(feature = "testing")]
    pub(super) fn kept_pool(&self) -> Option<&Buffer> {
        self.kept.as_ref()
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
                storage_buffer_read_only::<CullParams>(true),
                storage_buffer_sized(true, NonZero::new(INSTANCE_BYTES)),
                storage_buffer_sized(false, None),
                storage_buffer_sized(false, None),
            ),
        ),
    );
    let pyramids = occlusion::Pyramids::new(&device);
    let pipeline = culls_on(&device, &adapter).then(|| {
        cache.queue_compute_pipeline(ComputePipelineDescriptor {
            label: Some("rwt_cull".into()),
            layout: vec![layout.clone(), pyramids.layout().clone()],
            shader: bevy::asset::load_embedded_asset!(asset_server.as_ref(), "cull.wgsl"),
            entry_point: Some("cull_instances".into()),
            ..default()
        })
    });
    commands.insert_resource(InstanceCuller {
        pipeline,
        layout,
        params: DynamicStorageBuffer::default(),
        kept: None,
        fresh_pool: false,
        args: None,
        marks: None,
        phases: None,
        pyramids,
        chunks: HashMap::default(),
        draws: HashMap::default(),
        late: HashMap::default(),
        draw_count: 0,
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
        && limits.max_storage_buffers_per_shader_stage >= 4
        && limits.max_dynamic_storage_buffers_per_pipeline_layout >= 1
}

/// How each view culls: its half-spaces, where its level of detail is measured from, and
/// how it occludes.
#[derive(Clone, Copy)]
struct ViewCull {
    entity: Entity,
    planes: [Vec4; 6],
    eye: Vec3,
    shadow: bool,
    occluding: Option<occlusion::Occluding>,
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

impl Dispatch<'_> {
    /// Last frame's and this frame's clip space from world space, where the dispatch
    /// occludes in two phases.
    fn occludes(&self) -> Option<(Mat4, Mat4)> {
        let occluding = self.view.occluding?;
        Some((occluding.previous?, occluding.current))
    }
}

/// What culling reads of a view: its frustum, whether it is a shadow view, its pyramid.
type ViewData = (
    Entity,
    &'static ExtractedView,
    Option<&'static Frustum>,
    Has<LightEntity>,
    occlusion::PyramidQuery,
);

/// What the culling pass reads of the render world.
#[derive(bevy::ecs::system::SystemParam)]
pub(in crate::instancing) struct CullInputs<'w, 's> {
    setting: Option<Res<'w, InstanceCulling>>,
    main: Res<'w, Queued<Opaque3d>>,
    prepass: Res<'w, Queued<Opaque3dPrepass>>,
    shadow: Res<'w, Queued<Shadow>>,
    views: Query<'w, 's, ViewData>,
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
    culler.late.clear();
    #[cfg(feature = "testing")]
    culler.checked.clear();
    let on = inputs.setting.as_deref().copied().unwrap_or_default() != InstanceCulling::PerChunk;
    let Some(pipeline) = culler.pipeline.filter(|_| on) else {
        return;
    };
    let Some(pipeline) = cache.get_compute_pipeline(pipeline) else {
        return;
    };
    let culler = culler.as_mut();
    let views = inputs
        .views
        .iter()
        .map(|(e, view, _, shadow, p)| (e, view, shadow, p));
    let occluding = culler.pyramids.prepare(views, &device, &cache);
    let dispatches = inputs.dispatches(&occluding);
    if dispatches.is_empty() {
        return;
    }
    let Some(mut offsets) = culler.lay_out(&dispatches, &device) else {
        return;
    };
    culler.write(&dispatches, &mut offsets, &device, &queue);
    culler.bind(&dispatches, &device, &cache);
    let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor {
        label: Some("rwt_cull"),
    });
    if let Some(marks) = &culler.marks {
        encoder.clear_buffer(marks, 0, None);
    }
    // wgpu zeroes the parts of a new buffer it has not seen written before their first use,
    // and it did not see the compute writes through dynamic offsets: a pool drawn the frame
    // it was made lost instances (readback). Cleared whole once, the pool counts as written.
    if let Some(kept) = culler.kept.as_ref().filter(|_| culler.fresh_pool) {
        encoder.clear_buffer(kept, 0, None);
        culler.fresh_pool = false;
    }
    culler.dispatch_early(&mut encoder, pipeline, &dispatches, &offsets);
    queue.submit([encoder.finish()]);
    culler.record(&dispatches, offsets);
}

impl InstanceCuller {
    /// Encodes the early phase (the only one, where the view does not occlude).
    fn dispatch_early(
        &self,
        encoder: &mut CommandEncoder,
        pipeline: &ComputePipeline,
        dispatches: &[Dispatch],
        offsets: &[Offsets],
    ) {
        let mut pass = encoder.begin_compute_pass(&ComputePassDescriptor {
            label: Some("rwt_cull"),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        let mut bound_view = None;
        for (d, o) in dispatches.iter().zip(offsets) {
            let (Some(chunk), Some(pyramid)) = (
                self.chunks.get(&d.chunk),
                self.pyramids.bind_group(d.view.entity),
            ) else {
                continue;
            };
            if bound_view != Some(d.view.entity) {
                pass.set_bind_group(1, pyramid, &[]);
                bound_view = Some(d.view.entity);
            }
            pass.set_bind_group(0, &chunk.bind_group, &[o.params, o.kept as u32]);
            let (x, y) = workgroups(d.gpu.count);
            pass.dispatch_workgroups(x, y, 1);
        }
    }

    /// Records this frame's culled draws and each occluding view's late phase.
    fn record(&mut self, dispatches: &[Dispatch], offsets: Vec<Offsets>) {
        self.draw_count = dispatches.len() as u32;
        for (d, o) in dispatches.iter().zip(offsets) {
            let bytes = u64::from(d.gpu.count) * INSTANCE_BYTES;
            #[cfg(feature = "testing")]
            self.checked.push(super::cull_check::Checked {
                params: params(d, &o),
                instances: d.extracted.buffer.clone(),
                occludes: o.late.is_some(),
                kept: o.kept..o.kept + bytes,
                late: o.late.as_ref().map(|l| l.kept..l.kept + bytes),
            });
            if !self.chunks.contains_key(&d.chunk) {
                // Not dispatched (no bind group): its arguments count nothing; drawn whole.
                continue;
            }
            let early = CulledRange {
                args: u64::from(o.draw * ARGS_WORDS * 4),
                kept: o.kept..o.kept + bytes,
            };
            let late = o.late.as_ref().map(|late| {
                self.late
                    .entry(d.view.entity)
                    .or_insert_with(|| occlusion::LateWork::new(o.draw))
                    .push(d.chunk, o.draw, late, d.gpu.count);
                CulledRange {
                    args: u64::from((self.draw_count + o.draw) * ARGS_WORDS * 4),
                    kept: late.kept..late.kept + bytes,
                }
            });
            self.draws
                .insert((d.view.entity, d.chunk), CulledDraw { early, late });
        }
    }
}

/// Workgroups covering `count` instances (x, y): at most 65 535 along x.
fn workgroups(count: u32) -> (u32, u32) {
    let groups = count.div_ceil(WORKGROUP).max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}

/// Where one dispatch's data lies: its settings, its kept instances (bytes), its draw; and
/// its late phase's, where it occludes.
struct Offsets {
    params: u32,
    kept: u64,
    draw: u32,
    late: Option<occlusion::LateOffsets>,
}

impl CullInputs<'_, '_> {
    /// Every (view, chunk) binned this frame, once each, in a stable order (a view's
    /// dispatches together).
    fn dispatches(&self, occluding: &HashMap<Entity, occlusion::Occluding>) -> Vec<Dispatch<'_>> {
        let views: HashMap<RetainedViewEntity, ViewCull> = self
            .views
            .iter()
            .map(|(entity, view, frustum, shadow, _)| {
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
                    occluding: occluding.get(&entity).copied(),
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
                if let Some(&(entity, extracted, gpu)) = chunks.get(&main) {
                    pairs.push((*view, entity, extracted, gpu));
                }
            }
        }
        pairs.sort_by_key(|(view, chunk, ..)| (view.entity, *chunk));
        pairs.dedup_by_key(|(view, chunk, ..)| (view.entity, *chunk));
        pairs
            .into_iter()
            .filter(|(.., gpu)| gpu.count > 0)
            .filter(|(view, _, extracted, gpu)| {
                whole::may_drop(view, &extracted.bounds, &gpu.uniform, extracted.shadows)
            })
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
    /// Places each dispatch's kept instances in the pool (at the storage offset alignment;
    /// twice where it occludes, once a phase) and its marks, and makes the buffers large
    /// enough; `None` when the pool would pass the device's largest buffer (the frame
    /// draws directly).
    fn lay_out(&mut self, dispatches: &[Dispatch], device: &RenderDevice) -> Option<Vec<Offsets>> {
        let limits = device.limits();
        let align = u64::from(limits.min_storage_buffer_offset_alignment.max(4));
        let binding = kept_binding(dispatches);
        if binding > limits.max_storage_buffer_binding_size {
            warn_once!(
                "rwt: a chunk holds more instances than a GPU binding; drawing chunks whole"
            );
            return None;
        }
        let mut offsets = Vec::with_capacity(dispatches.len());
        let (mut end, mut marks) = (0u64, 0u32);
        let mut place = |count: u32| {
            let at = end.next_multiple_of(align);
            end = at + u64::from(count) * INSTANCE_BYTES;
            at
        };
        for (i, d) in dispatches.iter().enumerate() {
            let kept = place(d.gpu.count);
            let late = d.occludes().map(|_| {
                let late = occlusion::LateOffsets {
                    params: 0,
                    kept: place(d.gpu.count),
                    marks,
                };
                marks += d.gpu.count.div_ceil(32);
                late
            });
            offsets.push(Offsets {
                params: 0,
                kept,
                draw: i as u32,
                late,
            });
        }
        let last = offsets
            .iter()
            .map(|o| o.late.as_ref().map_or(o.kept, |l| l.kept))
            .max()
            .unwrap_or(0);
        let size = (last + binding).max(end);
        if size > limits.max_buffer_size || last > u64::from(u32::MAX) {
            warn_once!(
                "rwt: the instances kept by culling pass the GPU's largest buffer; drawing chunks whole"
            );
            return None;
        }
        self.grow(dispatches.len() as u64, size, marks, device);
        Some(offsets)
    }

    /// Grows the buffers for `draws` draws, a pool of `kept` bytes and `marks` words.
    fn grow(&mut self, draws: u64, kept: u64, marks: u32, device: &RenderDevice) {
        // Cleared once made (below), copied from by the check (`testing`).
        let usage = BufferUsages::VERTEX
            | BufferUsages::STORAGE
            | BufferUsages::COPY_DST
            | BufferUsages::COPY_SRC;
        self.fresh_pool |= grow(&mut self.kept, device, kept, "rwt_kept_instances", usage);
        let block = draws * u64::from(ARGS_WORDS) * 4;
        // Copied from by the check (`testing`) and the late phase, into by the late phase.
        let usage = BufferUsages::INDIRECT
            | BufferUsages::STORAGE
            | BufferUsages::COPY_DST
            | BufferUsages::COPY_SRC;
        grow(&mut self.args, device, 2 * block, "rwt_cull_args", usage);
        let usage = BufferUsages::COPY_DST | BufferUsages::COPY_SRC;
        grow(
            &mut self.phases,
            device,
            2 * block,
            "rwt_cull_phases",
            usage,
        );
        let usage = BufferUsages::STORAGE | BufferUsages::COPY_DST;
        let marks = u64::from(marks.max(1)) * 4;
        grow(&mut self.marks, device, marks, "rwt_cull_marks", usage);
    }

    /// Writes the settings (their offsets into `offsets`), the arguments (both blocks with
    /// no instances) and the early block with no instances the late phase restores.
    fn write(
        &mut self,
        dispatches: &[Dispatch],
        offsets: &mut [Offsets],
        device: &RenderDevice,
        queue: &RenderQueue,
    ) {
        self.params.clear();
        let mut args = Vec::with_capacity(dispatches.len() * ARGS_WORDS as usize);
        let late_block = dispatches.len() as u32 * ARGS_WORDS;
        for (d, o) in dispatches.iter().zip(offsets.iter_mut()) {
            let early = params(d, o);
            o.params = self.params.push(early);
            if let (Some(late), Some((_, current))) = (o.late.as_mut(), d.occludes()) {
                late.params = self.params.push(CullParams {
                    clip_from_world: current,
                    phase: 2,
                    first_mark: late.marks,
                    count_word: late_block + o.draw * ARGS_WORDS + 1,
                    ..early
                });
            }
            args.extend_from_slice(&d.args);
        }
        self.params.write_buffer(device, queue);
        let block: &[u8] = bytemuck::cast_slice(&args);
        if let (Some(buffer), Some(phases)) = (&self.args, &self.phases) {
            queue.write_buffer(buffer, 0, block);
            queue.write_buffer(buffer, block.len() as u64, block);
            queue.write_buffer(phases, block.len() as u64, block);
        }
    }

    /// Makes the bind group of each dispatched chunk whose buffers changed; forgets those of
    /// chunks not dispatched.
    fn bind(&mut self, dispatches: &[Dispatch], device: &RenderDevice, cache: &PipelineCache) {
        let (Some(kept), Some(args), Some(marks), Some(params)) =
            (&self.kept, &self.args, &self.marks, self.params.buffer())
        else {
            return;
        };
        // One dispatch's settings, at its dynamic offset.
        let one = BufferBinding {
            buffer: params,
            offset: 0,
            size: Some(CullParams::min_size()),
        };
        let binding = kept_binding(dispatches);
        let layout = cache.get_bind_group_layout(&self.layout);
        let mut chunks = HashMap::default();
        for d in dispatches {
            if chunks.contains_key(&d.chunk) {
                continue;
            }
            let made_with = [
                d.gpu.instances.id(),
                params.id(),
                kept.id(),
                args.id(),
                marks.id(),
            ];
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
                            one.clone(),
                            BufferBinding {
                                buffer: kept,
                                offset: 0,
                                size: NonZero::new(binding),
                            },
                            args.as_entire_binding(),
                            marks.as_entire_binding(),
                        )),
                    ),
                },
            };
            chunks.insert(d.chunk, chunk);
        }
        self.chunks = chunks;
    }
}

/// The size every chunk's binding of the pool has: the largest chunk's instances.
fn kept_binding(dispatches: &[Dispatch]) -> u64 {
    let most = dispatches.iter().map(|d| d.gpu.count).max().unwrap_or(1);
    let size = u64::from(most.max(1)) * INSTANCE_BYTES;
    // Grown in steps, so that bind groups are not made anew for every new largest chunk.
    size.next_power_of_two()
}

/// Makes `buffer` anew, of at least `size` bytes (grown by halves), when it is smaller;
/// whether it did.
fn grow(
    buffer: &mut Option<Buffer>,
    device: &RenderDevice,
    size: u64,
    label: &str,
    usage: BufferUsages,
) -> bool {
    if buffer.as_ref().is_some_and(|b| b.size() >= size) {
        return false;
    }
    let size = (size + size / 2).next_multiple_of(256);
    *buffer = Some(device.create_buffer(&BufferDescriptor {
        label: Some(label),
        size,
        usage,
        mapped_at_creation: false,
    }));
    true
}

/// The early phase's settings of one dispatch.
fn params(d: &Dispatch, o: &Offsets) -> CullParams {
    let u = &d.gpu.uniform;
    let shadow_distance = match (d.view.shadow, d.extracted.shadows) {
        (true, InstancedShadows::Within(distance)) => distance,
        _ => -1.0,
    };
    let (clip_from_world, phase, first_mark) = match (d.occludes(), &o.late) {
        (Some((previous, _)), Some(late)) => (previous, 1, late.marks),
        _ => (Mat4::IDENTITY, 0, 0),
    };
    CullParams {
        planes: d.view.planes,
        clip_from_world,
        eye: d.view.eye,
        shadow_distance,
        origin: u.origin,
        reach: d.extracted.reach,
        falloff_near: u.falloff_near,
        falloff_far: u.falloff_far,
        falloff_floor: u.falloff_floor,
        falloff_on: u.falloff_on,
        fade_band: u.fade_band,
        fade_in_from: u.fade_in_from,
        fade_out_to: u.fade_out_to,
        thinning_from: u.thinning_from,
        thinning_floor: u.thinning_floor,
        thinning_on: u.thinning_on,
        instances: d.gpu.count,
        count_word: o.draw * ARGS_WORDS + 1,
        workgroups_x: workgroups(d.gpu.count).0,
        phase,
        first_mark,
    }
}
