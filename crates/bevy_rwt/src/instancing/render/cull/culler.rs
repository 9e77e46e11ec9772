//! The culling pass as a resource: its pipeline, the frame's buffers, and the culled draws
//! the draw commands read.

use super::params::{CullRecord, CullView};
use super::pyramids::Pyramids;
use crate::instancing::chunk::GPU_BYTES_PER_INSTANCE;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_resource::binding_types::{
    storage_buffer_read_only, storage_buffer_read_only_sized, storage_buffer_sized,
};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderAdapter, RenderDevice};
use std::num::NonZero;
use std::ops::Range;

/// Invocations per workgroup (`cull.wgsl`'s `workgroup_size`).
pub(super) const WORKGROUP: u32 = 64;
/// Words of one draw's indirect arguments (indexed: count, instances, first index, base
/// vertex, first instance; direct draws read the first four the same way).
pub(super) const ARGS_WORDS: u32 = 5;
/// Bytes of one instance.
pub(super) const INSTANCE_BYTES: u64 = GPU_BYTES_PER_INSTANCE as u64;

/// Where one culled draw reads: its arguments (a byte offset into the frame's indirect
/// arguments) and its kept instances (a byte range of the pool).
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
/// meshes where its instances lie on both sides of the far distance: [`lods`](super::lods)).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(in crate::instancing) struct CulledDraws([Option<CulledDraw>; 2]);

impl CulledDraws {
    /// Its draws, in the order they were recorded.
    pub fn iter(&self) -> impl Iterator<Item = &CulledDraw> {
        self.0.iter().flatten()
    }

    pub(super) fn push(&mut self, draw: CulledDraw) {
        let free = self.0.iter_mut().find(|d| d.is_none());
        debug_assert!(free.is_some(), "a chunk draws at most two meshes");
        if let Some(free) = free {
            *free = Some(draw);
        }
    }
}

/// One view's dispatch in one phase: its records, its workgroups, where its kept instances
/// lie in the pool (the byte offset of its binding), and its settings (their dynamic offset
/// into the frame's views, and themselves).
#[derive(Clone)]
pub(super) struct ViewWork {
    pub entity: Entity,
    pub records: Range<u32>,
    pub workgroups: u32,
    pub pool: u64,
    pub params: u32,
    pub settings: CullView,
}

/// The frame's cull bind group, and the buffers it was made with.
pub(super) struct FrameBind {
    pub made_with: [BufferId; 6],
    pub pool_binding: u64,
    pub bind_group: BindGroup,
}

/// The culling pass: its pipeline, this frame's buffers and the culled draws.
#[derive(Resource)]
pub(in crate::instancing) struct InstanceCuller {
    /// The pipeline, where the adapter runs compute shaders and indirect draws.
    pub(super) pipeline: Option<CachedComputePipelineId>,
    pub(super) layout: BindGroupLayoutDescriptor,
    /// Each view's settings (early, late), read through a dynamic offset. A storage
    /// buffer: lavapipe specialises a shader on the values of the uniforms its branches
    /// read and keeps every variant, so a uniform that varies by dispatch compiled one per
    /// dispatch, without end.
    pub(super) views: DynamicStorageBuffer<CullView>,
    /// Every view's records, a view's together.
    pub(super) records: StorageBuffer<Vec<CullRecord>>,
    /// The pool of kept instances.
    pub(super) kept: Option<Buffer>,
    /// Whether the pool was made this frame and not yet cleared.
    pub(super) fresh_pool: bool,
    /// Every draw's indirect arguments: the early block, then the late block.
    pub(super) args: Option<Buffer>,
    /// One bit per instance of a chunk in an occluding view: hidden in the early phase.
    pub(super) marks: Option<Buffer>,
    /// The pyramids views occlude with.
    pub(super) pyramids: Pyramids,
    /// The bind group every dispatch of the frame uses.
    pub(super) bind: Option<FrameBind>,
    /// This frame's culled draws, by (view, chunk) render entity.
    pub(super) draws: HashMap<(Entity, Entity), CulledDraws>,
    /// This frame's early phase, a dispatch per view.
    pub(super) early: Vec<ViewWork>,
    /// This frame's late phase, by view (views that occlude).
    pub(super) late: HashMap<Entity, ViewWork>,
}

impl InstanceCuller {
    /// The culled draws of `chunk` in `view` this frame, with the buffers they read.
    pub fn draw(&self, view: Entity, chunk: Entity) -> Option<(&CulledDraws, &Buffer, &Buffer)> {
        let draw = self.draws.get(&(view, chunk))?;
        Some((draw, self.kept.as_ref()?, self.args.as_ref()?))
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
    let pyramids = Pyramids::new(&device);
    let pipeline = gpu_culling_supported(&device, &adapter).then(|| {
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
    });
}

/// Whether the adapter runs the culling pass of [`InstanceCulling`](crate::InstanceCulling)'s
/// `Auto` and `PerInstance`: compute shaders (not WebGL2-class adapters, nor limits that
/// emulate them), indirect draws, and storage buffers enough. Where it does not, every kept
/// chunk is drawn whole, directly (the main world has both resources, to tell a user).
pub fn gpu_culling_supported(device: &RenderDevice, adapter: &RenderAdapter) -> bool {
    let limits = device.limits();
    let flags = adapter.get_downlevel_capabilities().flags;
    flags.contains(DownlevelFlags::COMPUTE_SHADERS | DownlevelFlags::INDIRECT_EXECUTION)
        && limits.max_compute_workgroup_size_x >= WORKGROUP
        && limits.max_compute_invocations_per_workgroup >= WORKGROUP
        && limits.max_storage_buffers_per_shader_stage >= 6
        && limits.max_dynamic_storage_buffers_per_pipeline_layout >= 2
}

/// `groups` workgroups as a grid (x, y): at most 65 535 along x.
pub(super) fn grid(groups: u32) -> (u32, u32) {
    let groups = groups.max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}
