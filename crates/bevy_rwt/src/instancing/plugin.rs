//! The instancing feature plugin: the wind resource, and the render-world systems that draw
//! every [`InstancedChunk`] with one instanced draw.

use super::{InstancedChunk, InstancedMeshes, RwtFadeIn, RwtWind};
use super::{mesh, render};
use crate::settings::RwtSystems;
use bevy::asset::embedded_asset;
use bevy::core_pipeline::core_3d::Transparent3d;
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::pbr::MeshPipelineSystems;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponentPlugin;
use bevy::render::extract_resource::ExtractResourcePlugin;
use bevy::render::render_phase::AddRenderCommand;
use bevy::render::render_resource::SpecializedMeshPipelines;
use bevy::render::{Render, RenderApp, RenderStartup, RenderSystems};

/// Draws instanced classes (part of [`crate::RwtPlugin`]) and reports classes it cannot
/// draw in their layer's [`crate::ScatterLayerStatus::class_errors`]. Without a renderer
/// (headless apps, tests) chunk buffers are still made and counted.
pub struct RwtInstancingPlugin {
    /// Schedule of the main-world systems.
    pub schedule: InternedScheduleLabel,
}

impl Plugin for RwtInstancingPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<RwtWind>()
            .init_resource::<RwtFadeIn>()
            .init_resource::<InstancedMeshes>()
            .add_systems(
                self.schedule,
                (
                    mesh::refit_changed_meshes.before(RwtSystems::Apply),
                    mesh::report_class_errors
                        .after(RwtSystems::Apply)
                        .before(RwtSystems::Stats),
                ),
            );
        if app.get_sub_app(RenderApp).is_none() {
            return;
        }
        embedded_asset!(app, "instanced.wgsl");
        app.add_plugins((
            ExtractComponentPlugin::<InstancedChunk>::default(),
            ExtractResourcePlugin::<RwtWind>::default(),
            ExtractResourcePlugin::<RwtFadeIn>::default(),
        ));
        let render_app = app.sub_app_mut(RenderApp);
        render_app
            .add_render_command::<Transparent3d, render::DrawInstancedChunk>()
            .init_resource::<SpecializedMeshPipelines<render::InstancedPipeline>>()
            .init_resource::<render::ReportedMeshes>()
            .add_systems(
                RenderStartup,
                render::init_pipeline.after(MeshPipelineSystems),
            )
            .add_systems(
                Render,
                (
                    render::prepare_chunks.in_set(RenderSystems::PrepareResources),
                    render::queue_chunks.in_set(RenderSystems::QueueMeshes),
                ),
            );
    }
}
