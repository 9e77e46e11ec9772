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
//!     falloff_floor: 0.1,
//!     classes: [
//!         (density: Noise(seed: 1, frequency: 0.02, octaves: 4, base: 0.2, amplitude: 0.8, scale: 0.4),
//!          mesh: Cone(radius: 0.6, height: 2.5), material: Color(0.15, 0.4, 0.15)),
//!         (density: Image(path: "maps/flowers.png", min: (-128.0, -128.0), size: (256.0, 256.0), scale: 2.0),
//!          mesh: Path("models/flower.glb#Mesh0/Primitive0"), material: Path("models/flower.glb#Material0")),
//!         // Instanced: one draw per chunk, no entity per blade.
//!         (density: Constant(40.0), mesh: Blade(width: 0.08, height: 0.6, bend: 0.1),
//!          material: Instanced(tip: (0.3, 0.5, 0.1), wind_response: 0.3), scale_variation: 0.3),
//!     ],
//!     exclusion: Image(path: "maps/roads.png", min: (-128.0, -128.0), size: (256.0, 256.0), scale: 1.0),
//! )
//! ```

use super::{HeightSource, LayerDensity, ScatterClass, ScatterLayer};
use crate::instancing::{InstancedMaterial, blade_mesh};
use bevy::asset::{AssetLoader, LoadContext, io::Reader};
use bevy::prelude::*;
use rwt_core::density::{NoiseDensity, NoiseParams};
use rwt_core::streaming::Falloff;
use rwt_core::streaming::StreamingConfig;
use serde::{Deserialize, Serialize};

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
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
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
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
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
    /// A grass blade for instanced classes (see [`crate::instancing::blade_mesh`]).
    Blade {
        /// Width at the root.
        width: f32,
        /// Height of the tip.
        height: f32,
        /// How far the tip curves forward.
        #[serde(default)]
        bend: f32,
    },
}

impl MeshDescription {
    /// The mesh of a primitive, or the asset path to load.
    pub fn primitive(&self) -> Result<Mesh, &str> {
        Ok(match self {
            MeshDescription::Path(path) => return Err(path),
            MeshDescription::Sphere { radius } => Mesh::from(Sphere::new(*radius)),
            MeshDescription::Cone { radius, height } => Mesh::from(Cone {
                radius: *radius,
                height: *height,
            }),
            MeshDescription::Cuboid { size } => Mesh::from(Cuboid::new(size.0, size.1, size.2)),
            MeshDescription::Blade {
                width,
                height,
                bend,
            } => blade_mesh(*width, *height, *bend),
        })
    }
}

/// A material in a layer file: an asset path or a plain colour (linear RGB) for entity
/// classes, or the shading of an instanced class.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub enum MaterialDescription {
    /// Asset path, e.g. `"models/tree.glb#Material0"`.
    Path(String),
    /// A plain colour.
    Color(f32, f32, f32),
    /// The class is instanced (no entity per instance; see [`crate::instancing`]), shaded so.
    Instanced(InstancedMaterialDescription),
}

/// The shading of an instanced class in a layer file (colours linear RGB); each field
/// defaults to [`InstancedMaterial::default`]'s.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(default)]
pub struct InstancedMaterialDescription {
    /// Colour at the root.
    pub base: (f32, f32, f32),
    /// Colour at the tip.
    pub tip: (f32, f32, f32),
    /// See [`InstancedMaterial::color_variation`].
    pub color_variation: f32,
    /// See [`InstancedMaterial::roughness`].
    pub roughness: f32,
    /// See [`InstancedMaterial::wind_response`].
    pub wind_response: f32,
    /// See [`InstancedMaterial::fade_band`].
    pub fade_band: f32,
    /// See [`InstancedMaterial::tip_from`].
    pub tip_from: f32,
}

impl Default for InstancedMaterialDescription {
    fn default() -> Self {
        let m = InstancedMaterial::default();
        let linear = |c: Color| {
            let c = c.to_linear();
            (c.red, c.green, c.blue)
        };
        Self {
            base: linear(m.base_color),
            tip: linear(m.tip_color),
            color_variation: m.color_variation,
            roughness: m.roughness,
            wind_response: m.wind_response,
            fade_band: m.fade_band,
            tip_from: m.tip_from,
        }
    }
}

impl InstancedMaterialDescription {
    /// The material it describes.
    pub fn to_material(&self) -> InstancedMaterial {
        let color = |(r, g, b): (f32, f32, f32)| Color::linear_rgb(r, g, b);
        InstancedMaterial {
            base_color: color(self.base),
            tip_color: color(self.tip),
            color_variation: self.color_variation,
            roughness: self.roughness,
            wind_response: self.wind_response,
            fade_band: self.fade_band,
            tip_from: self.tip_from,
        }
    }
}

fn one() -> f32 {
    1.0
}

fn variation() -> f32 {
    0.2
}

/// A class in a layer file.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
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
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
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
    /// Fraction of the density kept beyond the fall-off's `far` (see [`Falloff::floor`]).
    #[serde(default)]
    pub falloff_floor: f64,
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
    /// The description could not be written as RON.
    #[error("cannot write layer file: {0}")]
    Write(String),
}

impl LayerDescription {
    /// The layer file text: what [`LayerDescription::from_ron`] reads back (optional fields
    /// as plain values).
    pub fn to_ron(&self) -> Result<String, LayerFileError> {
        let config = ron::ser::PrettyConfig::default().extensions(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        ron::ser::to_string_pretty(self, config).map_err(|e| LayerFileError::Write(e.to_string()))
    }

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

    /// The layer, with handles made by the given functions (asset loads in a loader;
    /// `material` is called for the classes that are not instanced only).
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
            .map(|c| {
                let density = c.density.to_density(&mut image);
                let class = match &c.material {
                    MaterialDescription::Instanced(m) => {
                        ScatterClass::instanced(density, mesh(&c.mesh), m.to_material())
                    }
                    other => ScatterClass::new(density, mesh(&c.mesh), material(other)),
                };
                ScatterClass {
                    scale: c.scale,
                    scale_variation: c.scale_variation,
                    ..class
                }
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
        layer.falloff = self
            .falloff
            .map(|(near, far)| Falloff::new(near, far).with_floor(self.falloff_floor));
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
            meshes.push(match c.mesh.primitive() {
                Ok(m) => ctx.add_labeled_asset(format!("mesh{i}"), m),
                Err(path) => ctx.load(path.to_string()),
            });
            match &c.material {
                MaterialDescription::Path(p) => materials.push(ctx.load(p.clone())),
                MaterialDescription::Color(r, g, b) => materials.push(ctx.add_labeled_asset(
                    format!("material{i}"),
                    StandardMaterial::from(Color::linear_rgb(*r, *g, *b)),
                )),
                MaterialDescription::Instanced(_) => {}
            }
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
    use crate::layers::ClassLook;

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
    fn a_layer_file_writes_and_reads_back_the_same() {
        let with_all = MEADOW.replace(
            "falloff: (20.0, 60.0),",
            "falloff: (20.0, 60.0), falloff_floor: 0.25, exclusion: Image(path: \"roads.png\", min: (0.0, 0.0), size: (8.0, 8.0), scale: 1.0),",
        );
        let with_all = with_all.replace(
            "classes: [",
            r#"classes: [
            (density: Image(path: "m.png", min: (0.0, 0.0), size: (8.0, 8.0), scale: 2.0),
             mesh: Blade(width: 0.1, height: 0.6), material: Instanced(tip: (0.3, 0.5, 0.1), tip_from: 0.8)),
            (density: Constant(1.0), mesh: Path("a.glb#Mesh0/Primitive0"), material: Path("a.glb#Material0")),"#,
        );
        let d = LayerDescription::from_ron(&with_all).unwrap();
        assert_eq!(d.classes.len(), 4);
        let text = d.to_ron().unwrap();
        assert!(!text.contains("Some("), "{text}");
        assert_eq!(LayerDescription::from_ron(&text).unwrap(), d);
    }

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
        assert_eq!(layer.falloff, Some(Falloff::new(20.0, 60.0)));
        assert!(layer.exclusion.is_none());
        let floored = MEADOW.replace(
            "falloff: (20.0, 60.0),",
            "falloff: (20.0, 60.0), falloff_floor: 0.25,",
        );
        let floored = LayerDescription::from_ron(&floored).unwrap().to_layer(
            |_| Handle::default(),
            |_| Handle::default(),
            |_| Handle::default(),
        );
        assert_eq!(floored.falloff.map(|f| f.floor), Some(0.25));
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
    fn instanced_classes_in_a_layer_file() {
        let text = MEADOW.replace(
            "classes: [",
            "classes: [(density: Constant(30.0), mesh: Blade(width: 0.08, height: 0.6), \
             material: Instanced(tip: (0.3, 0.5, 0.1), fade_band: 0.2), scale_variation: 0.3), \
             (density: Constant(5.0), mesh: Cuboid(size: (0.1, 0.1, 0.1)), material: Instanced()),",
        );
        let d = LayerDescription::from_ron(&text).unwrap();
        let mut materials = 0;
        let layer = d.to_layer(
            |_| Handle::default(),
            |_| {
                materials += 1;
                Handle::default()
            },
            |_| Handle::default(),
        );
        assert_eq!(materials, 2, "entity classes only");
        let ClassLook::Instanced(look) = &layer.classes[0].look else {
            panic!("{:?}", layer.classes[0].look);
        };
        assert_eq!(look.material.tip_color, Color::linear_rgb(0.3, 0.5, 0.1));
        assert_eq!(look.material.fade_band, 0.2);
        let defaults = InstancedMaterial::default();
        assert_eq!(look.material.roughness, defaults.roughness);
        assert_eq!(layer.classes[0].scale_variation, 0.3);
        let ClassLook::Instanced(plain) = &layer.classes[1].look else {
            panic!("{:?}", layer.classes[1].look);
        };
        let base = defaults.base_color.to_linear();
        let read = plain.material.base_color.to_linear();
        assert!((base.green - read.green).abs() < 1e-6, "{base:?} {read:?}");
        let blade = d.classes[0].mesh.primitive().unwrap();
        let (_, hi) = crate::instancing::check_instanced_mesh(&blade)
            .unwrap()
            .unwrap();
        assert!((hi.y - 0.6).abs() < 1e-6);
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
