//! The open world's vegetation: every plant and rock is placed by a `bevy_rwt` layer (none
//! by hand). Trees, bushes, ferns, rocks and flowers are the asset pack's glTF files
//! ([`crate::pack`]), drawn instanced as asset classes; grass is rwt's own look.

use crate::forest::{ForestCover, asset_tree_layer};
use crate::pack::{PACK, flowers};
use crate::terrain::{Terrain, WATER};
use bevy::prelude::*;
use bevy_rwt::brush::DensityBrush;
use bevy_rwt::layers::file::NamedAssets;
use bevy_rwt::look::asset::{AssetLods, AssetLook, AssetRoot};
use bevy_rwt::look::{blade_mesh, far_blade_mesh};
use bevy_rwt::prelude::*;
use glam::DVec2;
use noise::{NoiseFn, Perlin};
use rwt_core::density::{Density, NoiseDensity, NoiseParams, Scale};
use std::sync::Arc;

/// The painted maps: `MAP_TEXELS` a side over `MAP_SIZE` metres centred on the origin.
const MAP_TEXELS: u32 = 2048;
/// Grass and flowers cast shadows this close to the camera (metres).
const GRASS_SHADOWS: f32 = 25.0;
/// Grass thins out from this far from the camera (metres).
const GRASS_THINNING: f32 = 25.0;
/// Grass chunks farther than this from the camera draw a blade of 6 vertices instead of 10
/// (metres).
const GRASS_FAR_BLADE: f32 = 30.0;
const MAP_SIZE: f32 = 4096.0;

/// Flowers draw their lighter level from this far from the camera (metres).
const FLOWER_LOD: f32 = 15.0;

/// Within this distance of a viewer (the camera, the walker) trees and rocks are entities
/// with the file's collider (metres).
const PROMOTION: f32 = 14.0;

/// How much of the world's vegetation grows: 1 (the default) is the showcase's; less
/// keeps that share of every layer's instances, in the same places (a lower density only
/// takes points away). For weak devices and software renderers: SwiftShader, the browser
/// test's, pays for every instance drawn.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct Detail(pub f64);

impl Default for Detail {
    fn default() -> Self {
        Self(1.0)
    }
}

impl Detail {
    /// `layer` with every class's density scaled by the detail.
    fn thin(self, mut layer: ScatterLayer) -> ScatterLayer {
        if self.0 == 1.0 {
            return layer;
        }
        for class in &mut layer.classes {
            class.density = match std::mem::replace(&mut class.density, LayerDensity::Constant(0.0))
            {
                LayerDensity::Constant(c) => LayerDensity::Constant(c * self.0),
                LayerDensity::Noise(n) => LayerDensity::Noise(NoiseDensity::new(NoiseParams {
                    scale: n.params().scale * self.0,
                    ..n.params()
                })),
                LayerDensity::Image(mut map) => {
                    map.scale *= self.0;
                    LayerDensity::Image(map)
                }
                LayerDensity::Custom(d) => LayerDensity::Custom(Arc::new(Scale(d, self.0))),
                other => other,
            };
        }
        layer
    }
}

/// The world's layers, by name, and the names of the flower maps (one per class of
/// `"flowers"`, the brush's targets with `"bushes"`).
pub struct WorldLayers {
    /// Trees, rocks, grass, ferns, flowers and bushes, with their names.
    pub layers: Vec<(&'static str, ScatterLayer)>,
    /// The flower maps' names.
    pub flower_maps: Vec<String>,
}

/// What the world's layers are made of: the ground, the pack's files (`load` gives the
/// handle of a pack path; a server that draws nothing passes `|_| Handle::default()`),
/// the assets the grass and painted maps are made into, and the share that grows.
pub struct LayerParts<'a> {
    /// The terrain.
    pub terrain: &'a Terrain,
    /// A pack file's handle, by path.
    pub load: &'a dyn Fn(&str) -> Handle<Gltf>,
    /// Where meshes go.
    pub meshes: &'a mut Assets<Mesh>,
    /// Where materials go.
    pub materials: &'a mut Assets<StandardMaterial>,
    /// Where the painted maps go.
    pub images: &'a mut Assets<Image>,
    /// The share that grows.
    pub detail: Detail,
}

impl LayerParts<'_> {
    /// The layers; the names `names` holds for layer files ("terrain", "white") added.
    pub fn build(self, names: &NamedAssets) -> WorldLayers {
        let detail = self.detail;
        let white = self.materials.add(StandardMaterial {
            perceptual_roughness: 0.9,
            reflectance: 0.2,
            ..default()
        });
        // Named, so that the brush writes the painted layers as layer files (F5).
        let ground = self.terrain.source();
        names.insert_height("terrain", &ground);
        names.insert_material("white", white.clone());
        let look = |path: &str| AssetLook::new((self.load)(path));
        let trees = asset_tree_layer(
            &ground,
            PACK.trees.map(look),
            self.meshes,
            &white,
            PROMOTION,
        )
        .with_height_range(WATER + 1.5, 112.0)
        .with_max_slope(0.6);
        let (flowers, flower_maps) = flowers(&ground, (self.load)(PACK.flowers), self.images);
        let bush_density = painted_map(self.images, 9, 0.05, 120.0);
        let layers = vec![
            ("trees", trees),
            ("rocks", rocks(&ground, look(PACK.rock))),
            ("grass", grass(&ground, self.meshes)),
            ("ferns", ferns(&ground, look(PACK.fern))),
            ("flowers", flowers),
            ("bushes", bushes(&ground, bush_density, look(PACK.bush))),
        ];
        let layers = layers
            .into_iter()
            .map(|(name, layer)| (name, detail.thin(layer)))
            .collect();
        WorldLayers {
            layers,
            flower_maps,
        }
    }
}

impl WorldLayers {
    /// Spawns the layers, each with its `Name`; the entities by name.
    pub fn spawn(self, commands: &mut Commands) -> Vec<(&'static str, Entity)> {
        let layers = self.layers.into_iter();
        layers
            .map(|(name, layer)| (name, commands.spawn((Name::new(name), layer)).id()))
            .collect()
    }
}

/// Spawns the layers and aims the brush at the flower and bush maps.
#[allow(clippy::too_many_arguments)]
pub fn setup_layers(
    mut commands: Commands,
    terrain: Res<Terrain>,
    server: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
    mut brush: ResMut<DensityBrush>,
    names: Res<NamedAssets>,
    detail: Option<Res<Detail>>,
) {
    let parts = LayerParts {
        terrain: &terrain,
        load: &|path| server.load(path.to_string()),
        meshes: &mut meshes,
        materials: &mut materials,
        images: &mut images,
        detail: detail.map_or(Detail::default(), |d| *d),
    };
    let world = parts.build(&names);
    let flower_maps = world.flower_maps.clone();
    let spawned = world.spawn(&mut commands);
    let entity = |name: &str| spawned.iter().find(|(n, _)| *n == name).map(|(_, e)| *e);
    let (Some(flowers), Some(bushes)) = (entity("flowers"), entity("bushes")) else {
        return;
    };
    brush.targets = flower_maps
        .into_iter()
        .enumerate()
        .map(|(class, name)| NamedMap::new(flowers, class, name))
        .chain([NamedMap::new(bushes, 0, "bushes")])
        .collect();
    brush.save_dir = std::env::var_os("RWT_PAINT_DIR").map_or("painted".into(), Into::into);
}

/// A map over the world's painted square, filled with soft patches of noise (`seed`,
/// patches about `feature` metres across) so that the world starts with meadows; the density
/// reads `scale` instances per square metre where it is white.
fn painted_map(images: &mut Assets<Image>, seed: u32, scale: f64, feature: f64) -> LayerDensity {
    let area = Rect::from_center_size(Vec2::ZERO, Vec2::splat(MAP_SIZE));
    let map = bevy_rwt::brush::blank_map(images, MAP_TEXELS, area, scale);
    let noise = Perlin::new(seed);
    let mut image = images.get_mut(&map.image).expect("just added");
    let data = image.data.as_mut().expect("a CPU-side map");
    let texel = (MAP_SIZE / MAP_TEXELS as f32) as f64;
    for (i, px) in data.chunks_exact_mut(4).enumerate() {
        let (x, y) = (
            (i as u32 % MAP_TEXELS) as f64,
            (i as u32 / MAP_TEXELS) as f64,
        );
        let n = noise.get([x * texel / feature, y * texel / feature]);
        let v = ((n - 0.15) * 2.5).clamp(0.0, 1.0);
        let byte = (v * v * 255.0) as u8;
        px.copy_from_slice(&[byte, byte, byte, 255]);
    }
    LayerDensity::Image(map)
}

/// Ferns per square metre under a full canopy.
const FERNS: f64 = 0.3;
/// The forest cover (trees per square metre) from which ferns grow at full density; they
/// thin out towards forest edges.
const FERN_COVER: f64 = 0.005;

/// The ferns' density: the forest floor's, from the forest cover.
struct FernDensity(ForestCover);

impl Density for FernDensity {
    fn density(&self, p: DVec2) -> f64 {
        FERNS * (self.0.density(p) / FERN_COVER).min(1.0)
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        FERNS * (self.0.max_over(min, max) / FERN_COVER).min(1.0)
    }

    /// The density grows with the cover, so the cover's bounds bound it.
    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        FERNS * (self.0.min_over(min, max) / FERN_COVER).min(1.0)
    }
}

/// Boulders, more of them on slopes' noise-chosen patches; promoted near a viewer, where
/// the rock's hull becomes its collider.
fn rocks(ground: &HeightSource, rock: AssetLook) -> ScatterLayer {
    let density = LayerDensity::Noise(NoiseDensity::new(NoiseParams {
        seed: 21,
        frequency: 1.0 / 300.0,
        octaves: 3,
        base: -0.2,
        amplitude: 1.5,
        scale: 0.004,
    }));
    let look = AssetLook {
        color_variation: 0.15,
        ..rock
    };
    let mut class = ScatterClass::asset(density, look).with_promotion(PROMOTION, |_| {});
    class.scale = 1.1;
    class.scale_variation = 0.6;
    ScatterLayer::new(vec![class])
        .with_seed(4)
        .with_tile_size(64.0)
        .with_streaming(StreamingConfig {
            chunk_size: 64.0,
            load_distance: 700.0,
            unload_distance: 780.0,
            near_distance: 80.0,
        })
        .with_falloff(200.0, 700.0)
        .with_height(ground.clone())
        .with_height_range(WATER - 2.0, 200.0)
}

/// Bushes from a painted map (up to 0.05 per square metre).
fn bushes(ground: &HeightSource, density: LayerDensity, bush: AssetLook) -> ScatterLayer {
    let look = AssetLook {
        wind_response: 0.05,
        color_variation: 0.15,
        ..bush
    };
    let mut class = ScatterClass::asset(density, look);
    class.scale_variation = 0.4;
    ScatterLayer::new(vec![class])
        .with_seed(2)
        .with_tile_size(64.0)
        .with_streaming(StreamingConfig {
            chunk_size: 64.0,
            load_distance: 500.0,
            unload_distance: 580.0,
            near_distance: 80.0,
        })
        .with_falloff(150.0, 500.0)
        .with_height(ground.clone())
        .with_height_range(WATER + 0.5, 110.0)
        .with_max_slope(0.8)
}

/// Grass blades, up to 140 per square metre, drawn from per-chunk instance buffers (no
/// entity per blade), growing in and out with the level of detail.
fn grass(ground: &HeightSource, meshes: &mut Assets<Mesh>) -> ScatterLayer {
    // A blade's width at the root, height and forward bend (metres).
    let (width, height, bend) = (0.085, 0.6, 0.11);
    let mut class = ScatterClass::instanced(
        LayerDensity::Noise(NoiseDensity::new(NoiseParams {
            seed: 3,
            frequency: 1.0 / 120.0,
            octaves: 3,
            base: 0.45,
            amplitude: 0.9,
            scale: 140.0,
        })),
        meshes.add(blade_mesh(width, height, bend)),
        InstancedShading {
            base_color: Color::srgb(0.05, 0.13, 0.025),
            tip_color: Color::srgb(0.33, 0.47, 0.12),
            // Blades cast near the player only: far grass costs nothing in shadow passes.
            shadows: InstancedShadows::Within(GRASS_SHADOWS),
            // Fewer, wider blades from 25 m: the far field costs vertices as the pixels
            // it covers (culled per instance, the thinned blades are not drawn at all).
            thinning: Some(InstancedThinning::from(GRASS_THINNING)),
            ..default()
        },
    );
    class.scale_variation = 0.35;
    let far = meshes.add(far_blade_mesh(width, height, bend));
    let class = class.with_instanced_far(far, GRASS_FAR_BLADE);
    ScatterLayer::new(vec![class])
        .with_seed(3)
        .with_tile_size(4.0)
        .with_streaming(StreamingConfig {
            chunk_size: 16.0,
            load_distance: 120.0,
            unload_distance: 140.0,
            near_distance: 24.0,
        })
        .with_falloff(35.0, 115.0)
        .with_height(ground.clone())
        .with_height_range(WATER + 0.3, 105.0)
}

/// Ferns on the forest floor: the pack's fern, its fronds cut out by their texture's
/// alpha, instanced.
fn ferns(ground: &HeightSource, fern: AssetLook) -> ScatterLayer {
    let look = AssetLook {
        wind_response: 0.35,
        color_variation: 0.15,
        shadows: InstancedShadows::Within(GRASS_SHADOWS),
        ..fern
    };
    let mut class = ScatterClass::asset(
        LayerDensity::Custom(Arc::new(FernDensity(ForestCover::new()))),
        look,
    );
    class.scale_variation = 0.3;
    ScatterLayer::new(vec![class])
        .with_seed(6)
        .with_tile_size(16.0)
        .with_streaming(StreamingConfig {
            chunk_size: 32.0,
            load_distance: 110.0,
            unload_distance: 130.0,
            near_distance: 32.0,
        })
        .with_falloff(60.0, 105.0)
        .with_height(ground.clone())
        .with_height_range(WATER + 1.5, 112.0)
        .with_max_slope(0.7)
}

/// Flowers in three colours, the pack's flower file's root nodes, each from its own
/// painted map (up to 5 per square metre); returns the layer and its maps' names (one per
/// class).
fn flowers(
    ground: &HeightSource,
    file: Handle<Gltf>,
    images: &mut Assets<Image>,
) -> (ScatterLayer, Vec<String>) {
    let classes = flowers::FLOWERS
        .iter()
        .enumerate()
        .map(|(i, (name, _, _))| {
            let density = painted_map(images, 30 + i as u32, 5.0, 45.0);
            let look = AssetLook {
                color_variation: 0.15,
                wind_response: 0.2,
                shadows: InstancedShadows::Within(GRASS_SHADOWS),
                lods: AssetLods {
                    distances: vec![FLOWER_LOD],
                    ..default()
                },
                collider: false,
                ..AssetLook::new(file.clone()).with_root(AssetRoot::Node(name.to_string()))
            };
            let mut class = ScatterClass::asset(density, look);
            class.scale_variation = 0.3;
            class
        })
        .collect();
    let layer = ScatterLayer::new(classes)
        .with_seed(5)
        .with_tile_size(8.0)
        .with_streaming(StreamingConfig {
            chunk_size: 16.0,
            load_distance: 100.0,
            unload_distance: 120.0,
            near_distance: 24.0,
        })
        .with_falloff(30.0, 95.0)
        .with_height(ground.clone())
        .with_height_range(WATER + 0.5, 100.0);
    let maps = flowers::FLOWERS
        .iter()
        .map(|(n, _, _)| format!("{n} flowers"));
    (layer, maps.collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rwt_core::density::Constant;

    /// Each class's density as a query reads it, at a few places.
    fn sampled(layer: &ScatterLayer, images: &Assets<Image>) -> Vec<f64> {
        let places = [DVec2::new(3.0, -7.0), DVec2::new(250.0, 40.0)];
        let resolved = layer
            .classes
            .iter()
            .map(|c| c.density.resolve(images).unwrap());
        resolved
            .flat_map(|d| places.map(|p| d.density(p)))
            .collect()
    }

    #[test]
    fn detail_scales_every_kind_of_density_and_one_leaves_the_layer_as_it_is() {
        let images = Assets::<Image>::default();
        let noise = NoiseDensity::new(NoiseParams {
            seed: 3,
            frequency: 1.0 / 120.0,
            octaves: 3,
            base: 0.45,
            amplitude: 0.9,
            scale: 140.0,
        });
        let layer = || {
            let class = |d| ScatterClass::new(d, Handle::default(), Handle::default());
            ScatterLayer::new(vec![
                class(LayerDensity::Constant(2.0)),
                class(LayerDensity::Noise(noise.clone())),
                class(LayerDensity::Custom(Arc::new(Constant(0.5)))),
            ])
        };
        let full = sampled(&layer(), &images);
        assert!(full.iter().all(|d| *d > 0.0), "{full:?}");
        assert_eq!(sampled(&Detail(1.0).thin(layer()), &images), full);
        let thinned = sampled(&Detail(0.25).thin(layer()), &images);
        for (t, f) in thinned.iter().zip(&full) {
            assert!((t - f * 0.25).abs() <= 1e-9 * f, "{t} against {f}");
        }
    }
}
