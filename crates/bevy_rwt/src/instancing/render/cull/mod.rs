//! Culling per instance on the GPU ([`InstanceCulling`]).
//!
//! After queueing, each view gets one compute dispatch (`cull.wgsl`) over a record of each
//! chunk binned into any of its phases ([`CullRecord`]), the chunks' instances all in one
//! buffer ([`InstanceSlab`]): each instance is tested against the view and, when it may be
//! seen, copied into the frame's pool of kept instances, and counted in its draw's indirect
//! arguments. The chunk's draws in that view then read their instances from the pool and
//! their count from the arguments ([`CulledDraw`]). The compute work is encoded at the start
//! of the frame's render graph ([`encode_cull`]), before every view's passes, so each pass
//! of the view (prepasses, main pass, shadow map) reads what it wrote. A chunk without a
//! culled draw (culling off, the adapter unable, the pool full, or nothing culling could
//! drop: [`whole`]) is drawn directly, whole.
//!
//! A camera with Bevy's `OcclusionCulling` and `DepthPrepass`, and the cascades of a light
//! with `OcclusionCulling`, also cull what their depth pyramids hide, in two phases
//! ([`occlusion`]): what last frame's depth hid is tested again once this frame's early
//! depth is reduced, and drawn from the late prepass and late shadow passes on.

mod layout;
mod lods;
mod occlusion;
mod params;
#[cfg(test)]
mod tests;
mod whole;

use layout::{Offsets, Plan, ViewWork};
pub(in crate::instancing) use occlusion::cull_late;
pub(super) use params::{CullRecord, CullView};

use super::draw::MeshSlices;
use super::receivers::{CascadeReceivers, Receivers};
use super::{ExtractedChunk, GpuChunk, InstanceSlab, MainViewer, Queued};
#[cfg(test)]
use crate::instancing::GpuInstance;
use crate::instancing::{GPU_BYTES_PER_INSTANCE, InstanceCulling};
use bevy::camera::primitives::Frustum;
use bevy::core_pipeline::core_3d::Opaque3d;
use bevy::core_pipeline::prepass::Opaque3dPrepass;
use bevy::pbr::{LightEntity, Shadow};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::diagnostic::{DiagnosticsRecorder, RecordDiagnostics};
use bevy::render::mesh::RenderMesh;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::binding_types::{
    storage_buffer_read_only, storage_buffer_read_only_sized, storage_buffer_sized,
};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderAdapter, RenderContext, RenderDevice, RenderQueue};
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

/// One mesh's culled draw of a chunk in one view: the mesh, the instances its early phase
/// kept, and in a view that occludes, those its late phase kept.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(in crate::instancing) struct CulledDraw {
    pub mesh: AssetId<Mesh>,
    pub early: CulledRange,
    pub late: Option<CulledRange>,
}

/// A chunk's culled draws in one view: one per mesh it draws (its class's near and far
/// meshes where its instances lie on both sides of the far distance: [`lods`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(in crate::instancing) struct CulledDraws([Option<CulledDraw>; 2]);

impl CulledDraws {
    /// Its draws, in the order they were recorded.
    pub fn iter(&self) -> impl Iterator<Item = &CulledDraw> {
        self.0.iter().flatten()
    }

    fn push(&mut self, draw: CulledDraw) {
        let free = self.0.iter_mut().find(|d| d.is_none());
        debug_assert!(free.is_some(), "a chunk draws at most two meshes");
        if let Some(free) = free {
            *free = Some(draw);
        }
    }
}

/// The frame's cull bind group, and the buffers it was made with.
struct FrameBind {
    made_with: [BufferId; 6],
    pool_binding: u64,
    bind_group: BindGroup,
}

/// The culling pass: its pipeline, this frame's buffers and the culled draws.
#[derive(Resource)]
pub(in crate::instancing) struct InstanceCuller {
    /// The pipeline, where the adapter runs compute shaders and indirect draws.
    pipeline: Option<CachedComputePipelineId>,
    layout: BindGroupLayoutDescriptor,
    /// Each view's dispatches (early, late), read through a dynamic offset. A storage
    /// buffer: lavapipe specialises a shader on the values of the uniforms its branches
    /// read and keeps every variant, so a uniform that varies by dispatch compiled one per
    /// dispatch, without end.
    views: DynamicStorageBuffer<CullView>,
    /// Every view's records, a view's together.
    records: StorageBuffer<Vec<CullRecord>>,
    /// The pool of kept instances.
    kept: Option<Buffer>,
    /// Whether the pool was made this frame and not yet cleared.
    fresh_pool: bool,
    /// Every draw's indirect arguments: the early block, then the late block.
    args: Option<Buffer>,
    /// One bit per instance of a chunk in an occluding view: hidden in the early phase.
    marks: Option<Buffer>,
    /// The pyramids views occlude with.
    pyramids: occlusion::Pyramids,
    /// The bind group every dispatch of the frame uses.
    bind: Option<FrameBind>,
    /// This frame's culled draws, by (view, chunk) render entity.
    draws: HashMap<(Entity, Entity), CulledDraws>,
    /// This frame's early phase, a dispatch per view.
    early: Vec<ViewWork>,
    /// This frame's late phase, by view.
    late: HashMap<Entity, occlusion::LateWork>,
    /// This frame's culled draws, in the order of their arguments, for the check.
    #[cfg(feature = "testing")]
    checked: Vec<super::cull_check::Checked>,
}

impl InstanceCuller {
    /// The culled draws of `chunk` in `view` this frame, with the buffers they read.
    pub fn draw(&self, view: Entity, chunk: Entity) -> Option<(&CulledDraws, &Buffer, &Buffer)> {
        let draw = self.draws.get(&(view, chunk))?;
        Some((draw, self.kept.as_ref()?, self.args.as_ref()?))
    }

    /// This frame's culled draws (view, record, instances, whether it occludes), in the
    /// order of their arguments.
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
                storage_buffer_read_only_sized(false, None),
                storage_buffer_read_only::<CullView>(true),
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
        views: DynamicStorageBuffer::default(),
        records: StorageBuffer::default(),
        kept: None,
        fresh_pool: false,
        args: None,
        marks: None,
        pyramids,
        bind: None,
        draws: HashMap::default(),
        early: Vec::new(),
        late: HashMap::default(),
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
        && limits.max_storage_buffers_per_shader_stage >= 6
        && limits.max_dynamic_storage_buffers_per_pipeline_layout >= 2
}

/// How each view culls: its half-spaces, where its level of detail is measured from, and
/// how it occludes.
#[derive(Clone, Copy)]
struct ViewCull {
    entity: Entity,
    planes: [Vec4; 6],
    eye: Vec3,
    shadow: bool,
    /// In a directional light's cascade, where its shadows are read.
    receivers: Option<Receivers>,
    occluding: Option<occlusion::Occluding>,
}

/// Each mesh's draw arguments before culling, found once a frame.
type MeshArgs = HashMap<AssetId<Mesh>, Option<[u32; ARGS_WORDS as usize]>>;

/// One chunk in a view, one mesh of it (a record of the view's dispatch).
struct Dispatch<'a> {
    view: &'a ViewCull,
    chunk: Entity,
    extracted: &'a ExtractedChunk,
    gpu: &'a GpuChunk,
    /// The mesh and the instances it draws.
    part: lods::Part,
    /// The chunk's first instance in the slab.
    first_instance: u32,
    /// The draw's arguments before culling (the instance count 0).
    args: [u32; ARGS_WORDS as usize],
}

impl Dispatch<'_> {
    /// The bytes of the chunk's instances: of each range of the pool it keeps into.
    fn bytes(&self) -> u64 {
        u64::from(self.gpu.count) * INSTANCE_BYTES
    }

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
    chunks: Query<'w, 's, (&'static ExtractedChunk, &'static GpuChunk)>,
    meshes: Res<'w, RenderAssets<RenderMesh>>,
    allocator: Res<'w, MeshAllocator>,
    viewer: Res<'w, MainViewer>,
    slab: Res<'w, InstanceSlab>,
    receivers: Res<'w, CascadeReceivers>,
}

/// Lays out and writes the culling of every chunk binned into every view, and records the
/// culled draws ([`encode_cull`] encodes the work).
pub(in crate::instancing) fn cull_instances(
    mut culler: ResMut<InstanceCuller>,
    inputs: CullInputs,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    cache: Res<PipelineCache>,
    #[cfg(feature = "testing")] check: Res<super::FrameCheck>,
) {
    culler.draws.clear();
    culler.early.clear();
    culler.late.clear();
    #[cfg(feature = "testing")]
    culler.checked.clear();
    let on = inputs.setting.as_deref().copied().unwrap_or_default() != InstanceCulling::PerChunk;
    let ready = culler.pipeline.filter(|_| on);
    if ready.and_then(|p| cache.get_compute_pipeline(p)).is_none() {
        return;
    }
    let culler = culler.as_mut();
    let views = inputs
        .views
        .iter()
        .map(|(e, view, _, shadow, p)| (e, view, shadow, p));
    let occluding = culler.pyramids.prepare(views, &device, &cache);
    let views = inputs.views(&occluding);
    let dispatches = inputs.dispatches(&views);
    if dispatches.is_empty() {
        return;
    }
    let Some(slab) = inputs.slab.buffer() else {
        return;
    };
    let Some(mut plan) = culler.lay_out(&dispatches, &device) else {
        return;
    };
    culler.write(&dispatches, &mut plan, &device, &queue);
    culler.bind(slab, plan.pool_binding, &device, &cache);
    if culler.bind.is_none() {
        culler.late.clear();
        return;
    }
    culler.early = plan.early;
    culler.record(&dispatches, &plan.offsets);
    #[cfg(feature = "testing")]
    if check.requested() {
        culler.keep_for_check(&dispatches, &plan.offsets);
    }
}

/// At the start of the frame's render graph, before any view's passes: encodes the early
/// phase (clearing the marks, and the pool where it is new). Encoded with the frame's
/// commands, as Bevy's own preprocessing is, rather than submitted apart from them.
pub(in crate::instancing) fn encode_cull(
    mut culler: ResMut<InstanceCuller>,
    cache: Res<PipelineCache>,
    mut ctx: RenderContext,
) {
    if culler.early.is_empty() {
        return;
    }
    let Some(pipeline) = culler.pipeline.and_then(|p| cache.get_compute_pipeline(p)) else {
        return;
    };
    let diagnostics = ctx.diagnostic_recorder();
    let encoder = ctx.command_encoder();
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
    culler.dispatch_early(encoder, pipeline, diagnostics.as_deref());
}

impl InstanceCuller {
    /// Encodes the early phase (the only one, where the view does not occlude): one
    /// dispatch per view. Its GPU time is the render diagnostic `rwt_cull`.
    fn dispatch_early(
        &self,
        encoder: &mut CommandEncoder,
        pipeline: &ComputePipeline,
        diagnostics: Option<&DiagnosticsRecorder>,
    ) {
        let Some(bind) = &self.bind else { return };
        let mut pass = encoder.begin_compute_pass(&ComputePassDescriptor {
            label: Some("rwt_cull"),
            timestamp_writes: None,
        });
        let span = diagnostics.pass_span(&mut pass, "rwt_cull");
        pass.set_pipeline(pipeline);
        for view in &self.early {
            let Some(pyramid) = self.pyramids.bind_group(view.entity) else {
                continue;
            };
            pass.set_bind_group(1, pyramid, &[]);
            pass.set_bind_group(0, &bind.bind_group, &[view.params, view.pool as u32]);
            let (x, y) = grid(view.workgroups);
            pass.dispatch_workgroups(x, y, 1);
        }
        span.end(&mut pass);
    }

    /// Keeps what culled each of this frame's draws, for the check.
    #[cfg(feature = "testing")]
    fn keep_for_check(&mut self, dispatches: &[Dispatch], offsets: &[Offsets]) {
        for ((d, o), record) in dispatches.iter().zip(offsets).zip(self.records.get()) {
            let view = self.early.iter().find(|v| v.entity == d.view.entity);
            self.checked.push(super::cull_check::Checked {
                view: view.map(|v| v.params_value).unwrap_or_default(),
                record: *record,
                instances: d.extracted.buffer.clone(),
                occludes: o.late.is_some(),
                pyramid: d.view.occluding.is_some(),
                shadow: d.view.shadow,
                far: d.part.far,
                kept: o.kept..o.kept + d.bytes(),
                late: o.late.map(|l| l..l + d.bytes()),
            });
        }
    }

    /// Records this frame's culled draws (the late block of arguments follows the early
    /// one, a record each).
    fn record(&mut self, dispatches: &[Dispatch], offsets: &[Offsets]) {
        let draw_count = dispatches.len() as u32;
        for (d, o) in dispatches.iter().zip(offsets) {
            let early = CulledRange {
                args: u64::from(o.draw * ARGS_WORDS * 4),
                kept: o.kept..o.kept + d.bytes(),
            };
            let late = o.late.map(|late| CulledRange {
                args: u64::from((draw_count + o.draw) * ARGS_WORDS * 4),
                kept: late..late + d.bytes(),
            });
            self.draws
                .entry((d.view.entity, d.chunk))
                .or_default()
                .push(CulledDraw {
                    mesh: d.part.mesh,
                    early,
                    late,
                });
        }
    }
}

/// `groups` workgroups as a grid (x, y): at most 65 535 along x.
fn grid(groups: u32) -> (u32, u32) {
    let groups = groups.max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}

impl CullInputs<'_, '_> {
    /// How each view culls this frame.
    fn views(
        &self,
        occluding: &HashMap<Entity, occlusion::Occluding>,
    ) -> HashMap<RetainedViewEntity, ViewCull> {
        self.views
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
                    receivers: self.receivers.of(entity).copied(),
                    occluding: occluding.get(&entity).copied(),
                };
                (view.retained_view_entity, cull)
            })
            .collect()
    }

    /// Every (view, chunk) binned this frame in one of `views`, once each, in a stable
    /// order (a view's dispatches together).
    fn dispatches<'a>(
        &'a self,
        views: &'a HashMap<RetainedViewEntity, ViewCull>,
    ) -> Vec<Dispatch<'a>> {
        // Every (view, chunk) binned in any phase, once each: the camera's chunks are in
        // its main pass and its prepass.
        let mut pairs: Vec<(&ViewCull, Entity)> = Vec::new();
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

    /// The dispatches of one chunk in one view, a mesh each; none unless every mesh is
    /// ready and the chunk's instances are in the slab (then it is drawn whole).
    fn parts<'a>(
        &'a self,
        view: &'a ViewCull,
        chunk: Entity,
        extracted: &'a ExtractedChunk,
        gpu: &'a GpuChunk,
        args: &mut MeshArgs,
    ) -> [Option<Dispatch<'a>>; 2] {
        let first = self.slab.range(chunk).filter(|_| gpu.own.is_none());
        let Some(first_instance) = first.map(|r| r.start) else {
            return [None, None];
        };
        let parts = lods::parts(view, extracted, &self.meshes);
        let dispatch = |part: Option<lods::Part>| {
            let part = part?;
            Some(Dispatch {
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
        let dispatches = parts.map(dispatch);
        let ready = parts
            .iter()
            .zip(&dispatches)
            .all(|(p, d)| p.is_none() == d.is_none());
        if ready { dispatches } else { [None, None] }
    }

    /// A mesh's draw arguments before culling, as the direct draw would give them.
    fn args(&self, mesh: AssetId<Mesh>) -> Option<[u32; ARGS_WORDS as usize]> {
        MeshSlices::of(&self.meshes, &self.allocator, mesh).map(|s| s.args)
    }
}

impl InstanceCuller {
    /// Writes the records, each view's settings (their offsets into `plan`; a late phase's
    /// where the view occludes) and the arguments (both blocks with no instances).
    fn write(
        &mut self,
        dispatches: &[Dispatch],
        plan: &mut Plan,
        device: &RenderDevice,
        queue: &RenderQueue,
    ) {
        let late_block = dispatches.len() as u32 * ARGS_WORDS;
        for r in &mut plan.records {
            r.late_count_word = late_block + r.count_word;
        }
        self.records.set(std::mem::take(&mut plan.records));
        self.records.write_buffer(device, queue);
        self.views.clear();
        for work in &mut plan.early {
            let d = &dispatches[work.records.start as usize];
            let (x, _) = grid(work.workgroups);
            let (receivers, light) = match d.view.receivers {
                Some(r) => (r.planes, r.light.extend(1.0)),
                None => ([Vec4::ZERO; 6], Vec4::ZERO),
            };
            let early = CullView {
                planes: d.view.planes,
                receivers,
                light,
                clip_from_world: Mat4::IDENTITY,
                eye: d.view.eye,
                phase: 0,
                first_record: work.records.start,
                records: work.records.len() as u32,
                workgroups: work.workgroups,
                workgroups_x: x,
            };
            let early = match d.occludes() {
                Some((previous, current)) => {
                    let late = self.views.push(CullView {
                        clip_from_world: current,
                        phase: 2,
                        ..early
                    });
                    self.late
                        .insert(d.view.entity, occlusion::LateWork::new(work, late));
                    CullView {
                        clip_from_world: previous,
                        phase: 1,
                        ..early
                    }
                }
                None => early,
            };
            work.params = self.views.push(early);
            #[cfg(feature = "testing")]
            {
                work.params_value = early;
            }
        }
        self.views.write_buffer(device, queue);
        let args: Vec<u32> = dispatches.iter().flat_map(|d| d.args).collect();
        let block: &[u8] = bytemuck::cast_slice(&args);
        if let Some(buffer) = &self.args {
            queue.write_buffer(buffer, 0, block);
            queue.write_buffer(buffer, block.len() as u64, block);
        }
    }

    /// Makes the frame's bind group when its buffers or the pool's binding changed.
    fn bind(
        &mut self,
        slab: &Buffer,
        pool_binding: u64,
        device: &RenderDevice,
        cache: &PipelineCache,
    ) {
        let (Some(kept), Some(args), Some(marks), Some(records), Some(views)) = (
            &self.kept,
            &self.args,
            &self.marks,
            self.records.buffer(),
            self.views.buffer(),
        ) else {
            self.bind = None;
            return;
        };
        let made_with = [
            slab.id(),
            records.id(),
            views.id(),
            kept.id(),
            args.id(),
            marks.id(),
        ];
        if self
            .bind
            .as_ref()
            .is_some_and(|b| b.made_with == made_with && b.pool_binding == pool_binding)
        {
            return;
        }
        let bind_group = device.create_bind_group(
            "rwt_cull",
            &cache.get_bind_group_layout(&self.layout),
            &BindGroupEntries::sequential((
                slab.as_entire_binding(),
                records.as_entire_binding(),
                // One view's settings, at its dynamic offset.
                BufferBinding {
                    buffer: views,
                    offset: 0,
                    size: Some(CullView::min_size()),
                },
                BufferBinding {
                    buffer: kept,
                    offset: 0,
                    size: NonZero::new(pool_binding),
                },
                args.as_entire_binding(),
                marks.as_entire_binding(),
            )),
        );
        self.bind = Some(FrameBind {
            made_with,
            pool_binding,
            bind_group,
        });
    }
}
