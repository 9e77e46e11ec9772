//! The frame's culling: laid out and written after queueing ([`cull_instances`]), the
//! early phase encoded at the start of the render graph ([`encode_cull`]).

use super::culler::{ARGS_WORDS, CulledDraw, FrameBind, InstanceCuller, ViewWork, grid};
use super::entries::{CullEntry, CullInputs};
use super::layout::Plan;
use super::params::CullView;
use crate::instancing::settings::InstanceCulling;
use bevy::prelude::*;
use bevy::render::diagnostic::{DiagnosticsRecorder, RecordDiagnostics};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue};
use std::num::NonZero;

/// Lays out and writes the culling of every chunk binned into every view, and records the
/// culled draws ([`encode_cull`] encodes the work).
pub(in crate::instancing) fn cull_instances(
    mut culler: ResMut<InstanceCuller>,
    inputs: CullInputs,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    cache: Res<PipelineCache>,
    #[cfg(feature = "testing")] mut check: super::check::Publish,
) {
    culler.draws.clear();
    culler.early.clear();
    culler.late.clear();
    #[cfg(feature = "testing")]
    check.clear();
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
    let entries = inputs.entries(&views);
    if entries.is_empty() {
        return;
    }
    let Some(slab) = inputs.slab.buffer() else {
        return;
    };
    let Some(mut plan) = culler.lay_out(&entries, &device) else {
        return;
    };
    culler.write(&entries, &mut plan, &device, &queue);
    culler.bind(slab, plan.pool_binding, &device, &cache);
    if culler.bind.is_none() {
        culler.late.clear();
        return;
    }
    culler.early = plan.early;
    #[cfg(feature = "testing")]
    check.publish(culler, &entries, &plan.draws);
    culler.record(&entries, plan.draws);
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

    /// Records this frame's culled draws by (view, chunk).
    fn record(&mut self, entries: &[CullEntry], draws: Vec<CulledDraw>) {
        for (d, draw) in entries.iter().zip(draws) {
            self.draws
                .entry((d.view.entity, d.chunk))
                .or_default()
                .push(draw);
        }
    }
}

impl InstanceCuller {
    /// Writes the records, each view's settings (their offsets into `plan`; a late phase's
    /// where the view occludes) and the arguments (both blocks with no instances).
    fn write(
        &mut self,
        entries: &[CullEntry],
        plan: &mut Plan,
        device: &RenderDevice,
        queue: &RenderQueue,
    ) {
        let late_block = entries.len() as u32 * ARGS_WORDS;
        for r in &mut plan.records {
            r.late_count_word = late_block + r.count_word;
        }
        self.records.set(std::mem::take(&mut plan.records));
        self.records.write_buffer(device, queue);
        self.views.clear();
        for work in &mut plan.early {
            let d = &entries[work.records.start as usize];
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
                    let late = CullView {
                        clip_from_world: current,
                        phase: 2,
                        ..early
                    };
                    let params = self.views.push(late);
                    let late = ViewWork {
                        params,
                        settings: late,
                        ..work.clone()
                    };
                    self.late.insert(d.view.entity, late);
                    CullView {
                        clip_from_world: previous,
                        phase: 1,
                        ..early
                    }
                }
                None => early,
            };
            work.params = self.views.push(early);
            work.settings = early;
        }
        self.views.write_buffer(device, queue);
        let args: Vec<u32> = entries.iter().flat_map(|d| d.args).collect();
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
