//! Pipelines: the instance buffer's vertex layout and the choice of a chunk's specialized
//! pipeline, shared by the main pass and the depth passes.

use super::extract::ExtractedChunk;
use crate::instancing::chunk::GpuInstance;
use crate::look::check_topology;
use bevy::mesh::VertexBufferLayout;
use bevy::pbr::MeshPipelineKey;
use bevy::platform::collections::HashSet;
use bevy::prelude::*;
use bevy::render::mesh::RenderMesh;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::*;

/// Shader locations of the instance attributes (after every mesh attribute).
const INSTANCE_LOCATIONS: [u32; 2] = [8, 9];

/// Meshes that cannot be drawn, reported once each.
#[derive(Resource, Default)]
pub(in crate::instancing) struct ReportedMeshes(HashSet<AssetId<Mesh>>);

impl ReportedMeshes {
    /// Logs why `mesh` cannot be drawn, the first time only.
    pub(super) fn once(&mut self, mesh: AssetId<Mesh>, reason: &str) {
        if self.0.insert(mesh) {
            error!("instanced class mesh {mesh:?} cannot be drawn: {reason}");
        }
    }
}

/// The instance buffer's layout: offset and scale, then yaw, appearance and tint.
pub(super) fn instance_layout() -> VertexBufferLayout {
    VertexBufferLayout {
        array_stride: size_of::<GpuInstance>() as u64,
        step_mode: VertexStepMode::Instance,
        attributes: vec![
            VertexAttribute {
                format: VertexFormat::Float32x4,
                offset: 0,
                shader_location: INSTANCE_LOCATIONS[0],
            },
            VertexAttribute {
                format: VertexFormat::Unorm16x4,
                offset: 16,
                shader_location: INSTANCE_LOCATIONS[1],
            },
        ],
    }
}

/// What choosing a chunk's pipeline reads: the pipelines of specializer `S`, the meshes,
/// and the meshes already reported as undrawable.
#[derive(bevy::ecs::system::SystemParam)]
pub(in crate::instancing) struct ChunkPipelines<'w, S: SpecializedMeshPipeline + Resource>
where
    S::Key: Send + Sync,
{
    specializer: Option<Res<'w, S>>,
    pipelines: ResMut<'w, SpecializedMeshPipelines<S>>,
    cache: Res<'w, PipelineCache>,
    meshes: Res<'w, RenderAssets<RenderMesh>>,
    reported: ResMut<'w, ReportedMeshes>,
}

impl<S: SpecializedMeshPipeline + Resource> ChunkPipelines<'_, S>
where
    S::Key: Send + Sync,
{
    /// The pipeline drawing `chunk` under the key `key` makes of the mesh's topology bits,
    /// or `None` (the reason logged once when the mesh cannot be drawn; nothing while the
    /// mesh or the specializer is not ready).
    pub(super) fn of(
        &mut self,
        chunk: &ExtractedChunk,
        key: impl FnOnce(MeshPipelineKey) -> S::Key,
    ) -> Option<CachedRenderPipelineId> {
        let specializer = self.specializer.as_deref()?;
        let mesh = self.meshes.get(chunk.mesh)?;
        let topology = MeshPipelineKey::from_primitive_topology_and_strip_index(
            mesh.primitive_topology(),
            mesh.index_format(),
        );
        let specialized = check_topology(mesh.primitive_topology())
            .map_err(|e| e.to_string())
            .and_then(|()| {
                self.pipelines
                    .specialize(&self.cache, specializer, key(topology), &mesh.layout)
                    .map_err(|e| e.to_string())
            });
        specialized
            .map_err(|e| self.reported.once(chunk.mesh, &e))
            .ok()
    }
}
