//! The instancing feature plugin: the wind resource, and the render-world systems that draw
//! every [`InstancedChunk`] with one instanced draw.

use super::bend::{self, BendField, Bender};
use super::chunk::InstancedChunk;
use super::mesh::{self, InstancedMeshes};
use super::settings::{CascadeCasters, InstanceCulling, RwtFadeIn, RwtWind};
use super::{far, render};
use crate::settings::{RwtSystems, configure_sets, in_schedule};
use bevy::core_pipeline::core_3d::Opaque3d;
use bevy::core_pipeline::mip_generation::experimental::depth::early_downsample_depth;
use bevy::core_pipeline::prepass::Opaque3dPrepass;
use bevy::core_pipeline::prepass::node::late_prepass;
use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::ecs::schedule::{InternedScheduleLabel, ScheduleConfigs};
use bevy::ecs::system::ScheduleSystem;
use bevy::pbr::{
    LATE_SHADOW_PASS, MeshPipelineSystems, Shadow, init_prepass_pipeline, per_view_shadow_pass,
    shared_shadow_pass,
};
use bevy::prelude::*;
use bevy::render::diagnostic::begin_diagnostics_frame;
use bevy::render::extract_component::ExtractComponentPlugin;
use bevy::render::extract_resource::ExtractResourcePlugin;
use bevy::render::render_phase::AddRenderCommand;
use bevy::render::render_resource::SpecializedMeshPipelines;
use bevy::render::renderer::{RenderGraph, RenderGraphSystems};
use bevy::render::{Render, RenderApp, RenderStartup, RenderSystems};

/// Draws instanced classes (part of [`crate::RwtPlugins`]) and reports classes it cannot
/// draw in their layer's [`crate::ScatterLayerStatus::class_errors`]. Without a renderer
/// (headless apps, tests), or without this part, chunk buffers are still made and counted.
pub struct RwtInstancingPlugin {
    schedule: InternedScheduleLabel,
}

in_schedule!(RwtInstancingPlugin);

impl Plugin for RwtInstancingPlugin {
    fn build(&self, app: &mut App) {
        configure_sets(app, self.schedule);
        app.init_resource::<RwtWind>()
            .init_resource::<RwtFadeIn>()
            .init_resource::<InstanceCulling>()
            .init_resource::<CascadeCasters>()
            .init_resource::<InstancedMeshes>()
            .init_resource::<BendField>()
            .init_resource::<crate::impostor::ImpostorAtlases>()
            .register_type::<Bender>()
            .register_type::<BendField>()
            .register_type::<RwtWind>()
            .register_type::<RwtFadeIn>()
            .register_type::<InstanceCulling>()
            .register_type::<CascadeCasters>()
            .register_type::<InstancedChunk>()
            .add_systems(
                self.schedule,
                (
                    // The bake writes meshes and images: before planning reads them.
                    crate::impostor::bake_impostors
                        .after(RwtSystems::Viewers)
                        .before(RwtSystems::Plan)
                        .before(mesh::refit_changed_meshes),
                    mesh::refit_changed_meshes.before(RwtSystems::Apply),
                    bend::update_bend_field,
                    (far::choose_chunk_meshes, mesh::report_class_errors)
                        .chain()
                        .after(RwtSystems::Apply)
                        .before(RwtSystems::Stats),
                ),
            );
        #[cfg(feature = "gltf")]
        crate::look::asset::register_msft_lod(app);
        #[cfg(feature = "gltf")]
        app.init_resource::<super::ResolvedAssets>()
            .register_type::<crate::look::asset::AssetCollider>()
            .add_systems(
                self.schedule,
                // It adds meshes: before the bake and planning read them.
                (
                    super::assets::resolve_asset_looks,
                    super::assets::bake_asset_impostors,
                )
                    .chain()
                    .after(RwtSystems::Viewers)
                    .before(crate::impostor::bake_impostors)
                    .before(RwtSystems::Plan),
            );
        if app.get_sub_app(RenderApp).is_some() {
            build_render(app);
        }
    }
}

/// The render world's part: extraction, pipelines, queueing, culling (and its check, with
/// feature `testing`), draws.
fn build_render(app: &mut App) {
    render::embed_shader(app);
    app.add_plugins((
        ExtractComponentPlugin::<InstancedChunk>::default(),
        ExtractResourcePlugin::<RwtWind>::default(),
        ExtractResourcePlugin::<RwtFadeIn>::default(),
        ExtractResourcePlugin::<InstanceCulling>::default(),
        ExtractResourcePlugin::<CascadeCasters>::default(),
        ExtractResourcePlugin::<BendField>::default(),
    ));
    #[cfg(feature = "testing")]
    build_culling_check(app.sub_app_mut(RenderApp));
    let render_app = app.sub_app_mut(RenderApp);
    render_app
        .add_render_command::<Opaque3d, render::DrawInstancedChunk>()
        .add_render_command::<Opaque3dPrepass, render::DrawInstancedDepth>()
        .add_render_command::<Shadow, render::DrawInstancedDepth>()
        .init_resource::<SpecializedMeshPipelines<render::InstancedPipeline>>()
        .init_resource::<SpecializedMeshPipelines<render::InstancedDepthPipeline>>()
        .init_resource::<render::ReportedMeshes>()
        .init_resource::<render::MainViewer>()
        .init_resource::<render::InstanceSlab>()
        .init_resource::<render::Queued<Opaque3d>>()
        .init_resource::<render::Queued<Opaque3dPrepass>>()
        .init_resource::<render::Queued<Shadow>>()
        .init_resource::<render::CascadeReceivers>()
        .init_resource::<render::LatePasses>()
        .add_systems(
            RenderStartup,
            (
                render::init_bindings,
                render::init_main_pipeline.after(MeshPipelineSystems),
                render::init_depth_pipeline.after(init_prepass_pipeline),
                render::init_culler,
            )
                .chain(),
        )
        .add_systems(
            Render,
            (
                // After the lights' shadow views are made, before the shadow queue.
                render::find_receivers.in_set(RenderSystems::PrepareViews),
                (render::prepare_frame, render::prepare_chunks)
                    .in_set(RenderSystems::PrepareResources),
                (
                    render::queue_main,
                    render::queue_prepass,
                    render::queue_shadows,
                )
                    .in_set(RenderSystems::QueueMeshes),
                render::cull_instances.in_set(RenderSystems::PrepareBindGroups),
            ),
        )
        .add_systems(
            RenderGraph,
            // After the diagnostics' frame begins, so the culling's GPU time is this frame's.
            render::encode_cull
                .in_set(RenderGraphSystems::Begin)
                .after(begin_diagnostics_frame),
        )
        .add_systems(Core3d, late_phase());
}

/// Culling's late phase, between Bevy's early depth pyramid and its late prepass and late
/// shadow passes, and the brackets that let those passes draw only what it kept.
fn late_phase() -> ScheduleConfigs<ScheduleSystem> {
    (
        render::cull_late
            .after(early_downsample_depth)
            .before(late_prepass)
            .before(per_view_shadow_pass::<LATE_SHADOW_PASS>)
            .before(shared_shadow_pass::<LATE_SHADOW_PASS>),
        render::begin_late_passes
            .after(early_downsample_depth)
            .before(late_prepass)
            .before(per_view_shadow_pass::<LATE_SHADOW_PASS>)
            .before(shared_shadow_pass::<LATE_SHADOW_PASS>),
        render::end_late_passes
            .after(late_prepass)
            .after(per_view_shadow_pass::<LATE_SHADOW_PASS>)
            .after(shared_shadow_pass::<LATE_SHADOW_PASS>)
            .before(Core3dSystems::MainPass),
    )
        .into_configs()
}

/// The culling check (feature `testing`): the frame it asks for is extracted, and read
/// back once the frame is rendered.
#[cfg(feature = "testing")]
fn build_culling_check(render_app: &mut SubApp) {
    render_app
        .init_resource::<render::FrameCheck>()
        .init_resource::<render::CullSnapshot>()
        .add_systems(ExtractSchedule, render::extract_culling_check)
        .add_systems(
            Render,
            render::check_culling
                .after(RenderSystems::Render)
                .before(RenderSystems::Cleanup),
        );
}
