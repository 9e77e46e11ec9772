//! The asset loader of layer files.

use super::{
    LayerDescription, LayerFileError, MAX_LAYER_FILE_BYTES, MaterialDescription, NamedAssets,
    ScatterLayerAsset,
};
use bevy::asset::{AssetLoader, AssetPath, AsyncReadExt, LoadContext, io::Reader};
use bevy::prelude::*;
use std::cell::RefCell;

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
        // Primitive meshes and plain colours become labelled sub-assets of the layer file.
        let ctx = RefCell::new(ctx);
        let (mut meshes, mut materials) = (0, 0);
        let layer = description.to_layer(
            &self.names,
            |m| {
                let mut ctx = ctx.borrow_mut();
                let label = format!("mesh{meshes}");
                meshes += 1;
                match m.primitive() {
                    Ok(mesh) => ctx.add_labeled_asset(label, mesh),
                    Err(path) => {
                        let path = relative_to(ctx.path(), path);
                        ctx.load(path)
                    }
                }
            },
            |m| {
                let mut ctx = ctx.borrow_mut();
                let label = format!("material{materials}");
                materials += 1;
                match m {
                    MaterialDescription::Color(r, g, b) => ctx.add_labeled_asset(
                        label,
                        StandardMaterial::from(Color::linear_rgb(*r, *g, *b)),
                    ),
                    MaterialDescription::Path(path) => {
                        let path = relative_to(ctx.path(), path);
                        ctx.load(path)
                    }
                    MaterialDescription::Named(_) | MaterialDescription::Instanced(_) => {
                        Handle::default()
                    }
                }
            },
            |path| {
                let mut ctx = ctx.borrow_mut();
                let path = relative_to(ctx.path(), path);
                ctx.load(path)
            },
        )?;
        Ok(ScatterLayerAsset(layer))
    }

    fn extensions(&self) -> &[&str] {
        &["layer.ron"]
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
