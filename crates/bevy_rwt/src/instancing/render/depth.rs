//! Depth of chunks: the depth, normal and motion-vector prepasses of views that have them,
//! and the shadow maps of shadow-casting lights (directional cascades, point and spot
//! lights), culled per shadow view by each chunk's bounds and chosen by each class's
//! [`InstancedShadows`](crate::look::InstancedShadows). The deferred G-buffer is not
//! written: under a deferred camera chunks are drawn forward.

use super::draw::{DrawChunkInstances, SetChunkBindGroup};
use super::extract::{ClassFeatures, ExtractedChunk};
use super::main_pass::{mesh_attributes, mesh_bin};
use super::pipelines::{ChunkPipelines, instance_layout};
use super::prepare::{ChunkBindings, MainViewer};
use super::receivers::CascadeReceivers;
use super::retained::{Queued, rebin_cameras};
use crate::instancing::chunk::distance_to_box;
use crate::look::InstancedShadows;
use bevy::camera::primitives::{Aabb, Frustum};
use bevy::camera::visibility::RenderLayers;
use bevy::core_pipeline::core_3d::CORE_3D_DEPTH_FORMAT;
use bevy::core_pipeline::prepass::{
    Opaque3dPrepass, OpaqueNoLightmap3dBatchSetKey, OpaqueNoLightmap3dBinKey,
    prepass_target_descriptors,
};
use bevy::mesh::MeshVertexBufferLayoutRef;
use bevy::pbr::{
    LightEntity, LightKeyCache, MeshPipelineKey, PrepassPipeline, SetPrepassViewBindGroup,
    SetPrepassViewEmptyBindGroup, Shadow, ShadowBatchSetKey, ShadowBinKey, ViewKeyPrepassCache,
};
use bevy::prelude::*;
use bevy::render::mesh::allocator::MeshSlabs;
use bevy::render::render_phase::{DrawFunctions, SetItemPipeline, ViewBinnedRenderPhases};
use bevy::render::render_resource::*;
use bevy::render::sync_world::MainEntity;
use bevy::render::view::{ExtractedView, RenderVisibleEntities};
use bevy::shader::ShaderDefVal;

/// The draw of one chunk into a prepass or a shadow map.
pub(in crate::instancing) type DrawInstancedDepth = (
    SetItemPipeline,
    SetPrepassViewBindGroup<0>,
    SetPrepassViewEmptyBindGroup<1>,
    SetChunkBindGroup<2>,
    DrawChunkInstances,
);

/// The depth pipeline: Bevy's prepass view layouts with our shader.
#[derive(Resource)]
pub(in crate::instancing) struct InstancedDepthPipeline {
    prepass: PrepassPipeline,
    bindings: ChunkBindings,
}

/// A depth pipeline's key: the view's and mesh's bits, and whether it draws a shadow map
/// (instances grow as the main camera sees them there, not as the light does).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(in crate::instancing) struct DepthKey {
    mesh: MeshPipelineKey,
    shadow: bool,
    /// The class's features (a textured class's cut-out discards fragments here too).
    features: ClassFeatures,
}

pub(in crate::instancing) fn init_depth_pipeline(
    mut commands: Commands,
    prepass: Option<Res<PrepassPipeline>>,
    bindings: Res<ChunkBindings>,
) {
    if let Some(prepass) = prepass {
        commands.insert_resource(InstancedDepthPipeline {
            prepass: prepass.clone(),
            bindings: bindings.clone(),
        });
    }
}

impl SpecializedMeshPipeline for InstancedDepthPipeline {
    type Key = DepthKey;

    fn specialize(
        &self,
        key: Self::Key,
        layout: &MeshVertexBufferLayoutRef,
    ) -> Result<RenderPipelineDescriptor, SpecializedMeshPipelineError> {
        let k = key.mesh;
        let normals = k.contains(MeshPipelineKey::NORMAL_PREPASS);
        let motion = k.contains(MeshPipelineKey::MOTION_VECTOR_PREPASS);
        let emulate_unclipped = k.contains(MeshPipelineKey::UNCLIPPED_DEPTH_ORTHO)
            && !self.prepass.depth_clip_control_supported;
        let mut defs: Vec<ShaderDefVal> = vec!["PREPASS_PIPELINE".into()];
        let attributes = mesh_attributes(layout, key.features, &mut defs);
        for (on, def) in [
            (normals, "NORMAL_PREPASS"),
            (motion, "MOTION_VECTOR_PREPASS"),
            (emulate_unclipped, "UNCLIPPED_DEPTH_ORTHO_EMULATION"),
            (key.shadow, "RWT_SHADOW_PASS"),
        ] {
            if on {
                defs.push(def.into());
            }
        }
        // Every prepass attachment, in the pass's order (None where unused).
        let targets = prepass_target_descriptors(normals, motion, false);
        let writes = normals || motion || emulate_unclipped;
        if writes {
            defs.push("PREPASS_FRAGMENT".into());
        }
        // A textured class needs the fragment stage to cut out, even for depth alone, and a
        // class fading out to dither.
        let fragment =
            (writes || key.features.textured || key.features.fades_out || key.features.fades_in)
                .then(|| FragmentState {
                    shader: self.bindings.shader.clone(),
                    shader_defs: defs.clone(),
                    targets: if normals || motion { targets } else { vec![] },
                    ..default()
                });
        let view_layout = if motion {
            self.prepass.view_layout_motion_vectors.clone()
        } else {
            self.prepass.view_layout_no_motion_vectors.clone()
        };
        Ok(RenderPipelineDescriptor {
            label: Some("rwt_instanced_depth_pipeline".into()),
            layout: vec![
                view_layout,
                self.prepass.empty_layout.clone(),
                self.bindings.layout.clone(),
            ],
            vertex: VertexState {
                shader: self.bindings.shader.clone(),
                shader_defs: defs,
                buffers: vec![layout.0.get_layout(&attributes)?, instance_layout()],
                ..default()
            },
            fragment,
            primitive: PrimitiveState {
                topology: k.primitive_topology(),
                strip_index_format: k.strip_index_format(),
                unclipped_depth: k.contains(MeshPipelineKey::UNCLIPPED_DEPTH_ORTHO)
                    && self.prepass.depth_clip_control_supported,
                cull_mode: key.features.cull_mode(),
                ..default()
            },
            depth_stencil: Some(DepthStencilState {
                format: CORE_3D_DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(CompareFunction::GreaterEqual),
                stencil: default(),
                bias: default(),
            }),
            multisample: MultisampleState {
                count: k.msaa_samples(),
                ..default()
            },
            ..default()
        })
    }
}

/// Bins every chunk visible from each view with a depth, normal or motion-vector prepass
/// into its opaque prepass phase.
pub(in crate::instancing) fn queue_prepass(
    draw_functions: Res<DrawFunctions<Opaque3dPrepass>>,
    mut pipelines: ChunkPipelines<InstancedDepthPipeline>,
    chunks: Query<&ExtractedChunk>,
    mut phases: ResMut<ViewBinnedRenderPhases<Opaque3dPrepass>>,
    views: Query<(&ExtractedView, &RenderVisibleEntities)>,
    view_keys: Res<ViewKeyPrepassCache>,
    mut queued: ResMut<Queued<Opaque3dPrepass>>,
) {
    let draw = draw_functions.read().id::<DrawInstancedDepth>();
    let key_of = |view: &_| view_keys.get(view).copied();
    rebin_cameras(
        &mut phases,
        &mut queued,
        &views,
        key_of,
        |view_key, entity, main| {
            let chunk = chunks.get(entity).ok()?;
            let id = pipelines.of(chunk, |topology| DepthKey {
                mesh: view_key | topology,
                shadow: false,
                features: chunk.features(),
            })?;
            let batch_set = OpaqueNoLightmap3dBatchSetKey {
                draw_function: draw,
                pipeline: id,
                material_bind_group_index: None,
                slabs: MeshSlabs::default(),
            };
            let bin = OpaqueNoLightmap3dBinKey {
                asset_id: mesh_bin(chunk.mesh),
            };
            Some((batch_set, bin, (entity, main)))
        },
    );
}

/// A shadow view: where it looks (a directional light's frustum reaches to the light), and
/// what it draws.
type ShadowView<'a> = (
    Entity,
    &'a ExtractedView,
    Option<&'a Frustum>,
    Option<&'a RenderLayers>,
);

/// Bins the chunks that cast (their class's setting, their distance to the main camera)
/// and that each shadow view's frustum holds, where a directional light's cascade is read,
/// into its shadow phase.
#[allow(clippy::too_many_arguments)]
pub(in crate::instancing) fn queue_shadows(
    draw_functions: Res<DrawFunctions<Shadow>>,
    mut pipelines: ChunkPipelines<InstancedDepthPipeline>,
    chunks: Query<(Entity, &MainEntity, &ExtractedChunk)>,
    mut phases: ResMut<ViewBinnedRenderPhases<Shadow>>,
    views: Query<ShadowView, With<LightEntity>>,
    light_keys: Res<LightKeyCache>,
    viewer: Res<MainViewer>,
    mut queued: ResMut<Queued<Shadow>>,
    receivers: Res<CascadeReceivers>,
) {
    let draw = draw_functions.read().id::<DrawInstancedDepth>();
    let casting: Vec<_> = chunks
        .iter()
        .filter(|(_, _, chunk)| casts(chunk, viewer.0))
        .collect();
    for (entity, view, frustum, layers) in &views {
        let Some(phase) = phases.get_mut(&view.retained_view_entity) else {
            continue;
        };
        let light_key = light_keys.get(&view.retained_view_entity).copied();
        let sees_chunks = layers.is_none_or(|l| l.intersects(&RenderLayers::default()));
        let read = receivers.of(entity);
        let items = casting
            .iter()
            .filter(|_| sees_chunks)
            .filter(|(_, _, chunk)| {
                frustum.is_none_or(|f| f.intersects_obb_identity(&chunk.bounds))
                    && read.is_none_or(|r| r.may_cast(&chunk.bounds))
            })
            .filter_map(|&(entity, main_entity, chunk)| {
                let light_key = light_key?;
                let id = pipelines.of(chunk, |topology| DepthKey {
                    mesh: light_key | topology,
                    shadow: true,
                    features: chunk.features(),
                })?;
                let batch_set = ShadowBatchSetKey {
                    pipeline: id,
                    draw_function: draw,
                    material_bind_group_index: None,
                    slabs: MeshSlabs::default(),
                };
                let bin = ShadowBinKey {
                    asset_id: mesh_bin(chunk.mesh),
                };
                Some((batch_set, bin, (entity, *main_entity)))
            });
        queued.rebin_phase(view.retained_view_entity, phase, items.collect::<Vec<_>>());
    }
    queued.end_frame();
}

/// Whether a chunk casts: its class's setting at its distance from the main camera.
fn casts(chunk: &ExtractedChunk, viewer: Option<Vec3>) -> bool {
    shadows_at(&chunk.bounds, chunk.shadows, viewer)
}

/// Whether `shadows` cast for bounds `aabb` seen from `viewer` (at any distance when there
/// is no camera).
fn shadows_at(aabb: &Aabb, shadows: InstancedShadows, viewer: Option<Vec3>) -> bool {
    let distance = viewer.map_or(0.0, |eye| distance_to_box(aabb, eye));
    shadows.casts_at(distance)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chunk_casts_by_its_class_setting_and_its_distance_to_the_camera() {
        let bounds = Aabb::from_min_max(Vec3::new(10.0, 0.0, 0.0), Vec3::new(26.0, 1.0, 16.0));
        assert_eq!(distance_to_box(&bounds, Vec3::new(15.0, 0.5, 5.0)), 0.0);
        assert_eq!(distance_to_box(&bounds, Vec3::new(0.0, 1.0, 8.0)), 10.0);
        assert_eq!(distance_to_box(&bounds, Vec3::new(29.0, 5.0, 16.0)), 5.0);
        let near = |shadows| {
            let eye = Some(Vec3::new(-20.0, 1.0, 8.0));
            shadows_at(&bounds, shadows, eye)
        };
        assert!(near(InstancedShadows::On));
        assert!(!near(InstancedShadows::Off));
        assert!(near(InstancedShadows::Within(30.0)));
        assert!(!near(InstancedShadows::Within(29.0)));
        // Without a camera only the distance-free settings hold.
        assert!(shadows_at(&bounds, InstancedShadows::Within(1.0), None));
    }
}
