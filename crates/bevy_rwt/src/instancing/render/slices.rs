//! Where a mesh lies in Bevy's mesh allocator, as a direct draw and culling's indirect
//! arguments read it.

use bevy::prelude::{AssetId, Mesh};
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::mesh::{RenderMesh, RenderMeshBufferInfo};
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_phase::TrackedRenderPass;
use bevy::render::render_resource::{Buffer, IndexFormat};

/// Where a mesh lies in the mesh allocator's slabs: its vertex buffer, its index buffer and
/// format (indexed meshes), and the draw's arguments for an instance count of 0 (indexed:
/// index count, 0, first index, base vertex, 0; direct: vertex count, 0, first vertex, 0, 0),
/// as both the direct draw and culling's indirect arguments read them.
pub(super) struct MeshSlices<'a> {
    pub vertices: &'a Buffer,
    pub indices: Option<(&'a Buffer, IndexFormat)>,
    pub args: [u32; 5],
}

impl<'a> MeshSlices<'a> {
    /// Binds the mesh's vertices (slot 0) and indices.
    pub fn bind(&self, pass: &mut TrackedRenderPass<'a>) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        if let Some((buffer, format)) = self.indices {
            pass.set_index_buffer(buffer.slice(..), format);
        }
    }

    /// The slices of `mesh`, once it is prepared and allocated.
    pub fn of(
        meshes: &'a RenderAssets<RenderMesh>,
        allocator: &'a MeshAllocator,
        mesh: AssetId<Mesh>,
    ) -> Option<Self> {
        let info = meshes.get(mesh)?;
        let vertices = allocator.mesh_vertex_slice(&mesh)?;
        Some(match &info.buffer_info {
            RenderMeshBufferInfo::Indexed {
                index_format,
                count,
            } => {
                let indices = allocator.mesh_index_slice(&mesh)?;
                Self {
                    vertices: vertices.buffer,
                    indices: Some((indices.buffer, *index_format)),
                    args: [*count, 0, indices.range.start, vertices.range.start, 0],
                }
            }
            RenderMeshBufferInfo::NonIndexed => Self {
                vertices: vertices.buffer,
                indices: None,
                args: [vertices.range.len() as u32, 0, vertices.range.start, 0, 0],
            },
        })
    }
}
