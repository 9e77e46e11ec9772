//! Layer files: scatter layers described in RON files (`*.layer.ron`), loaded as assets and hot-reloaded:
//! an entity with a [`ScatterLayerSource`] gets the file's [`ScatterLayer`], and gets it
//! again, restreamed, whenever the file changes (with Bevy's `file_watcher` feature).
//!
//! ```ron
//! (
//!     tile_size: 8.0,
//!     seed: 7,
//!     chunk_size: 32.0,
//!     load_distance: 256.0,
//!     unload_distance: 320.0,
//!     falloff: (40.0, 200.0),
//!     classes: [
//!         (density: Noise(seed: 1, frequency: 0.02, octaves: 4, base: 0.2, amplitude: 0.8, scale: 0.4),
//!          mesh: Cone(radius: 0.6, height: 2.5), material: Color(0.15, 0.4, 0.15)),
//!         (density: Image(path: "maps/flowers.png", min: (-128.0, -128.0), size: (256.0, 256.0), scale: 2.0),
//!          mesh: Path("models/flower.glb#Mesh0/Primitive0"), material: Path("models/flower.glb#Material0")),
//!     ],
//!     exclusion: Image(path: "maps/roads.png", min: (-128.0, -128.0), size: (256.0, 256.0), scale: 1.0),
//! )
//! ```

use super::{HeightSource, LayerDensity, ScatterClass, ScatterLayer};
use bevy::asset::{AssetLoader, LoadContext, io::Reader};
use bevy::prelude::*;
use rwt_core::density::{NoiseDensity, NoiseParams};
use rwt_core::streaming::Falloff;
use rwt_core::streaming::StreamingConfig;
use serde::Deserialize;

/// A layer loaded from a `.layer.ron` file.
#[derive(Asset, TypePath, Clone, Debug)]
pub struct ScatterLayerAsset(pub ScatterLayer);

/// Puts the layer of a `.layer.ron` asset on this entity, and updates it when the file
/// changes. Until the file loads, the entity's [`super::ScatterLayerStatus`] says whether it
/// is waiting for it or why it failed.
#[derive(Component, Clone, Debug)]
#[require(super::ScatterLayerStatus)]
pub struct ScatterLayerSource(pub Handle<ScatterLayerAsset>);

/// A density in a layer file.
#[derive(Deserialize, Clone, Debug, PartialEq)]
pub enum DensityDescription {
    /// Instances per square unit.
    Constant(f64),
    /// Fractal noise (see [`NoiseDensity`]).
    Noise(NoiseParams),
    /// A painted map (asset path), over the ground rectangle `min..min + size` (x, z).
    Image {
        /// Asset path of the image.
        path: String,
        /// Ground position of the image's bottom-left corner.
        min: (f32, f32),
        /// Ground size of the image.
        size: (f32, f32),
        /// Instances per square unit where the image is white.
        scale: f64,
    },
}

/// A mesh in a layer file: an asset path or a primitive.
#[derive(Deserialize, Clone, Debug, PartialEq)]
pub enum MeshDescription {
    /// Asset path, e.g. `"models/tree.glb#Mesh0/Primitive0"`.
    Path(String),
    /// A sphere.
    Sphere {
        /// Radius.
        radius: f32,
    },
    /// A cone standing on the ground.
    Cone {
        /// Base radius.
        radius: f32,
        /// Height.
        height: f32,
    },
    /// A box.
    Cuboid {
        /// Size on x, y, z.
        size: (f32, f32, f32),
    },
}

/// A material in a layer file: an asset path or a plain colour (linear RGB).
#[derive(Deserialize, Clone, Debug, PartialEq)]
pub enum MaterialDescription {
    /// Asset path, e.g. `"models/tree.glb#Material0"`.
    Path(String),
    /// A plain colour.
    Color(f32, f32, f32),
}

fn one() -> f32 {
    1.0
}

fn variation() -> f32 {
    0.2
}

/// A class in a layer file.
#[derive(Deserialize, Clone, Debug, PartialEq)]
pub struct ClassDescription {
    /// Where and how densely the class grows.
    pub density: DensityDescription,
    /// Its mesh.
    pub mesh: MeshDescription,
    /// Its material.
    pub material: MaterialDescription,
    /// Base scale.
    #[serde(default = "one")]
    pub scale: f32,
    /// Hashed scale variation.
    #[serde(default = "variation")]
    pub scale_variation: f32,
}

fn default_tile() -> f64 {
    8.0
}

/// A whole layer file.
#[derive(Deserialize, Clone, Debug, PartialEq)]
pub struct LayerDescription {
    /// Classes sharing the layer's point set.
    pub classes: Vec<ClassDescription>,
    /// Base tile width in world units.
    #[serde(default = "default_tile")]
    pub tile_size: f64,
    /// Tiling seed.
    #[serde(default)]
    pub seed: u64,
    /// Chunk side.
    #[serde(default)]
    pub chunk_size: Option<f64>,
    /// Load distance.
    #[serde(default)]
    pub load_distance: Option<f64>,
    /// Unload distance.
    #[serde(default)]
    pub unload_distance: Option<f64>,
    /// Density fall-off `(near, far)`.
    #[serde(default)]
    pub falloff: Option<(f64, f64)>,
    /// Flat ground height.
    #[serde(default)]
    pub height: f32,
    /// Allowed ground height range.
    #[serde(default)]
    pub height_range: Option<(f32, f32)>,
    /// Largest ground slope.
    #[serde(default)]
    pub max_slope: Option<f32>,
    /// No instances where this is 0.5 or more (e.g. `Image(path: "roads.png", .., scale: 1.0)`).
    #[serde(default)]
    pub exclusion: Option<DensityDescription>,
}

impl DensityDescription {
    /// The layer density, with image handles made by `image`.
    fn to_density(&self, image: &mut impl FnMut(&str) -> Handle<Image>) -> LayerDensity {
        match self {
            DensityDescription::Constant(v) => LayerDensity::Constant(*v),
            DensityDescription::Noise(params) => LayerDensity::Noise(NoiseDensity::new(*params)),
            DensityDescription::Image {
                path,
                min,
                size,
                scale,
            } => LayerDensity::Image {
                image: image(path),
                min: Vec2::new(min.0, min.1),
                size: Vec2::new(size.0, size.1),
                scale: *scale,
            },
        }
    }
}

/// What is wrong with a layer file.
#[derive(Debug, thiserror::Error)]
pub enum LayerFileError {
    /// Not readable.
    #[error("cannot read layer file: {0}")]
    Io(#[from] std::io::Error),
    /// Not valid RON for a layer.
    #[error("invalid layer file: {0}")]
    Parse(String),
    /// Valid RON with values out of range.
    #[error("invalid layer: {0}")]
    Invalid(String),
}

impl LayerDescription {
    /// Parses and checks a layer file.
    pub fn from_ron(text: &str) -> Result<Self, LayerFileError> {
        // Optional fields take plain values (`falloff: (40.0, 200.0)`, not `Some(..)`), and
        // `Noise(seed: 1, ..)` needs no inner parentheses.
        let options = ron::Options::default().with_default_extension(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        let d: LayerDescription = options
            .from_str(text)
            .map_err(|e| LayerFileError::Parse(e.to_string()))?;
        if d.classes.is_empty() {
            return Err(LayerFileError::Invalid(
                "a layer needs at least one class".into(),
            ));
        }
        if !(d.tile_size.is_finite() && d.tile_size > 0.0) {
            return Err(LayerFileError::Invalid(format!(
                "tile_size {} must be positive",
                d.tile_size
            )));
        }
        for (name, v) in [
            ("chunk_size", d.chunk_size),
            ("load_distance", d.load_distance),
            ("unload_distance", d.unload_distance),
        ] {
            if let Some(v) = v
                && !(v.is_finite() && v > 0.0)
            {
                return Err(LayerFileError::Invalid(format!(
                    "{name} {v} must be positive"
                )));
            }
        }
        let chunk = d
            .chunk_size
            .unwrap_or(StreamingConfig::default().chunk_size);
        let load = d
            .load_distance
            .unwrap_or(StreamingConfig::default().load_distance);
        if load / chunk > rwt_core::streaming::MAX_REACH_CHUNKS {
            return Err(LayerFileError::Invalid(format!(
                "load_distance {load} spans more than {} chunks of {chunk}",
                rwt_core::streaming::MAX_REACH_CHUNKS
            )));
        }
        if let (Some(l), Some(u)) = (d.load_distance, d.unload_distance)
            && u < l
        {
            return Err(LayerFileError::Invalid(format!(
                "unload_distance {u} is below load_distance {l}"
            )));
        }
        Ok(d)
    }

    /// The layer, with handles made by the given functions (asset loads in a loader).
    pub fn to_layer(
        &self,
        mut mesh: impl FnMut(&MeshDescription) -> Handle<Mesh>,
        mut material: impl FnMut(&MaterialDescription) -> Handle<StandardMaterial>,
        mut image: impl FnMut(&str) -> Handle<Image>,
    ) -> ScatterLayer {
        let defaults = StreamingConfig::default();
        let classes = self
            .classes
            .iter()
            .map(|c| ScatterClass {
                scale: c.scale,
                scale_variation: c.scale_variation,
                ..ScatterClass::new(
                    c.density.to_density(&mut image),
                    mesh(&c.mesh),
                    material(&c.material),
                )
            })
            .collect();
        let mut layer = ScatterLayer::new(classes)
            .with_tile_size(self.tile_size)
            .with_seed(self.seed)
            .with_streaming(StreamingConfig {
                chunk_size: self.chunk_size.unwrap_or(defaults.chunk_size),
                load_distance: self.load_distance.unwrap_or(defaults.load_distance),
                unload_distance: self.unload_distance.unwrap_or(defaults.unload_distance),
                near_distance: defaults.near_distance,
            })
            .with_height(HeightSource::Constant(self.height));
        layer.falloff = self.falloff.map(|(near, far)| Falloff { near, far });
        layer.exclusion = self.exclusion.as_ref().map(|e| e.to_density(&mut image));
        layer.height_range = self.height_range;
        layer.max_slope = self.max_slope;
        layer
    }
}

/// Loads `.layer.ron` files.
#[derive(Default, TypePath)]
pub struct ScatterLayerLoader;

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
        reader.read_to_end(&mut bytes).await?;
        let text = std::str::from_utf8(&bytes).map_err(|e| LayerFileError::Parse(e.to_string()))?;
        let description = LayerDescription::from_ron(text)?;
        // Primitive meshes and plain colours become labelled sub-assets of the layer file.
        let mut meshes = Vec::new();
        let mut materials = Vec::new();
        for (i, c) in description.classes.iter().enumerate() {
            meshes.push(match &c.mesh {
                MeshDescription::Path(p) => ctx.load(p.clone()),
                MeshDescription::Sphere { radius } => {
                    ctx.add_labeled_asset(format!("mesh{i}"), Mesh::from(Sphere::new(*radius)))
                }
                MeshDescription::Cone { radius, height } => ctx.add_labeled_asset(
                    format!("mesh{i}"),
                    Mesh::from(Cone {
                        radius: *radius,
                        height: *height,
                    }),
                ),
                MeshDescription::Cuboid { size } => ctx.add_labeled_asset(
                    format!("mesh{i}"),
                    Mesh::from(Cuboid::new(size.0, size.1, size.2)),
                ),
            });
            materials.push(match &c.material {
                MaterialDescription::Path(p) => ctx.load(p.clone()),
                MaterialDescription::Color(r, g, b) => ctx.add_labeled_asset(
                    format!("material{i}"),
                    StandardMaterial::from(Color::linear_rgb(*r, *g, *b)),
                ),
            });
        }
        let mut images = Vec::new();
        for d in description
            .classes
            .iter()
            .map(|c| &c.density)
            .chain(description.exclusion.iter())
        {
            if let DensityDescription::Image { path, .. } = d {
                images.push(ctx.load(path.clone()));
            }
        }
        let (mut m, mut t, mut im) = (
            meshes.into_iter(),
            materials.into_iter(),
            images.into_iter(),
        );
        Ok(ScatterLayerAsset(description.to_layer(
            |_| m.next().unwrap_or_default(),
            |_| t.next().unwrap_or_default(),
            |_| im.next().unwrap_or_default(),
        )))
    }

    fn extensions(&self) -> &[&str] {
        &["layer.ron"]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEADOW: &str = r#"(
        tile_size: 4.0,
        seed: 9,
        chunk_size: 16.0,
        load_distance: 48.0,
        unload_distance: 64.0,
        falloff: (20.0, 60.0),
        classes: [
            (density: Constant(0.4), mesh: Cone(radius: 0.5, height: 2.0), material: Color(0.1, 0.5, 0.1)),
            (density: Noise(seed: 1, frequency: 0.1, octaves: 3, base: 0.5, amplitude: 0.5, scale: 0.2),
             mesh: Sphere(radius: 0.3), material: Color(0.6, 0.2, 0.2), scale: 1.5),
        ],
    )"#;

    #[test]
    fn parses_a_layer_file() {
        let d = LayerDescription::from_ron(MEADOW).unwrap();
        assert_eq!(d.classes.len(), 2);
        assert_eq!(d.classes[1].scale, 1.5);
        assert_eq!(d.classes[0].scale_variation, 0.2);
        let layer = d.to_layer(
            |_| Handle::default(),
            |_| Handle::default(),
            |_| Handle::default(),
        );
        assert_eq!(layer.tile_size, 4.0);
        assert_eq!(layer.streaming.load_distance, 48.0);
        assert_eq!(
            layer.falloff,
            Some(Falloff {
                near: 20.0,
                far: 60.0
            })
        );
        assert!(layer.exclusion.is_none());
        let excluded = MEADOW.replace(
            "falloff: (20.0, 60.0),",
            "falloff: (20.0, 60.0), exclusion: Image(path: \"roads.png\", min: (0.0, 0.0), size: (8.0, 8.0), scale: 1.0),",
        );
        let mut loads = Vec::new();
        let layer = LayerDescription::from_ron(&excluded).unwrap().to_layer(
            |_| Handle::default(),
            |_| Handle::default(),
            |path| {
                loads.push(path.to_string());
                Handle::default()
            },
        );
        assert!(matches!(layer.exclusion, Some(LayerDensity::Image { .. })));
        assert_eq!(loads, ["roads.png"]);
    }

    #[test]
    fn rejects_bad_files_with_reasons() {
        let err = |t: &str| LayerDescription::from_ron(t).unwrap_err().to_string();
        assert!(err("(classes: [").contains("invalid layer file"));
        assert!(err("(classes: [])").contains("at least one class"));
        let bad_tile = MEADOW.replace("tile_size: 4.0", "tile_size: -1.0");
        assert!(err(&bad_tile).contains("tile_size"));
        let inverted = MEADOW.replace("unload_distance: 64.0", "unload_distance: 10.0");
        assert!(err(&inverted).contains("unload_distance"));
        let far = MEADOW.replace("load_distance: 48.0", "load_distance: 1e300");
        assert!(err(&far).contains("more than 256 chunks"), "{}", err(&far));
        let zero = MEADOW.replace("load_distance: 48.0", "load_distance: 0.0");
        assert!(err(&zero).contains("load_distance 0 must be positive"));
    }
}
