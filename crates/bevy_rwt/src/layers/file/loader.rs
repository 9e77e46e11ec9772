//! The asset loader of layer files.

use super::{
    LayerDescription, LayerFileError, LayerHandles, MAX_LAYER_FILE_BYTES, MaterialDescription,
    MeshDescription, NamedAssets, ScatterLayerAsset,
};
use bevy::asset::{AssetLoader, AssetPath, AsyncReadExt, LoadContext, io::Reader};
use bevy::prelude::*;

/// Loads `.layer.ron` files, looking names up in the [`NamedAssets`] it was made with.
#[derive(Default, TypePath)]
pub struct ScatterLayerLoader {
    /// The names layer files may use.
    pub names: NamedAssets,
}

impl AssetLoader for ScatterLayerLoader {
    type Asset = ScatterLayerAsset;
    type Settings = ();
    type Error = LayerFileError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _: &(),
        ctx: &mut LoadContext<'_>,
    ) -> Result<ScatterLayerAsset, LayerFileError> {
        let mut bytes = Vec::new();
        AsyncReadExt::take(reader, MAX_LAYER_FILE_BYTES + 1)
            .read_to_end(&mut bytes)
            .await?;
        if bytes.len() as u64 > MAX_LAYER_FILE_BYTES {
            return Err(LayerFileError::TooLarge {
                limit: MAX_LAYER_FILE_BYTES,
            });
        }
        let text = std::str::from_utf8(&bytes)?;
        let description = LayerDescription::from_ron(text)?;
        let layer = description.to_layer(
            &self.names,
            &mut Loads {
                ctx,
                meshes: 0,
                materials: 0,
            },
        )?;
        Ok(ScatterLayerAsset(layer))
    }

    fn extensions(&self) -> &[&str] {
        &["layer.ron"]
    }
}

/// A layer file's handles: loads (its dependencies, so that it reloads with them), and its
/// primitive meshes and plain colours as labelled sub-assets.
struct Loads<'a, 'c> {
    ctx: &'a mut LoadContext<'c>,
    meshes: usize,
    materials: usize,
}

impl Loads<'_, '_> {
    fn load<A: Asset>(&mut self, path: &str) -> Handle<A> {
        let path = relative_to(self.ctx.path(), path);
        self.ctx.load(path)
    }
}

impl LayerHandles for Loads<'_, '_> {
    fn mesh(&mut self, mesh: &MeshDescription) -> Handle<Mesh> {
        let label = format!("mesh{}", self.meshes);
        self.meshes += 1;
        match mesh.primitive() {
            Ok(mesh) => self.ctx.add_labeled_asset(label, mesh),
            Err(path) => self.load(path),
        }
    }

    fn material(&mut self, material: &MaterialDescription) -> Handle<StandardMaterial> {
        let label = format!("material{}", self.materials);
        self.materials += 1;
        match material {
            MaterialDescription::Color(r, g, b) => self
                .ctx
                .add_labeled_asset(label, StandardMaterial::from(Color::linear_rgb(*r, *g, *b))),
            MaterialDescription::Path(path) => self.load(path),
            MaterialDescription::Named(_) | MaterialDescription::Instanced(_) => Handle::default(),
        }
    }

    fn image(&mut self, path: &str) -> Handle<Image> {
        self.load(path)
    }

    #[cfg(feature = "gltf")]
    fn gltf(&mut self, path: &str) -> Handle<bevy::gltf::Gltf> {
        self.load(path)
    }
}

/// An asset path of a layer file: relative to the file's folder when it starts with `./` or
/// `../`, else from the asset root.
fn relative_to(file: &AssetPath<'_>, path: &str) -> AssetPath<'static> {
    if path.starts_with("./") || path.starts_with("../") {
        file.resolve_embed_str(path)
            .unwrap_or_else(|_| AssetPath::parse(path).into_owned())
    } else {
        AssetPath::parse(path).into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_starting_with_a_dot_are_relative_to_the_file() {
        let file = AssetPath::parse("worlds/painted/flowers.layer.ron");
        assert_eq!(
            relative_to(&file, "./red.png"),
            AssetPath::parse("worlds/painted/red.png")
        );
        assert_eq!(
            relative_to(&file, "../maps/a.png"),
            AssetPath::parse("worlds/maps/a.png")
        );
        assert_eq!(
            relative_to(&file, "maps/a.png"),
            AssetPath::parse("maps/a.png")
        );
    }
}
