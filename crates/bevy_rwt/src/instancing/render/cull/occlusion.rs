//! Occlusion for culling per instance, in a view with a `ViewDepthPyramid` of Bevy's: a
//! camera with `OcclusionCulling` and `DepthPrepass`, and the cascades of a directional
//! light with `OcclusionCulling` (under such a camera). A caster its cascade's depth hides
//! changes nothing in the shadow map, so the shadows lose nothing.
//!
//! The early phase runs with the rest of culling, before the frame's passes: an instance
//! last frame's pyramid hides, seen from last frame's view, is marked rather than kept. The
//! early depth prepass (or shadow pass) draws what was kept; Bevy reduces it into this
//! frame's pyramid; then [`cull_late`] tests the marked instances against it and keeps,
//! into each draw's late range, those it does not hide. The late prepass and late shadow
//! passes draw the late ranges only ([`LatePasses`](crate::instancing::render::draw::LatePasses)), the
//! main pass both. What the early depth holds, the frame holds too, so an instance seen
//! this frame is never dropped, however the view moved.

use super::culler::{InstanceCuller, ViewWork, grid};
use bevy::prelude::*;
use bevy::render::diagnostic::RecordDiagnostics;
use bevy::render::occlusion_culling::OcclusionCullingSubviewEntities;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, ViewQuery};

/// What every view's late phase shares this frame: the pipeline and the frame's bind group.
struct LatePhase<'a> {
    pipeline: &'a ComputePipeline,
    bind_group: &'a BindGroup,
}

impl InstanceCuller {
    fn late_phase<'a>(&'a self, cache: &'a PipelineCache) -> Option<LatePhase<'a>> {
        Some(LatePhase {
            pipeline: cache.get_compute_pipeline(self.pipeline?)?,
            bind_group: &self.bind.as_ref()?.bind_group,
        })
    }

    /// One view's late work this frame and the pyramid it tests against.
    fn late_work(&self, view: Entity) -> Option<(&ViewWork, &BindGroup)> {
        Some((self.late.get(&view)?, self.pyramids.bind_group(view)?))
    }
}

/// After the early depth prepass and shadow maps are reduced into their pyramids: culls
/// the instances the early phase hid against them, into each draw's late range, for the
/// camera and each of its cascades that occludes.
pub(in crate::instancing) fn cull_late(
    view: ViewQuery<(Entity, Option<&OcclusionCullingSubviewEntities>)>,
    culler: Option<Res<InstanceCuller>>,
    cache: Res<PipelineCache>,
    mut ctx: RenderContext,
) {
    let Some(culler) = culler else { return };
    let (camera, cascades) = view.into_inner();
    let cascades = cascades.map(|c| c.0.as_slice()).unwrap_or_default();
    let views: Vec<_> = std::iter::once(&camera)
        .chain(cascades)
        .filter_map(|&view| culler.late_work(view))
        .collect();
    let Some(phase) = culler.late_phase(&cache).filter(|_| !views.is_empty()) else {
        return;
    };
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    let mut pass = ctx
        .command_encoder()
        .begin_compute_pass(&ComputePassDescriptor {
            label: Some("rwt_cull_late"),
            timestamp_writes: None,
        });
    let span = diagnostics.pass_span(&mut pass, "rwt_cull_late");
    pass.set_pipeline(phase.pipeline);
    for (work, pyramid) in views {
        pass.set_bind_group(1, pyramid, &[]);
        pass.set_bind_group(0, phase.bind_group, &[work.params, work.pool as u32]);
        let (x, y) = grid(work.workgroups);
        pass.dispatch_workgroups(x, y, 1);
    }
    span.end(&mut pass);
}
