//! What the instanced path requires of a class's mesh.

use super::GroundPlane;
use bevy::camera::primitives::MeshAabb;
use bevy::mesh::{MeshAccessError, PrimitiveTopology};
use bevy::prelude::*;
use bevy::render::render_resource::{TextureDimension, TextureFormat, TextureSampleType};

/// Why an instanced class cannot be drawn. Its chunks still stream and are counted; the
/// renderer skips them until the mesh is fixed (a reloaded or edited mesh is checked again).
/// An opaque value to reflection (it holds `wgpu` types).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error, Reflect)]
#[reflect(opaque, Clone, Debug, PartialEq)]
pub enum InstancedClassError {
    /// The mesh has no `Mesh::ATTRIBUTE_POSITION`.
    #[error("the mesh has no vertex positions")]
    MissingPositions,
    /// The mesh has positions but no vertex.
    #[error("the mesh has no vertices")]
    Empty,
    /// Points and lines cannot be shaded as surfaces.
    #[error("the mesh's topology is {0:?}; instanced classes draw triangle lists or strips")]
    Topology(PrimitiveTopology),
    /// An attribute does not have one value per vertex.
    #[error("the mesh's {attribute} has {len} values for {vertices} vertices")]
    AttributeLength {
        /// The attribute's name.
        attribute: String,
        /// Its values.
        len: usize,
        /// The positions.
        vertices: usize,
    },
    /// The layer lies on a plane the instanced path does not draw.
    #[error("instanced classes are drawn on GroundPlane::Xz only, not {0:?}")]
    Plane(GroundPlane),
    /// The class has a texture but its mesh has no `Mesh::ATTRIBUTE_UV_0` to read it by.
    #[error("the class has a texture but its mesh has no UV_0 coordinates")]
    MissingUvs,
    /// The texture is not one 2-D image of filterable colour.
    #[error(
        "the class's texture is a {dimension:?} image of {layers} layers in {format:?}; \
         textures must be one 2-D layer of a filterable colour format"
    )]
    Texture {
        /// Its dimension.
        dimension: TextureDimension,
        /// Its layers.
        layers: u32,
        /// Its format.
        format: TextureFormat,
    },
    /// The texture did not load.
    #[error("the class's texture did not load")]
    TextureNotLoaded,
    /// An asset class's file cannot be drawn (missing, garbled, or a part the instanced
    /// path cannot draw faithfully).
    #[cfg(feature = "gltf")]
    #[error("the class's asset cannot be drawn: {0}")]
    Asset(Box<super::asset::AssetLookError>),
}

/// Whether an image of this shape and format can be a class's texture.
pub(crate) fn check_texture(
    dimension: TextureDimension,
    layers: u32,
    format: TextureFormat,
) -> Result<(), InstancedClassError> {
    let filterable = matches!(
        format.sample_type(None, None),
        Some(TextureSampleType::Float { filterable: true })
    );
    if dimension == TextureDimension::D2 && layers == 1 && filterable {
        Ok(())
    } else {
        Err(InstancedClassError::Texture {
            dimension,
            layers,
            format,
        })
    }
}

/// Bounds of a mesh that the instanced path can draw (min, max), or why it cannot; `None`
/// while the mesh's data is not in the main world.
pub fn check_instanced_mesh(mesh: &Mesh) -> Option<Result<(Vec3, Vec3), InstancedClassError>> {
    if let Err(e) = check_topology(mesh.primitive_topology()) {
        return Some(Err(e));
    }
    let positions = match mesh.try_attribute(Mesh::ATTRIBUTE_POSITION) {
        Ok(p) => p.len(),
        Err(MeshAccessError::NotFound) => return Some(Err(InstancedClassError::MissingPositions)),
        // Render-world-only meshes keep only their bounds in the main world.
        Err(MeshAccessError::ExtractedToRenderWorld) => {
            return mesh
                .compute_aabb()
                .map(|a| Ok((a.min().into(), a.max().into())));
        }
    };
    if positions == 0 {
        return Some(Err(InstancedClassError::Empty));
    }
    for (attribute, values) in mesh.try_attributes().ok()? {
        if values.len() != positions {
            return Some(Err(InstancedClassError::AttributeLength {
                attribute: attribute.name.to_string(),
                len: values.len(),
                vertices: positions,
            }));
        }
    }
    let aabb = mesh.compute_aabb()?;
    Some(Ok((aabb.min().into(), aabb.max().into())))
}

/// Whether the instanced path draws meshes of this topology.
pub(crate) fn check_topology(topology: PrimitiveTopology) -> Result<(), InstancedClassError> {
    match topology {
        PrimitiveTopology::TriangleList | PrimitiveTopology::TriangleStrip => Ok(()),
        other => Err(InstancedClassError::Topology(other)),
    }
}
