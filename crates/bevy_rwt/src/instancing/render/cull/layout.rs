//! How a frame's culling is laid out: each view's region of the pool of kept instances,
//! each chunk's record in it (its ranges, marks and workgroups), and buffers large enough.

use super::culler::{
    ARGS_WORDS, CulledDraw, CulledRange, INSTANCE_BYTES, InstanceCuller, ViewWork, WORKGROUP,
};
use super::entries::CullEntry;
use super::params::{CullRecord, CullView};
use crate::look::InstancedShadows;
use bevy::prelude::*;
use bevy::render::render_resource::*;
use bevy::render::renderer::RenderDevice;
use std::ops::Range;

/// This frame's layout: each entry's culled draw (where its arguments and kept instances
/// lie, in each phase), each view's dispatch, the records, and the size every view's
/// binding of the pool has.
pub(super) struct Plan {
    pub draws: Vec<CulledDraw>,
    pub early: Vec<ViewWork>,
    pub records: Vec<CullRecord>,
    pub pool_binding: u64,
}

impl InstanceCuller {
    /// Places each view's kept instances in the pool (a region per view at the storage
    /// offset alignment: each chunk's early range, then where it occludes each chunk's late
    /// range), each chunk's marks and workgroups, and makes the buffers large enough;
    /// `None` when a view's region would pass one binding or the pool the device's largest
    /// buffer (the frame draws directly).
    pub(super) fn lay_out(&mut self, entries: &[CullEntry], device: &RenderDevice) -> Option<Plan> {
        let limits = device.limits();
        let align = u64::from(limits.min_storage_buffer_offset_alignment.max(4));
        let mut plan = Plan {
            draws: Vec::with_capacity(entries.len()),
            early: Vec::new(),
            records: Vec::with_capacity(entries.len()),
            pool_binding: 0,
        };
        let (mut end, mut marks, mut most) = (0u64, 0u32, 0u64);
        let mut first = 0;
        while first < entries.len() {
            let view = entries[first].view.entity;
            let last = first + entries[first..].partition_point(|d| d.view.entity == view);
            let pool = end.next_multiple_of(align);
            let draws = first as u32..entries.len() as u32;
            let ((draws, records), work) =
                self.lay_out_view(&entries[first..last], draws, pool, &mut marks);
            let bytes = draws
                .iter()
                .map(|d| d.late.as_ref().unwrap_or(&d.early).kept.end - pool)
                .max()
                .unwrap_or(0);
            most = most.max(bytes);
            end = pool + bytes;
            plan.draws.extend(draws);
            plan.records.extend(records);
            plan.early.push(work);
            first = last;
        }
        // Grown in steps, so that the bind group is not made anew for every new largest view.
        plan.pool_binding = most.max(INSTANCE_BYTES).next_power_of_two();
        let last_pool = plan.early.iter().map(|v| v.pool).max().unwrap_or(0);
        let size = (last_pool + plan.pool_binding).max(end);
        if plan.pool_binding > limits.max_storage_buffer_binding_size
            || size > limits.max_buffer_size
            || last_pool > u64::from(u32::MAX)
        {
            warn_once!(
                "rwt: the instances kept by culling pass the GPU's largest buffer; drawing chunks whole"
            );
            return None;
        }
        self.grow(entries.len() as u64, size, marks, device);
        Some(plan)
    }

    /// Lays out one view's entries from `pool` (bytes) on, the first of them the frame's
    /// draw `draws.start` of `draws.end`: their culled draws and records, and the view's
    /// dispatch (its settings written later).
    fn lay_out_view(
        &self,
        entries: &[CullEntry],
        draws: Range<u32>,
        pool: u64,
        marks: &mut u32,
    ) -> ((Vec<CulledDraw>, Vec<CullRecord>), ViewWork) {
        let (first_draw, draw_count) = (draws.start, draws.end);
        let view = entries[0].view;
        let occludes = view.occluding.is_some_and(|o| o.previous.is_some());
        let mut kept = 0u32;
        let mut place = |count: u32| {
            let at = kept;
            kept += count;
            at
        };
        let mut records: Vec<CullRecord> = entries
            .iter()
            .map(|d| CullRecord {
                kept: place(d.gpu.count),
                ..record(d)
            })
            .collect();
        let mut workgroups = 0;
        let mut culled = Vec::with_capacity(entries.len());
        for (i, (d, r)) in entries.iter().zip(&mut records).enumerate() {
            r.first_workgroup = workgroups;
            workgroups += d.gpu.count.div_ceil(WORKGROUP);
            let draw = first_draw + i as u32;
            // The late block of arguments follows the early one, a draw each.
            let range = |draw: u32, instance: u32| {
                let at = pool + u64::from(instance) * INSTANCE_BYTES;
                CulledRange {
                    args: u64::from(draw * ARGS_WORDS * 4),
                    kept: at..at + d.bytes(),
                }
            };
            let late = occludes.then(|| {
                r.late_kept = place(d.gpu.count);
                r.first_mark = *marks;
                *marks += d.gpu.count.div_ceil(32);
                range(draw_count + draw, r.late_kept)
            });
            r.count_word = draw * ARGS_WORDS + 1;
            culled.push(CulledDraw {
                mesh: d.part.mesh,
                early: range(draw, r.kept),
                late,
            });
        }
        let work = ViewWork {
            entity: view.entity,
            records: first_draw..first_draw + entries.len() as u32,
            workgroups,
            pool,
            params: 0,
            settings: CullView::default(),
        };
        ((culled, records), work)
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
        // Copied from by the check (`testing`).
        let usage = BufferUsages::INDIRECT
            | BufferUsages::STORAGE
            | BufferUsages::COPY_DST
            | BufferUsages::COPY_SRC;
        grow(&mut self.args, device, 2 * block, "rwt_cull_args", usage);
        let usage = BufferUsages::STORAGE | BufferUsages::COPY_DST;
        let marks = u64::from(marks.max(1)) * 4;
        grow(&mut self.marks, device, marks, "rwt_cull_marks", usage);
    }
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

/// A chunk's record in its view (of one of its meshes: the instances of its band), before
/// its place in the pool and the arguments is known.
pub(super) fn record(d: &CullEntry) -> CullRecord {
    let u = &d.gpu.uniform;
    let shadow_distance = match (d.view.shadow, d.extracted.shadows) {
        (true, InstancedShadows::Within(distance)) => distance,
        _ => -1.0,
    };
    let (fade_in_from, fade_out_to) = d.part.band(u.fade_in_from, u.fade_out_to);
    CullRecord {
        origin: u.origin,
        reach: d.extracted.reach,
        shadow_distance,
        fade_in_from,
        fade_out_to,
        lod: u.lod,
        instances: d.gpu.count,
        first_instance: d.first_instance,
        ..default()
    }
}
