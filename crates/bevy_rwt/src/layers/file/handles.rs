//! Where a layer file's paths and primitives get their handles: [`LayerHandles`].

use super::{
    LayerFileError, MaterialDescription, MeshDescription, NamedAssets, NamedKind, unknown,
};
use bevy::prelude::*;

/// Where [`LayerDescription::to_layer`](super::LayerDescription::to_layer) gets the handles
/// of what a file names by path or describes: in an asset loader, loads and labelled
/// sub-assets of the layer file.
pub trait LayerHandles {
    /// A mesh's handle: a loaded path, or a primitive made.
    fn mesh(&mut self, mesh: &MeshDescription) -> Handle<Mesh>;
    /// The material of a class that is not instanced: a loaded path, or a colour made.
    fn material(&mut self, material: &MaterialDescription) -> Handle<StandardMaterial>;
    /// An image (density map, heightmap, texture) loaded from its path.
    fn image(&mut self, path: &str) -> Handle<Image>;
    /// A glTF file loaded from its path (without a label), for an asset class.
    #[cfg(feature = "gltf")]
    fn gltf(&mut self, path: &str) -> Handle<bevy::gltf::Gltf>;
}

/// Default handles for everything a file names: a layer to check or inspect, not to draw.
#[derive(Clone, Copy, Debug, Default)]
pub struct Placeholders;

impl LayerHandles for Placeholders {
    fn mesh(&mut self, _: &MeshDescription) -> Handle<Mesh> {
        Handle::default()
    }

    fn material(&mut self, _: &MaterialDescription) -> Handle<StandardMaterial> {
        Handle::default()
    }

    fn image(&mut self, _: &str) -> Handle<Image> {
        Handle::default()
    }

    #[cfg(feature = "gltf")]
    fn gltf(&mut self, _: &str) -> Handle<bevy::gltf::Gltf> {
        Handle::default()
    }
}

/// Named assets and the handles of the rest.
pub(super) struct Handles<'a, H> {
    pub names: &'a NamedAssets,
    pub handles: &'a mut H,
}

impl<H: LayerHandles> Handles<'_, H> {
    pub fn mesh(&mut self, d: &MeshDescription) -> Result<Handle<Mesh>, LayerFileError> {
        match d {
            MeshDescription::Named(name) => self
                .names
                .mesh(name)
                .ok_or_else(|| unknown(NamedKind::Mesh, name)),
            other => Ok(self.handles.mesh(other)),
        }
    }

    pub fn material(
        &mut self,
        d: &MaterialDescription,
    ) -> Result<Handle<StandardMaterial>, LayerFileError> {
        match d {
            MaterialDescription::Named(name) => self
                .names
                .material(name)
                .ok_or_else(|| unknown(NamedKind::Material, name)),
            other => Ok(self.handles.material(other)),
        }
    }
}
