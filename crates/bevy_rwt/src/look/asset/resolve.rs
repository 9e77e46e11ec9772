//! An asset class's look ([`AssetLook`]: a glTF file, or a scene or node of it) made ready
//! to draw instanced ([`ResolvedAsset`]): each level's primitives as meshes in the asset's
//! frame (their node transforms applied once, here) with their surfaces, the colliders'
//! meshes, and the asset's bounds.

use super::file::{AssetPrimitive, AssetRoot, AssetTreeError, GltfAssets, asset_tree};
use super::parts::{AssetParts, Placed};
use super::surface::{InstancedSurface, SurfaceError};
use crate::look::{InstancedClassError, InstancedShading, InstancedShadows, check_instanced_mesh};
use bevy::gltf::{Gltf, GltfMaterial};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;

/// The look of a class drawn from a game's own glTF asset: every primitive under
/// [`AssetLook::root`], with its material, drawn instanced (one draw per primitive per chunk
/// and view). Nodes named `_LOD0`, `_LOD1`… give levels of detail; nodes named `UCX_…`,
/// `…_collider`, `…-colonly` collide and are never drawn ([`super::NodeRole`]).
///
/// The asset's frame is its root's: y up, standing on its origin.
#[derive(Clone, Debug, Reflect)]
#[reflect(Clone, Debug)]
pub struct AssetLook {
    /// The file (loaded with the asset server: `asset_server.load("trees/oak.glb")`).
    pub gltf: Handle<Gltf>,
    /// Which part of the file is the asset.
    pub root: AssetRoot,
    /// Strength of the per-instance colour variation, hashed from its point (0..1).
    pub color_variation: f32,
    /// How far the top sways in the wind, in asset heights per unit of wind strength,
    /// weighted by height in the asset (0: rigid, rocks).
    pub wind_response: f32,
    /// How far instances lean where a [`Bender`](crate::instancing::Bender) passed (0: they
    /// do not).
    pub bend_response: f32,
    /// Width of the fade-in band, as for [`InstancedShading::fade_band`](crate::look::InstancedShading::fade_band).
    pub fade_band: f32,
    /// Whether the class casts shadows.
    pub shadows: InstancedShadows,
    /// Where each level of detail takes over from the one before.
    pub lods: AssetLods,
    /// Whether a promoted instance gets the asset's [`AssetCollider`] (before the
    /// promotion's inserter, which turns it into a physics engine's collider).
    pub collider: bool,
}

/// The collision shape of a promoted instance of an asset class, from its file, in the
/// entity's frame (its transform carries the instance's place, turn and scale). Turn it
/// into your physics engine's collider with an observer or a system on
/// `Added<AssetCollider>` (avian: `Collider::convex_hull` of each mesh's positions, or of
/// the hull's points).
#[derive(Component, Clone, Debug, PartialEq, Reflect)]
#[reflect(Component, Clone, Debug, PartialEq)]
pub enum AssetCollider {
    /// The meshes of the asset's collider nodes (`UCX_…`: convex pieces; `…_collider`).
    Meshes(Vec<Handle<Mesh>>),
    /// The asset has no collider node: the vertices of its nearest level, whose convex hull
    /// stands for it.
    Hull(Vec<Vec3>),
}

/// Where an asset's levels of detail switch: each instance draws the level its own distance
/// from the camera calls for, crossfading (dithered) into the next over a band.
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct AssetLods {
    /// The distance at which level `i + 1` takes over from level `i` (metres from the
    /// camera to an instance's root); levels beyond the list switch where the file's
    /// screen coverage hint says (`MSFT_screencoverage`), else where the asset covers
    /// [`AssetLods::COVERAGE`] of the screen's height, halving at each level.
    pub distances: Vec<f32>,
    /// Width of each crossfade band, as a fraction of its distance (centred on it).
    pub crossfade: f32,
}

impl Default for AssetLods {
    fn default() -> Self {
        Self {
            distances: Vec::new(),
            crossfade: 0.1,
        }
    }
}

impl AssetLods {
    /// The fraction of the screen's height (under a 45-degree lens) an asset covers where
    /// its second level takes over, unless [`AssetLods::distances`] says where.
    pub const COVERAGE: f32 = 0.25;

    /// The switch distances of an asset of `levels` levels within `bounds`, nearest first
    /// (one fewer than the levels, rising). `coverage` is the file's hint: the fraction of
    /// the screen's height (the bounds' sphere's diameter over it, under a 45-degree lens)
    /// down to which each level is shown, the first level's first; its last value (where
    /// glTF's hint draws nothing) is left to the layer's reach and impostors.
    pub fn switches(&self, levels: usize, bounds: (Vec3, Vec3), coverage: &[f32]) -> Vec<f32> {
        let radius = 0.5 * (bounds.1 - bounds.0).length().max(1e-3);
        let mut last = 0.0f32;
        (1..levels)
            .map(|level| {
                let halved = Self::COVERAGE / (1u64 << (level - 1).min(30)) as f32;
                let hinted = coverage.get(level - 1).filter(|c| **c > 0.0 && **c <= 1.0);
                let covered = hinted.copied().unwrap_or(halved);
                let derived = radius / (covered * (std::f32::consts::PI / 8.0).tan());
                let given = self.distances.get(level - 1).copied();
                let d = given
                    .filter(|d| d.is_finite() && *d > 0.0)
                    .unwrap_or(derived);
                last = d.max(last * 1.01);
                last
            })
            .collect()
    }

    /// The crossfade band around the switch at `distance`.
    pub fn band(&self, distance: f32) -> (f32, f32) {
        let half = 0.5 * self.crossfade.clamp(0.0, 1.0) * distance;
        (distance - half, distance + half.max(1e-3))
    }
}

impl AssetLook {
    /// The whole file `gltf`, rigid, casting shadows.
    pub fn new(gltf: Handle<Gltf>) -> Self {
        Self {
            gltf,
            root: AssetRoot::File,
            color_variation: 0.0,
            wind_response: 0.0,
            bend_response: 0.0,
            fade_band: 0.1,
            shadows: InstancedShadows::On,
            lods: AssetLods::default(),
            collider: true,
        }
    }

    /// This look, of `root` in the file.
    pub fn with_root(mut self, root: AssetRoot) -> Self {
        self.root = root;
        self
    }

    /// The shading of a primitive of `surface` in this look: the class's motion, fade,
    /// shadows and colour variation; the surface's base colour (root and tip alike),
    /// texture, roughness and cut-off.
    pub fn shading(&self, surface: &InstancedSurface) -> InstancedShading {
        InstancedShading {
            base_color: surface.base_color,
            tip_color: surface.base_color,
            color_variation: self.color_variation,
            roughness: surface.perceptual_roughness,
            wind_response: self.wind_response,
            fade_band: self.fade_band,
            tip_from: 0.0,
            shadows: self.shadows,
            texture: surface.base_color_texture.clone(),
            alpha_cutoff: surface.alpha_cutoff(),
            bend_response: self.bend_response,
            thinning: None,
        }
    }
}

/// One primitive of an asset as drawn: its mesh in the asset's frame, and its surface.
#[derive(Clone, Debug, PartialEq)]
pub struct AssetPart {
    /// The mesh, its node's transform applied.
    pub mesh: Handle<Mesh>,
    /// Its material.
    pub surface: InstancedSurface,
}

/// An asset ready to draw instanced.
#[derive(Clone, Debug, PartialEq)]
pub struct ResolvedAsset {
    /// What each level of detail draws, nearest first (at least one level, none empty).
    pub levels: Vec<Vec<AssetPart>>,
    /// The collider nodes' meshes, in the asset's frame.
    pub colliders: Vec<Handle<Mesh>>,
    /// The bounds of every level (min, max), in the asset's frame.
    pub bounds: (Vec3, Vec3),
    /// The vertices of the nearest level (each position once), in the asset's frame.
    pub hull: Vec<Vec3>,
    /// The file's screen coverage hint for the levels (see [`AssetLods::switches`]).
    pub coverage: Vec<f32>,
}

impl ResolvedAsset {
    /// The collider a promoted instance gets: the collider nodes' meshes, else the hull.
    pub fn collider(&self) -> AssetCollider {
        match self.colliders.is_empty() {
            true => AssetCollider::Hull(self.hull.clone()),
            false => AssetCollider::Meshes(self.colliders.clone()),
        }
    }
}

/// Why an asset class cannot be drawn. The class draws nothing; the other classes stream on.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AssetLookError {
    /// The file did not load (missing, truncated, not glTF).
    #[error("the asset did not load: {0}")]
    Load(String),
    /// Its node tree cannot be read.
    #[error(transparent)]
    Tree(#[from] AssetTreeError),
    /// A primitive's material cannot be drawn instanced.
    #[error("a primitive's material cannot be drawn instanced: {0}")]
    Surface(#[from] SurfaceError),
    /// A primitive's mesh cannot be drawn instanced.
    #[error("a primitive's mesh cannot be drawn instanced: {0}")]
    Mesh(#[from] InstancedClassError),
    /// A primitive's mesh keeps its data in the render world only (load the file with
    /// `RenderAssetUsages::MAIN_WORLD` in its meshes' usages).
    #[error("a primitive's mesh is not in the main world")]
    MeshNotInMainWorld,
    /// Nothing under the root is drawn.
    #[error("the asset has no primitive to draw")]
    NothingDrawn,
}

/// `root` of the loaded file `gltf` made ready to draw: its primitives' meshes moved into
/// the asset's frame (added to `meshes` once per mesh and transform, shared where a node
/// does not move its mesh).
pub fn resolve_asset(
    gltf: &Gltf,
    root: &AssetRoot,
    from: GltfAssets,
    meshes: &mut Assets<Mesh>,
) -> Result<ResolvedAsset, AssetLookError> {
    let tree = asset_tree(gltf, root, from)?;
    let parts = AssetParts::split(&tree);
    let mut baker = Baker {
        meshes,
        baked: HashMap::new(),
    };
    let mut bounds = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let mut levels = Vec::with_capacity(parts.levels.len());
    for level in &parts.levels {
        let mut drawn = Vec::with_capacity(level.len());
        for placed in level {
            let surface = surface_of(&placed.primitive, from.materials)?;
            let (mesh, (lo, hi)) = baker.place(placed)?;
            bounds = (bounds.0.min(lo), bounds.1.max(hi));
            drawn.push(AssetPart { mesh, surface });
        }
        levels.push(drawn);
    }
    if levels.iter().any(Vec::is_empty) {
        return Err(AssetLookError::NothingDrawn);
    }
    let colliders = parts
        .colliders
        .iter()
        .map(|placed| baker.place(placed).map(|(mesh, _)| mesh))
        .collect::<Result<_, _>>()?;
    let hull = vertices(&levels[0], baker.meshes);
    Ok(ResolvedAsset {
        levels,
        colliders,
        bounds,
        hull,
        coverage: parts.coverage,
    })
}

/// Each vertex position of `parts`' meshes once.
fn vertices(parts: &[AssetPart], meshes: &Assets<Mesh>) -> Vec<Vec3> {
    let mut seen = std::collections::HashSet::new();
    let positions = parts
        .iter()
        .filter_map(|p| meshes.get(&p.mesh)?.attribute(Mesh::ATTRIBUTE_POSITION))
        .filter_map(|values| values.as_float3())
        .flatten();
    positions
        .filter(|p| seen.insert(p.map(f32::to_bits)))
        .map(|p| Vec3::from_array(*p))
        .collect()
}

/// The surface of a primitive (glTF's default material where it names none).
fn surface_of(
    primitive: &AssetPrimitive,
    materials: &Assets<GltfMaterial>,
) -> Result<InstancedSurface, AssetLookError> {
    let default = GltfMaterial::default();
    let material = match &primitive.material {
        Some(handle) => materials
            .get(handle)
            .ok_or_else(|| AssetTreeError::NotLoaded(format!("{handle:?}")))?,
        None => &default,
    };
    Ok(InstancedSurface::try_from(material)?)
}

/// A mesh in the asset's frame, and its bounds there.
type Baked = (Handle<Mesh>, (Vec3, Vec3));

/// Primitives' meshes moved into the asset's frame, each mesh and transform once: a part
/// every level shares is baked one time, not once per level.
struct Baker<'a> {
    meshes: &'a mut Assets<Mesh>,
    /// By mesh and the bits of the transform (translation, rotation, scale).
    baked: HashMap<(AssetId<Mesh>, [u32; 10]), Baked>,
}

impl Baker<'_> {
    fn place(&mut self, placed: &Placed<AssetPrimitive>) -> Result<Baked, AssetLookError> {
        let Transform {
            translation: t,
            rotation: r,
            scale: s,
        } = placed.transform;
        let values = [t.x, t.y, t.z, r.x, r.y, r.z, r.w, s.x, s.y, s.z];
        let key = (placed.primitive.mesh.id(), values.map(f32::to_bits));
        if let Some(done) = self.baked.get(&key) {
            return Ok(done.clone());
        }
        let done = placed_mesh(placed, self.meshes)?;
        self.baked.insert(key, done.clone());
        Ok(done)
    }
}

/// The primitive's mesh in the asset's frame, and its bounds there.
fn placed_mesh(
    placed: &Placed<AssetPrimitive>,
    meshes: &mut Assets<Mesh>,
) -> Result<Baked, AssetLookError> {
    let handle = &placed.primitive.mesh;
    let mesh = meshes
        .get(handle)
        .ok_or_else(|| AssetTreeError::NotLoaded(format!("{handle:?}")))?;
    // A render-world-only mesh keeps no attributes here (its bounds alone would pass the
    // check, its vertices could not be moved).
    if mesh.try_attributes().is_err() {
        return Err(AssetLookError::MeshNotInMainWorld);
    }
    if placed.transform == Transform::IDENTITY {
        let bounds = check(mesh)?;
        return Ok((handle.clone(), bounds));
    }
    let moved = mesh.clone().transformed_by(placed.transform);
    let bounds = check(&moved)?;
    Ok((meshes.add(moved), bounds))
}

fn check(mesh: &Mesh) -> Result<(Vec3, Vec3), AssetLookError> {
    match check_instanced_mesh(mesh) {
        Some(checked) => Ok(checked?),
        None => Err(AssetLookError::MeshNotInMainWorld),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_switch_where_given_else_where_the_asset_covers_less_of_the_screen() {
        // A 2 m box: radius sqrt(3), a quarter of a 45-degree screen at about 16.7 m.
        let bounds = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let derived = AssetLods::default().switches(3, bounds, &[]);
        assert_eq!(derived.len(), 2);
        let first = 3f32.sqrt() / (0.25 * (std::f32::consts::PI / 8.0).tan());
        assert!((derived[0] - first).abs() < 1e-3, "{derived:?}");
        assert!(
            (derived[1] - 2.0 * first).abs() < 1e-3,
            "half the cover, twice as far"
        );
        // Given distances first, the rest derived; never falling, never nonsense.
        let given = AssetLods {
            distances: vec![50.0, 20.0, f32::NAN],
            crossfade: 0.2,
        };
        let switches = given.switches(4, bounds, &[]);
        assert_eq!(switches[0], 50.0);
        assert!(
            switches[1] > 50.0 && switches[2] > switches[1],
            "{switches:?}"
        );
        assert_eq!(given.band(50.0), (45.0, 55.0));
        assert!(AssetLods::default().switches(1, bounds, &[]).is_empty());
        // The file's coverage hint where no distance is given: half the cover (0.125 of
        // the screen), twice as far as a quarter.
        let hinted = AssetLods::default().switches(3, bounds, &[0.25, 0.125, 0.01]);
        assert!((hinted[0] - first).abs() < 1e-3 && (hinted[1] - 2.0 * first).abs() < 1e-3);
        let near = AssetLods::default().switches(2, bounds, &[0.5, 0.01]);
        assert!((near[0] - first / 2.0).abs() < 1e-3, "{near:?}");
        let given_first = AssetLods {
            distances: vec![5.0],
            ..default()
        };
        assert_eq!(given_first.switches(2, bounds, &[0.5])[0], 5.0);
    }
}
