//! open_world's forests: three tree species from fractal noise, and their stump, in one
//! layer that streams to 2.6 km: the asset pack's glTF trees, or the meshes made in code. Shared by open_world and the cost benchmark, which times
//! far trees drawn both ways ([`FarTrees`]).

use crate::foliage;
use crate::terrain::{Terrain, WATER};
use bevy::prelude::*;
use bevy_rwt::look::asset::{AssetLods, AssetLook};
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::density::{Density, NoiseDensity, NoiseParams};
use glam::DVec2;

/// The tree layer's classes: the three species, then their stump.
pub const TREE_SPECIES: [u16; 3] = [0, 1, 2];
/// The stump's class in the tree layer.
pub const STUMP: u16 = 3;

/// The forests' noise seeds and bases, one per species.
const FORESTS: [(u32, f64); 3] = [(11, -0.1), (12, -0.2), (13, -0.35)];

/// Where near and far meshes crossfade (metres).
const LOD_DISTANCE: f32 = 180.0;
/// Where impostors take over (metres).
pub const IMPOSTOR_DISTANCE: f32 = 350.0;

/// The density of one species' forest (trees per square metre).
fn forest(seed: u32, base: f64) -> NoiseDensity {
    NoiseDensity::new(NoiseParams {
        seed,
        frequency: 1.0 / 650.0,
        octaves: 4,
        base,
        amplitude: 1.9,
        scale: 0.01,
    })
}

/// The three forests together: trees per square metre of all species.
pub struct ForestCover([NoiseDensity; 3]);

impl ForestCover {
    /// The three species' densities.
    pub fn new() -> Self {
        Self(FORESTS.map(|(seed, base)| forest(seed, base)))
    }
}

impl Default for ForestCover {
    fn default() -> Self {
        Self::new()
    }
}

impl Density for ForestCover {
    fn density(&self, p: DVec2) -> f64 {
        self.0.iter().map(|f| f.density(p)).sum()
    }

    fn max_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.0.iter().map(|f| f.max_over(min, max)).sum()
    }

    fn min_over(&self, min: DVec2, max: DVec2) -> f64 {
        self.0.iter().map(|f| f.min_over(min, max)).sum()
    }
}

/// A place near `p` in open ground that looks at a forest about 35 m ahead (its ferns in
/// view), and the yaw that looks there.
pub fn forest_edge(terrain: &Terrain, p: Vec2) -> (Vec2, f32) {
    let cover = ForestCover::new();
    let density = |q: Vec2| cover.density(glam::DVec2::new(q.x as f64, q.y as f64));
    let mut best = (f64::MIN, p, 0.0);
    for ring in 0..30 {
        for k in 0..24 {
            let a = k as f32 / 24.0 * std::f32::consts::TAU;
            let at = p + Vec2::from_angle(a) * (ring as f32 * 40.0);
            for j in 0..8 {
                let yaw = j as f32 / 8.0 * std::f32::consts::TAU;
                // FlyCamera looks along -z turned by yaw.
                let ahead = at + Vec2::new(-yaw.sin(), -yaw.cos()) * 35.0;
                let dry = terrain.height(at) > WATER + 2.0 && terrain.height(ahead) > WATER + 2.0;
                let score = density(ahead) - 3.0 * density(at) - 1e-6 * ring as f64;
                if dry && score > best.0 {
                    best = (score, at, yaw);
                }
            }
        }
    }
    (best.1, best.2)
}

/// How far trees are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FarTrees {
    /// Every tree an entity (near and far meshes), a fifth of the forest kept from 1.4 km
    /// on: what drawing every far tree as a mesh could afford.
    Thinned,
    /// Every tree to the horizon; from [`IMPOSTOR_DISTANCE`] on, impostors.
    Impostors,
}

/// The forests on `ground`: near and far meshes crossfade at 180 m; far trees as `far`
/// says. Standing wherever the ground lets them (the caller sets heights and slopes).
pub fn tree_layer(
    ground: &HeightSource,
    meshes: &mut Assets<Mesh>,
    material: &Handle<StandardMaterial>,
    far: FarTrees,
) -> ScatterLayer {
    let [a, b, c] = FORESTS.map(|(seed, base)| LayerDensity::Noise(forest(seed, base)));
    let species = [
        (foliage::conifer(), a),
        (foliage::broadleaf(), b),
        (foliage::birch(), c),
    ];
    let mut classes: Vec<ScatterClass> = species
        .into_iter()
        .map(|(tree, density)| {
            let near = meshes.add(tree.near);
            let far_mesh = meshes.add(tree.far);
            let mut class = ScatterClass::new(density, near, material.clone()).with_lod(
                far_mesh,
                material.clone(),
                LOD_DISTANCE,
            );
            if far == FarTrees::Impostors {
                class = class.with_impostor(Impostor::at(IMPOSTOR_DISTANCE));
            }
            class.scale_variation = 0.3;
            class
        })
        .collect();
    classes.push(stump(meshes, material));
    let layer = forest_layer(classes, ground);
    match far {
        FarTrees::Thinned => layer.with_falloff_floor(350.0, 1400.0, 0.2),
        FarTrees::Impostors => layer,
    }
}

/// The stump: nowhere until a tree is chopped (an edit gives its point this class); the
/// same scale rule as the trees, so a stump is as thick as its tree was.
fn stump(meshes: &mut Assets<Mesh>, material: &Handle<StandardMaterial>) -> ScatterClass {
    let mut stump = ScatterClass::new(
        LayerDensity::Constant(0.0),
        meshes.add(foliage::stump()),
        material.clone(),
    );
    stump.scale_variation = 0.3;
    stump
}

/// The forests' layer of `classes` on `ground`, streamed to 2.6 km.
fn forest_layer(classes: Vec<ScatterClass>, ground: &HeightSource) -> ScatterLayer {
    ScatterLayer::new(classes)
        .with_seed(1)
        .with_tile_size(128.0)
        .with_streaming(StreamingConfig {
            chunk_size: 256.0,
            load_distance: 2600.0,
            unload_distance: 2800.0,
            near_distance: 200.0,
        })
        .with_height(ground.clone())
}

/// Where the pack's trees switch from their near level to their far one (metres).
pub const ASSET_LOD_DISTANCE: f32 = 70.0;

/// The forests of the asset pack's trees on `ground` ([`crate::pack`]: spruce, oak and
/// birch files, `looks` made from them), drawn instanced with their own levels of detail,
/// impostors from [`IMPOSTOR_DISTANCE`] and promoted within `promotion` metres of a viewer
/// (where the file's trunk hull becomes their collider).
pub fn asset_tree_layer(
    ground: &HeightSource,
    looks: [AssetLook; 3],
    meshes: &mut Assets<Mesh>,
    material: &Handle<StandardMaterial>,
    promotion: f32,
) -> ScatterLayer {
    let densities = FORESTS.map(|(seed, base)| LayerDensity::Noise(forest(seed, base)));
    let mut classes: Vec<ScatterClass> = looks
        .into_iter()
        .zip(densities)
        .map(|(look, density)| {
            let look = AssetLook {
                wind_response: 0.015,
                color_variation: 0.12,
                lods: AssetLods {
                    distances: vec![ASSET_LOD_DISTANCE],
                    ..default()
                },
                ..look
            };
            let mut class = ScatterClass::asset(density, look)
                .with_impostor(Impostor::at(IMPOSTOR_DISTANCE))
                .with_promotion(promotion, |_| {});
            class.scale_variation = 0.3;
            class
        })
        .collect();
    classes.push(stump(meshes, material));
    forest_layer(classes, ground)
}

/// The tree layer's entity: the layer named "trees".
pub fn named_tree_layer(layers: &Query<(Entity, &Name), With<ScatterLayer>>) -> Option<Entity> {
    layers
        .iter()
        .find(|(_, n)| n.as_str() == "trees")
        .map(|(e, _)| e)
}

/// The trees (not stumps) a pick considers, up to 300 m away.
pub fn trees_only(layer: Entity) -> PickFilter {
    PickFilter::default()
        .layers([layer])
        .classes(TREE_SPECIES)
        .max_distance(300.0)
}

/// The tree under the mouse cursor of the one camera and window.
#[derive(bevy::ecs::system::SystemParam)]
pub struct TreeUnderCursor<'w, 's> {
    cameras: Query<'w, 's, (&'static Camera, &'static GlobalTransform)>,
    windows: Query<'w, 's, &'static Window>,
    layers: Query<'w, 's, (Entity, &'static Name), With<ScatterLayer>>,
    picking: ScatterPicking<'w, 's>,
}

impl TreeUnderCursor<'_, '_> {
    /// The tree the cursor points at, if any.
    pub fn tree(&self) -> Option<ScatterHit> {
        let (camera, at) = self.cameras.single().ok()?;
        let layer = named_tree_layer(&self.layers)?;
        let cursor = self.windows.single().ok()?.cursor_position()?;
        let ray = camera.viewport_to_world(at, cursor).ok()?;
        self.picking.cast_ray(ray, &trees_only(layer))
    }
}
