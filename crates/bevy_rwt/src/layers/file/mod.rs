//! Layer files: scatter layers described in RON files (`*.layer.ron`), loaded as assets and hot-reloaded:
//! an entity with a [`ScatterLayerSource`] gets the file's [`ScatterLayer`], and gets it
//! again, restreamed, whenever the file changes (with Bevy's `file_watcher` feature).
//!
//! ```ron
//! (
//!     format: 2,
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
//!         // A glTF asset with all its parts, levels and collider, drawn instanced.
//!         (density: Constant(0.01), asset: (path: "trees/oak.glb#Scene0", lods: [30.0, 90.0], wind_response: 0.05)),
//!         (density: Constant(0.02), asset: "rocks/boulder.glb"),
//!         // Instanced: one draw per chunk, no entity per blade.
//!         (density: Constant(40.0), mesh: Blade(width: 0.08, height: 0.6, bend: 0.1),
//!          material: Instanced(tip: (0.3, 0.5, 0.1), wind_response: 0.3), scale_variation: 0.3),
//!     ],
//!     exclusion: Image(path: "maps/roads.png", min: (-128.0, -128.0), size: (256.0, 256.0), scale: 1.0),
//! )
//! ```
//!
//! A layer on the game's meshes (see [`crate::ground`]), with clumped flowers and moss
//! standing along the surface:
//!
//! ```ron
//! (
//!     format: 2,
//!     ground: Surfaces,
//!     surfaces: Every,
//!     max_slope: 0.7,
//!     classes: [
//!         (density: Clumps(seed: 4, clumps: 0.008, per_clump: 30.0, radius: 2.2, kernel: Thomas),
//!          mesh: Named("flower"), material: Instanced(tip: (0.8, 0.2, 0.4))),
//!         (density: Constant(5.0), mesh: Named("tuft"), material: Named("moss"),
//!          stance: (align: 1.0, sink: 0.02)),
//!     ],
//! )
//! ```
//!
//! `format: 2` is this library's format: a file without it is of format 1, written before
//! seeds turned the tiling, and its layer keeps its places on [`Lattice::Aligned`]
//! (`lattice: Aligned` does the same in format 2).
//!
//! An `asset` class (see [`AssetDescription`]) has no `mesh`, `material` or `lod`: its
//! parts, materials, levels of detail and collider are the file's. The layer reloads with
//! the `.glb`, and a file that does not load leaves that class empty while the others
//! stream.
//!
//! In code, a file is parsed and checked by [`LayerDescription::from_ron`], becomes a
//! layer with [`LayerDescription::to_layer`], and a layer becomes a file again with
//! [`LayerDescription::describe`] and [`LayerDescription::to_ron`]:
//!
//! ```
//! use bevy::prelude::*;
//! use bevy_rwt::layers::file::{LayerDescription, MeshDescription, NamedAssets, Placeholders};
//! use bevy_rwt::prelude::*;
//!
//! let names = NamedAssets::default();
//! let pine: Handle<Mesh> = Handle::default();
//! names.insert_mesh("pine", pine.clone());
//! let text = r#"(classes: [(density: Constant(0.05), mesh: Named("pine"), material: Color(0.1, 0.3, 0.1))],
//!                tile_size: 32.0, falloff: (100.0, 400.0), falloff_floor: 0.2)"#;
//! let file = LayerDescription::from_ron(text).unwrap();
//! let layer = file.to_layer(&names, &mut Placeholders).unwrap();
//! assert_eq!(layer.tile_size, 32.0);
//! assert_eq!(layer.falloff.unwrap().floor, 0.2);
//! // Back to a file: the mesh by its name.
//! let material = Handle::<StandardMaterial>::default();
//! let look = ClassLook::Mesh { mesh: pine, material: material.clone() };
//! names.insert_material("needles", material);
//! let mut layer = layer;
//! layer.classes[0].look = look;
//! let again = LayerDescription::describe(&layer, &names, |_| None).unwrap();
//! assert_eq!(again.classes[0].mesh, Some(MeshDescription::Named("pine".into())));
//! assert!(again.to_ron().unwrap().contains("Named(\"needles\")"));
//! ```
//!
//! Paths are asset paths; one starting with `./` or `../` is relative to the layer file's
//! folder (what the brush writes, so that a saved folder can move). Meshes, materials and
//! height functions made in code take part by name (`Named("spruce")`, `ground:
//! Named("terrain")`) through [`NamedAssets`], and [`LayerDescription::describe`] turns a
//! layer built in code back into a file.

mod asset;
mod check;
mod describe;
mod error;
mod handles;
mod loader;
mod names;
mod numbers;
#[cfg(test)]
mod tests;

pub use asset::{AssetDescription, AssetLabel};
pub use error::{InvalidLayer, LayerFileError, LayerPart, NamedKind, Undescribable};
use handles::Handles;
pub use handles::{LayerHandles, Placeholders};
pub use loader::ScatterLayerLoader;
pub use names::NamedAssets;

use super::{
    DEFAULT_SCALE_VARIATION, DEFAULT_TILE_SIZE, GroundMap, HeightSource, KeepOut, LayerDensity,
    LayerRef, Promotion, ScatterClass, ScatterLayer,
};
use crate::ground::SurfacePolicy;
use crate::look::{
    GroundPlane, InstancedShading, InstancedShadows, InstancedThinning, MeshLod, Stance, blade_mesh,
};
use bevy::prelude::*;
use rwt_core::Lattice;
use rwt_core::clumps::{ClumpParams, Clumps};
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
#[derive(Component, Clone, Debug, Reflect)]
#[reflect(Component, Clone, Debug)]
#[require(super::ScatterLayerStatus)]
pub struct ScatterLayerSource(pub Handle<ScatterLayerAsset>);

/// A density in a layer file.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub enum DensityDescription {
    /// Instances per square unit.
    Constant(f64),
    /// Fractal noise (see [`NoiseDensity`]).
    Noise(NoiseParams),
    /// A painted map: its scale is the instances per square unit where it is white.
    Image(MapDescription),
    /// Instances in patches (see [`Clumps`]), e.g. `Clumps(seed: 4, clumps: 0.002,
    /// per_clump: 20.0, radius: 2.5, kernel: Thomas)`.
    Clumps(ClumpParams),
}

/// An image over a ground rectangle in a layer file (a [`GroundMap`]), written
/// `Image(path: "maps/flowers.png", min: (-128.0, -128.0), size: (256.0, 256.0), scale: 2.0)`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct MapDescription {
    /// Asset path of the image.
    pub path: String,
    /// Ground position of the image's bottom-left corner.
    pub min: (f32, f32),
    /// Ground size of the image.
    pub size: (f32, f32),
    /// What a white texel means.
    pub scale: f64,
}

impl MapDescription {
    /// The map, its image handle made by `image`.
    fn to_map(&self, image: impl FnOnce(&str) -> Handle<Image>) -> GroundMap {
        GroundMap {
            image: image(&self.path),
            min: Vec2::new(self.min.0, self.min.1),
            size: Vec2::new(self.size.0, self.size.1),
            scale: self.scale,
        }
    }

    /// The description of `map`, whose image loads from `path`.
    pub(crate) fn of(map: &GroundMap, path: String) -> Self {
        Self {
            path,
            min: map.min.into(),
            size: map.size.into(),
            scale: map.scale,
        }
    }
}

/// A mesh in a layer file: an asset path or a primitive.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum MeshDescription {
    /// Asset path, e.g. `"models/tree.glb#Mesh0/Primitive0"`.
    Path(String),
    /// A mesh the game registered in [`NamedAssets`].
    Named(String),
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
    /// A grass blade for instanced classes (see [`crate::look::blade_mesh`]).
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
    /// The mesh of a primitive, or the asset path to load or the name to look up.
    pub fn primitive(&self) -> Result<Mesh, &str> {
        Ok(match self {
            MeshDescription::Path(path) | MeshDescription::Named(path) => return Err(path),
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
    /// A material the game registered in [`NamedAssets`].
    Named(String),
    /// A plain colour.
    Color(f32, f32, f32),
    /// The class is instanced (no entity per instance; see [`crate::instancing`]), shaded so.
    Instanced(InstancedShadingDescription),
}

/// The shading of an instanced class in a layer file (colours linear RGB); each field
/// defaults to [`InstancedShading::default`]'s.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
#[serde(default)]
pub struct InstancedShadingDescription {
    /// Colour at the root.
    pub base: (f32, f32, f32),
    /// Colour at the tip.
    pub tip: (f32, f32, f32),
    /// See [`InstancedShading::color_variation`].
    pub color_variation: f32,
    /// See [`InstancedShading::roughness`].
    pub roughness: f32,
    /// See [`InstancedShading::wind_response`].
    pub wind_response: f32,
    /// See [`InstancedShading::fade_band`].
    pub fade_band: f32,
    /// See [`InstancedShading::tip_from`].
    pub tip_from: f32,
    /// See [`InstancedShading::shadows`]: `Off`, `On` or `Within(30.0)`.
    pub shadows: InstancedShadows,
    /// See [`InstancedShading::bend_response`].
    pub bend_response: f32,
    /// Asset path of the base-colour texture ([`InstancedShading::texture`]), e.g.
    /// `"foliage/fern.png"`.
    pub texture: Option<String>,
    /// See [`InstancedShading::alpha_cutoff`].
    pub alpha_cutoff: f32,
    /// See [`InstancedShading::thinning`]: `Some((from: 20.0, floor: 0.1))`.
    pub thinning: Option<InstancedThinning>,
}

impl Default for InstancedShadingDescription {
    fn default() -> Self {
        Self::from(&InstancedShading::default())
    }
}

impl From<&InstancedShading> for InstancedShadingDescription {
    fn from(m: &InstancedShading) -> Self {
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
            shadows: m.shadows,
            bend_response: m.bend_response,
            // The texture's path is the describer's to give (it knows where images are).
            texture: None,
            alpha_cutoff: m.alpha_cutoff,
            thinning: m.thinning,
        }
    }
}

impl InstancedShadingDescription {
    /// The material it describes; `image` loads the texture by its path.
    pub fn to_material(&self, image: impl FnOnce(&str) -> Handle<Image>) -> InstancedShading {
        let color = |(r, g, b): (f32, f32, f32)| Color::linear_rgb(r, g, b);
        InstancedShading {
            base_color: color(self.base),
            tip_color: color(self.tip),
            color_variation: self.color_variation,
            roughness: self.roughness,
            wind_response: self.wind_response,
            fade_band: self.fade_band,
            tip_from: self.tip_from,
            shadows: self.shadows,
            bend_response: self.bend_response,
            texture: self.texture.as_deref().map(image),
            alpha_cutoff: self.alpha_cutoff,
            thinning: self.thinning,
        }
    }
}

fn yes() -> bool {
    true
}

fn one() -> f32 {
    1.0
}

fn variation() -> f32 {
    DEFAULT_SCALE_VARIATION
}

/// A class in a layer file.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ClassDescription {
    /// Where and how densely the class grows.
    pub density: DensityDescription,
    /// Its mesh (a class has a mesh and a material, or an asset).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<MeshDescription>,
    /// Its material.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialDescription>,
    /// The glTF asset it draws, instanced, with every part and material
    /// (`asset: "trees/oak.glb#Scene0"`; see [`AssetDescription`]).
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "asset::either_form"
    )]
    pub asset: Option<AssetDescription>,
    /// Base scale.
    #[serde(default = "one")]
    pub scale: f32,
    /// Hashed scale variation.
    #[serde(default = "variation")]
    pub scale_variation: f32,
    /// A far mesh and material (see [`MeshLod`]).
    #[serde(default)]
    pub lod: Option<LodDescription>,
    /// How instances stand on their surface, e.g. `(align: 1.0, sink: 0.05)` (see
    /// [`Stance`]); upright when absent.
    #[serde(default)]
    pub stance: Stance,
    /// Bounds `(min, max)` of one instance at scale 1 for picking (see
    /// [`ScatterClass::pick_bounds`]).
    #[serde(default)]
    pub pick_bounds: Option<(Vec3, Vec3)>,
    /// Near instances become entities (see [`crate::Promotion`]), e.g.
    /// `(distance: 12.0, insert: "tree collider")`.
    #[serde(default)]
    pub promotion: Option<PromotionDescription>,
    /// Far instances drawn as impostors (see [`crate::Impostor`]), e.g.
    /// `(distance: 400.0)`.
    #[serde(default)]
    pub impostor: Option<crate::Impostor>,
}

/// A promotion in a layer file: its distance, and what promoted instances get by the name
/// the game registered in [`NamedAssets::insert_inserter`].
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PromotionDescription {
    /// Ground distance to the nearest viewer within which instances are entities.
    pub distance: f32,
    /// The inserter's name.
    pub insert: String,
}

/// The far level of detail of a class in a layer file (see [`MeshLod`]; for an instanced
/// class, [`InstancedFar`](crate::look::InstancedFar), whose material is `Instanced()`: the
/// class's shading applies, and whose crossfade is unused).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LodDescription {
    /// The far mesh.
    pub mesh: MeshDescription,
    /// The far material (`Instanced()` for an instanced class, and only then).
    pub material: MaterialDescription,
    /// Distance of the switch.
    pub distance: f32,
    /// Width of the crossfade band; a tenth of the distance when absent.
    #[serde(default)]
    pub crossfade: Option<f32>,
}

/// The ground of a layer file, when it is not flat.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub enum HeightDescription {
    /// A height function the game registered in [`NamedAssets`].
    Named(String),
    /// A heightmap (see [`HeightSource::Image`]): its scale is the height where it is white.
    Image(MapDescription),
    /// The meshes marked [`ScatterSurface`](crate::ground::ScatterSurface) for the layer
    /// (see [`HeightSource::Surfaces`]).
    Surfaces,
}

fn default_tile() -> f64 {
    DEFAULT_TILE_SIZE
}

/// The layer file format this library writes. It reads this one and format 1, the files
/// written before seeded lattices (no `format` field), whose layers keep their places on
/// [`Lattice::Aligned`].
pub const LAYER_FORMAT: u32 = 2;

/// The format of a layer file or save index without a `format` field: 1, written before
/// formats were named (a serde default).
pub(crate) fn format_1() -> u32 {
    1
}

/// A whole layer file.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct LayerDescription {
    /// The file's format ([`LAYER_FORMAT`]; a file without it is of format 1).
    #[serde(default = "format_1")]
    pub format: u32,
    /// Classes sharing the layer's point set.
    pub classes: Vec<ClassDescription>,
    /// Base tile width in world units.
    #[serde(default = "default_tile")]
    pub tile_size: f64,
    /// Tiling seed.
    #[serde(default)]
    pub seed: u64,
    /// How the seed places the tile lattice (see [`Lattice`]); unless set, the format's:
    /// `Seeded` from format 2 on, `Aligned` in format 1.
    #[serde(default)]
    pub lattice: Option<Lattice>,
    /// Chunk side.
    #[serde(default)]
    pub chunk_size: Option<f64>,
    /// Load distance.
    #[serde(default)]
    pub load_distance: Option<f64>,
    /// Unload distance.
    #[serde(default)]
    pub unload_distance: Option<f64>,
    /// Distance within which chunks are generated first (see [`StreamingConfig`]).
    #[serde(default)]
    pub near_distance: Option<f64>,
    /// Density fall-off `(near, far)`.
    #[serde(default)]
    pub falloff: Option<(f64, f64)>,
    /// Fraction of the density kept beyond the fall-off's `far` (see [`Falloff::floor`]).
    #[serde(default)]
    pub falloff_floor: f64,
    /// The plane the layer lies on.
    #[serde(default)]
    pub plane: GroundPlane,
    /// Flat ground height (when there is no `ground`).
    #[serde(default)]
    pub height: f32,
    /// The ground's height source, when it is not flat.
    #[serde(default)]
    pub ground: Option<HeightDescription>,
    /// Which surfaces above a point the layer grows on: `TopMost` (default) or `Every`.
    #[serde(default)]
    pub surfaces: SurfacePolicy,
    /// Whether densities count per unit of surface area (default) or of the plane.
    #[serde(default = "yes")]
    pub per_area: bool,
    /// Allowed ground height range.
    #[serde(default)]
    pub height_range: Option<(f32, f32)>,
    /// Largest ground slope.
    #[serde(default)]
    pub max_slope: Option<f32>,
    /// No instances where this is 0.5 or more (e.g. `Image(path: "roads.png", .., scale: 1.0)`).
    #[serde(default)]
    pub exclusion: Option<DensityDescription>,
    /// Other layers, by the `Name` of their entity, whose instances clear this one, e.g.
    /// `[(layer: "trees", radii: [1.2, 0.0])]` (see [`KeepOut`]).
    #[serde(default)]
    pub keep_out: Vec<KeepOutDescription>,
}

/// A keep-out in a layer file: the other layer's entity `Name` and a radius per class.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct KeepOutDescription {
    /// The `Name` of the layer entity whose instances clear this layer.
    pub layer: String,
    /// Per class of that layer, how far its instances clear.
    pub radii: Vec<f32>,
}

impl DensityDescription {
    /// The layer density, with image handles made by `image`.
    fn to_density(
        &self,
        image: &mut impl FnMut(&str) -> Handle<Image>,
    ) -> Result<LayerDensity, InvalidLayer> {
        Ok(match self {
            DensityDescription::Constant(v) => LayerDensity::Constant(*v),
            DensityDescription::Noise(params) => LayerDensity::Noise(NoiseDensity::new(*params)),
            DensityDescription::Image(map) => LayerDensity::Image(map.to_map(image)),
            DensityDescription::Clumps(params) => {
                LayerDensity::Clumps(Clumps::new(*params).map_err(InvalidLayer::Clumps)?)
            }
        })
    }
}

/// Largest layer file the loader reads (layer files are descriptions of a few kilobytes;
/// anything larger is refused after reading this many bytes).
pub const MAX_LAYER_FILE_BYTES: u64 = 1 << 20;

/// Most classes of a layer: a reclass edit names its class with 16 bits.
pub const MAX_CLASSES: usize = 1 << 16;

impl LayerDescription {
    /// The layer file text: what [`LayerDescription::from_ron`] reads back (optional fields
    /// as plain values).
    pub fn to_ron(&self) -> Result<String, LayerFileError> {
        let config = ron::ser::PrettyConfig::default().extensions(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        Ok(ron::ser::to_string_pretty(self, config)?)
    }

    /// Parses and checks a layer file.
    pub fn from_ron(text: &str) -> Result<Self, LayerFileError> {
        // Optional fields take plain values (`falloff: (40.0, 200.0)`, not `Some(..)`), and
        // `Noise(seed: 1, ..)` needs no inner parentheses.
        let options = ron::Options::default().with_default_extension(
            ron::extensions::Extensions::IMPLICIT_SOME
                | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        let d: LayerDescription = options.from_str(text)?;
        d.check()?;
        Ok(d)
    }

    /// How the layer's seed places the tile lattice: as the file says, or as its format
    /// placed it.
    pub fn lattice(&self) -> Lattice {
        self.lattice.unwrap_or(match self.format {
            1 => Lattice::Aligned,
            _ => Lattice::Seeded,
        })
    }

    /// The layer, with named assets from `names` and the other handles from `handles` (asset
    /// loads in a loader; [`Placeholders`] to check a file).
    pub fn to_layer(
        &self,
        names: &NamedAssets,
        handles: &mut impl LayerHandles,
    ) -> Result<ScatterLayer, LayerFileError> {
        let mut handles = Handles { names, handles };
        let classes = self
            .classes
            .iter()
            .enumerate()
            .map(|(i, c)| c.to_class(i, &mut handles))
            .collect::<Result<_, _>>()?;
        let defaults = StreamingConfig::default();
        let mut layer = ScatterLayer::new(classes)
            .with_tile_size(self.tile_size)
            .with_seed(self.seed)
            .with_lattice(self.lattice())
            .with_streaming(StreamingConfig {
                chunk_size: self.chunk_size.unwrap_or(defaults.chunk_size),
                load_distance: self.load_distance.unwrap_or(defaults.load_distance),
                unload_distance: self.unload_distance.unwrap_or(defaults.unload_distance),
                near_distance: self.near_distance.unwrap_or(defaults.near_distance),
            })
            .with_height(self.height_source(&mut handles)?);
        layer.plane = self.plane;
        layer.falloff = self
            .falloff
            .map(|(near, far)| Falloff::new(near, far).with_floor(self.falloff_floor));
        layer.exclusion = match &self.exclusion {
            Some(e) => Some(e.to_density(&mut |p| handles.handles.image(p))?),
            None => None,
        };
        layer.height_range = self.height_range;
        layer.max_slope = self.max_slope;
        layer.surfaces = self.surfaces;
        layer.per_area = self.per_area;
        layer.keep_out = self
            .keep_out
            .iter()
            .map(|k| KeepOut {
                layer: LayerRef::Named(k.layer.clone()),
                radii: k.radii.clone(),
            })
            .collect();
        Ok(layer)
    }

    fn height_source<H: LayerHandles>(
        &self,
        handles: &mut Handles<H>,
    ) -> Result<HeightSource, LayerFileError> {
        Ok(match &self.ground {
            None => HeightSource::Constant(self.height),
            Some(HeightDescription::Named(name)) => handles
                .names
                .height(name)
                .ok_or_else(|| unknown(NamedKind::Height, name))?,
            Some(HeightDescription::Image(map)) => {
                HeightSource::Image(map.to_map(|p| handles.handles.image(p)))
            }
            Some(HeightDescription::Surfaces) => HeightSource::Surfaces,
        })
    }
}

/// The error for a name `NamedAssets` does not have.
fn unknown(kind: NamedKind, name: &str) -> LayerFileError {
    LayerFileError::UnknownName {
        kind,
        name: name.to_string(),
    }
}

impl ClassDescription {
    fn promotion(&self, names: &NamedAssets) -> Result<Option<Promotion>, LayerFileError> {
        let Some(p) = &self.promotion else {
            return Ok(None);
        };
        let insert = names
            .inserter(&p.insert)
            .ok_or_else(|| unknown(NamedKind::Inserter, &p.insert))?;
        Ok(Some(Promotion {
            distance: p.distance,
            insert,
        }))
    }

    fn to_class<H: LayerHandles>(
        &self,
        index: usize,
        handles: &mut Handles<H>,
    ) -> Result<ScatterClass, LayerFileError> {
        let density = self.density.to_density(&mut |p| handles.handles.image(p))?;
        let class = ScatterClass {
            scale: self.scale,
            scale_variation: self.scale_variation,
            stance: self.stance,
            pick_bounds: self.pick_bounds,
            promotion: self.promotion(handles.names)?,
            impostor: self.impostor,
            ..self.look(index, density, handles)?
        };
        Ok(class)
    }

    /// The class's look and far level, its other fields at their defaults.
    fn look<H: LayerHandles>(
        &self,
        index: usize,
        density: LayerDensity,
        handles: &mut Handles<H>,
    ) -> Result<ScatterClass, LayerFileError> {
        let (Some(mesh), Some(material)) = (&self.mesh, &self.material) else {
            return self.asset_class(index, density, handles);
        };
        let mesh = handles.mesh(mesh)?;
        let class = match material {
            MaterialDescription::Instanced(m) => {
                let shading = m.to_material(|p| handles.handles.image(p));
                ScatterClass::instanced(density, mesh, shading)
            }
            other => ScatterClass::new(density, mesh, handles.material(other)?),
        };
        Ok(match (&self.lod, material) {
            (Some(lod), MaterialDescription::Instanced(_)) => {
                class.with_instanced_far(handles.mesh(&lod.mesh)?, lod.distance)
            }
            (Some(lod), _) => ScatterClass {
                lod: Some(MeshLod {
                    mesh: handles.mesh(&lod.mesh)?,
                    material: handles.material(&lod.material)?,
                    distance: lod.distance,
                    crossfade: lod.crossfade.unwrap_or(0.1 * lod.distance),
                }),
                ..class
            },
            (None, _) => class,
        })
    }

    /// The class of an asset (checked to have one when it has no mesh and material).
    #[cfg_attr(not(feature = "gltf"), allow(unused_variables))]
    fn asset_class<H: LayerHandles>(
        &self,
        index: usize,
        density: LayerDensity,
        handles: &mut Handles<H>,
    ) -> Result<ScatterClass, LayerFileError> {
        let Some(asset) = &self.asset else {
            return Err(InvalidLayer::ClassLook { class: index }.into());
        };
        #[cfg(feature = "gltf")]
        {
            let gltf = handles.handles.gltf(asset.file());
            Ok(ScatterClass::asset(density, asset.to_look(gltf)))
        }
        #[cfg(not(feature = "gltf"))]
        Err(LayerFileError::NoGltf { class: index })
    }
}
