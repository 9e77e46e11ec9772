//! The check of culling per instance against the CPU (feature `testing`): on request, the
//! render world reads back a frame's indirect arguments and kept instances and compares,
//! for every culled draw, the instances it draws with those the same test keeps on the CPU
//! ([`CullingCheck`]). The culling pass publishes what it culled into a [`CullSnapshot`];
//! the check reads that, nothing of the culler itself.

use super::culler::{ARGS_WORDS, CulledDraw, InstanceCuller};
use super::entries::CullEntry;
use super::params::{CullRecord, CullView};
use crate::instancing::chunk::InstanceBuffer;
use crate::instancing::render::slab::InstanceSlab;
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy::render::Extract;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use std::ops::Range;
use std::sync::{Arc, Mutex};

/// Asks the render world to check one frame's culling per instance against a brute-force
/// count on the CPU (the same test, the same view, every instance). Insert it, call
/// [`request`](Self::request), run frames until [`report`](Self::report) answers.
#[derive(Resource, Clone, Default)]
pub struct CullingCheck(Arc<Mutex<CheckState>>);

#[derive(Default)]
struct CheckState {
    requested: bool,
    report: Option<CullingReport>,
}

/// What a check found in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CullingReport {
    /// Culled draws (a mesh of a chunk in a view).
    pub draws: usize,
    /// Instances of the chunks drawn, summed over the draws.
    pub instances: u64,
    /// Instances the GPU kept (read back from the indirect arguments).
    pub gpu_kept: u64,
    /// Instances the CPU keeps (by the view's frustum, the fade and far thinning).
    pub cpu_kept: u64,
    /// Draws whose instances disagree: those the GPU kept (read back from the pool, as many
    /// as its arguments count) are not those the CPU keeps, or in a view that occludes, not
    /// among them (the CPU tests no depth, so occlusion may only drop instances).
    pub mismatched: usize,
    /// Culled draws of a class's far mesh, chosen by each instance's distance (a chunk
    /// across the far distance draws its near mesh too, in another draw).
    pub far_draws: usize,
    /// Culled draws in views that occlude (that test against a depth pyramid, from the
    /// second frame they do on in two phases).
    pub occluding_draws: usize,
    /// Instances the late phase of occlusion kept: hidden by last frame's depth, not by
    /// this frame's.
    pub late_kept: u64,
    /// Instances the buffer of every chunk's instances holds (its size, not its use).
    pub slab_capacity: u64,
    /// Instances of the draws in directional lights' cascades that the rest of the test
    /// keeps and that cast nowhere the camera reads the cascade ([`crate::CascadeCasters`];
    /// the CPU's count).
    pub cascade_dropped: u64,
    /// Culled draws in cascades that occlude (a light's `OcclusionCulling`), counted as
    /// [`occluding_draws`](Self::occluding_draws) counts them.
    pub cascade_occluding_draws: usize,
    /// Instances of those draws that the rest of the test keeps and the cascade's depth hid
    /// (neither phase kept them; the CPU's count less the GPU's).
    pub cascade_occluded: u64,
    /// Vertices the culled draws of cameras' views draw: each draw's index (or vertex)
    /// count times the instances it kept, read back from the indirect arguments.
    pub camera_vertices: u64,
}

impl CullingCheck {
    /// Checks the next frame that culls per instance (a report waiting is dropped): the
    /// frame of the main-world update that asks, or the first after it that culls.
    pub fn request(&self) {
        let mut state = self.0.lock().unwrap_or_else(|e| e.into_inner());
        state.requested = true;
        state.report = None;
    }

    /// The report, once the frame was checked.
    pub fn report(&self) -> Option<CullingReport> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).report
    }

    fn take_request(&self) -> bool {
        std::mem::take(&mut self.0.lock().unwrap_or_else(|e| e.into_inner()).requested)
    }

    fn answer(&self, report: CullingReport) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).report = Some(report);
    }
}

/// The render world's side of a [`CullingCheck`]: the check, and whether the frame being
/// rendered is the one asked for (the request is taken as the frame is extracted, so that
/// the frame checked is the one whose main-world state asked, pipelined or not).
#[derive(Resource, Default)]
pub(in crate::instancing) struct FrameCheck {
    check: Option<CullingCheck>,
    requested: bool,
}

/// Takes this frame's request, if any.
pub(in crate::instancing) fn extract_culling_check(
    source: Extract<Option<Res<CullingCheck>>>,
    mut frame: ResMut<FrameCheck>,
) {
    frame.check = source.as_deref().cloned();
    frame.requested = frame.check.as_ref().is_some_and(CullingCheck::take_request);
}

/// One culled draw as the check sees it: its view's early dispatch, its record, the chunk's
/// instances, whether its view occludes and is a light's.
struct Checked {
    pub view: CullView,
    pub record: CullRecord,
    pub instances: Arc<InstanceBuffer>,
    pub occludes: bool,
    /// Whether its view tests against a depth pyramid (in its first frame, no phase yet).
    pub pyramid: bool,
    /// Whether its view is a light's.
    pub shadow: bool,
    /// Whether it draws its class's far mesh (chosen per instance).
    pub far: bool,
    /// The byte ranges of the pool its early and late phases keep into.
    pub kept: Range<u64>,
    pub late: Option<Range<u64>>,
}

/// What the culling pass publishes for the check in a frame it was asked to: each culled
/// draw, in the order of its arguments, and the buffers the GPU writes.
#[derive(Resource, Default)]
pub(in crate::instancing) struct CullSnapshot {
    draws: Vec<Checked>,
    args: Option<Buffer>,
    kept: Option<Buffer>,
}

/// The culling pass's side of the check: the frame's request and the snapshot it fills.
#[derive(SystemParam)]
pub(in crate::instancing) struct Publish<'w> {
    frame: Res<'w, FrameCheck>,
    snapshot: ResMut<'w, CullSnapshot>,
}

impl Publish<'_> {
    /// Forgets the last frame's snapshot.
    pub(super) fn clear(&mut self) {
        let snapshot = self.snapshot.as_mut();
        snapshot.draws.clear();
        snapshot.args = None;
        snapshot.kept = None;
    }

    /// Publishes what culled each of this frame's draws (`entries`, laid out at
    /// `offsets`), when the frame is to be checked.
    pub(super) fn publish(
        &mut self,
        culler: &InstanceCuller,
        entries: &[CullEntry],
        draws: &[CulledDraw],
    ) {
        if !self.frame.requested {
            return;
        }
        let snapshot = self.snapshot.as_mut();
        let records = culler.records.get();
        for ((d, draw), record) in entries.iter().zip(draws).zip(records) {
            let view = culler.early.iter().find(|v| v.entity == d.view.entity);
            snapshot.draws.push(Checked {
                view: view.map(|v| v.settings).unwrap_or_default(),
                record: *record,
                instances: d.extracted.buffer.clone(),
                occludes: draw.late.is_some(),
                pyramid: d.view.occluding.is_some(),
                shadow: d.view.shadow,
                far: d.part.far,
                kept: draw.early.kept.clone(),
                late: draw.late.as_ref().map(|l| l.kept.clone()),
            });
        }
        snapshot.args = culler.args.clone();
        snapshot.kept = culler.kept.clone();
    }
}

/// After the frame's work is submitted: reads the arguments and the kept instances back
/// when a check was asked for and the frame culled per instance, and answers it.
pub(in crate::instancing) fn check_culling(
    frame: Res<FrameCheck>,
    snapshot: Res<CullSnapshot>,
    slab: Res<InstanceSlab>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
) {
    let Some(check) = frame.check.as_ref().filter(|_| frame.requested) else {
        return;
    };
    let (checked, Some(args), Some(kept)) = (&snapshot.draws, &snapshot.args, &snapshot.kept)
    else {
        // Nothing culled per instance this frame: the next frame that does is checked.
        check.request();
        return;
    };
    if checked.is_empty() {
        check.request();
        return;
    }
    // Both blocks of arguments: the early one, then the late one.
    let size = 2 * checked.len() as u64 * u64::from(ARGS_WORDS) * 4;
    let pool_size = checked
        .iter()
        .flat_map(|c| std::iter::once(&c.kept).chain(&c.late))
        .map(|r| r.end)
        .max()
        .unwrap_or(0);
    let (Some(words), Some(pool)) = (
        read_back(&device, &queue, args, size),
        read_back(&device, &queue, kept, pool_size),
    ) else {
        return;
    };
    let word = |draw: usize, k: usize| words[draw * ARGS_WORDS as usize + k];
    let count = |draw: usize| word(draw, 1);
    let mut report = CullingReport {
        slab_capacity: u64::from(slab.capacity()),
        ..default()
    };
    for (i, c) in checked.iter().enumerate() {
        let (early, late) = (count(i), count(checked.len() + i));
        compare_draw(&mut report, c, &pool, early, late);
        if !c.shadow {
            // The first word of an indexed or a direct draw's arguments: its vertices.
            let vertices = u64::from(word(i, 0));
            report.camera_vertices += vertices * u64::from(early + late);
        }
    }
    check.answer(report);
}

/// Adds one draw to the report: the instances the GPU kept (early and late phase) against
/// those the CPU's test keeps.
fn compare_draw(report: &mut CullingReport, c: &Checked, pool: &[u32], early: u32, late: u32) {
    let mut gpu = kept_words(pool, &c.kept, early);
    if let Some(range) = &c.late {
        gpu.extend(kept_words(pool, range, late));
    }
    let mut cpu: Vec<[u32; 6]> = c
        .instances
        .instances
        .iter()
        .filter(|g| c.record.keeps(&c.view, g))
        .map(|g| bytemuck::cast(*g))
        .collect();
    if c.view.light.w != 0.0 {
        let every_caster = CullView {
            light: Vec4::ZERO,
            ..c.view
        };
        let kept = c.instances.instances.iter();
        let kept = kept.filter(|g| c.record.keeps(&every_caster, g)).count();
        report.cascade_dropped += kept.saturating_sub(cpu.len()) as u64;
    }
    gpu.sort_unstable();
    cpu.sort_unstable();
    report.draws += 1;
    report.far_draws += usize::from(c.far);
    report.instances += c.instances.instances.len() as u64;
    report.occluding_draws += usize::from(c.pyramid);
    report.cascade_occluding_draws += usize::from(c.pyramid && c.shadow);
    report.gpu_kept += gpu.len() as u64;
    report.cpu_kept += cpu.len() as u64;
    if c.occludes {
        // What the pyramid hid is dropped from the frustum's instances, never added.
        report.late_kept += u64::from(late);
        cpu.dedup();
        if c.shadow {
            report.cascade_occluded += cpu.len().saturating_sub(gpu.len()) as u64;
        }
        report.mismatched += usize::from(gpu.iter().any(|g| cpu.binary_search(g).is_err()));
    } else {
        report.mismatched += usize::from(gpu != cpu || late != 0);
    }
}

/// The first `size` bytes of `buffer`, as words, once the GPU has done its work.
fn read_back(
    device: &RenderDevice,
    queue: &RenderQueue,
    buffer: &Buffer,
    size: u64,
) -> Option<Vec<u32>> {
    let size = size.max(4);
    let staging = device.create_buffer(&BufferDescriptor {
        label: Some("rwt_cull_check"),
        size,
        usage: BufferUsages::MAP_READ | BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor {
        label: Some("rwt_cull_check"),
    });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    let slice = staging.slice(..);
    slice.map_async(MapMode::Read, |_| {});
    device.poll(PollType::wait_indefinitely()).ok()?;
    let words = bytemuck::pod_collect_to_vec(&slice.get_mapped_range());
    Some(words)
}

/// The `count` instances kept at the start of the byte range `kept` of the pool.
fn kept_words(pool: &[u32], kept: &Range<u64>, count: u32) -> Vec<[u32; 6]> {
    let first = (kept.start / 4) as usize;
    let words = pool
        .get(first..first + count as usize * 6)
        .unwrap_or_default();
    words
        .chunks_exact(6)
        .map(|w| [w[0], w[1], w[2], w[3], w[4], w[5]])
        .collect()
}
