//! Scatter layers: what to place, where, how densely, and how it looks; layer files; the
//! status the plugin reports for each layer.

pub mod file;
mod image;
mod plugin;
mod status;

pub(crate) use image::too_large;
pub use image::{GroundMap, from_bevy_image};
pub(crate) use image::{set_texel_luminance, texel_luminance};
pub use plugin::RwtLayersPlugin;
pub(crate) use plugin::{init_image_assets, merge_missing, missing_asset, report_assets};
pub use status::{
    AssetFailure, AssetProblem, AssetStatus, LayerAsset, LoadFailure, ScatterLayerStatus,
};

use crate::edits::ScatterEdits;
use crate::ground::{
    FlatGround, FunctionGround, GroundRule, HeightmapGround, SharedGround, SurfaceHit,
    SurfacePolicy,
};
use crate::look::{
    ClassLook, GroundPlane, Impostor, InstanceInserter, InstancedFar, InstancedLook,
    InstancedShading, MeshLod, Pose, Stance,
};
use bevy::prelude::*;
use rwt_core::clumps::Clumps;
use rwt_core::density::{Constant, Density, NoiseDensity};
use rwt_core::query::{Lattice, Point};
use rwt_core::streaming::{Falloff, StreamingConfig};
use std::sync::Arc;

/// A density shared with generation tasks.
pub(crate) type SharedDensity = Arc<dyn Density + Send + Sync>;

/// What reflection puts in a [`LayerDensity::Custom`] it builds: no instances.
fn no_density() -> SharedDensity {
    Arc::new(Constant(0.0))
}

/// What reflection puts in a [`HeightSource::Function`] it builds: flat ground at 0.
fn flat_ground() -> HeightFn {
    Arc::new(|_| 0.0)
}

/// A density of a layer or class, in instances per square world unit on the ground (x, z).
#[derive(Clone, Reflect)]
#[reflect(Clone, Debug)]
pub enum LayerDensity {
    /// The same everywhere.
    Constant(f64),
    /// Fractal noise (`rwt_core`'s fBm density).
    Noise(NoiseDensity),
    /// A painted map: its scale is the instances per square unit where it is white.
    /// Repainting the image re-queries the chunks it covers.
    Image(GroundMap),
    /// Instances gathered into patches around sparse blue-noise parents (`rwt_core`'s
    /// clumps: Thomas or Matérn kernels).
    Clumps(Clumps),
    /// Any density of `rwt_core`. Code, not data: reflection does not see it (and makes an
    /// empty one when it builds this variant).
    Custom(#[reflect(ignore, default = "no_density")] Arc<dyn Density + Send + Sync>),
}

impl std::fmt::Debug for LayerDensity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LayerDensity::Constant(v) => write!(f, "Constant({v})"),
            LayerDensity::Noise(n) => write!(f, "{n:?}"),
            LayerDensity::Clumps(c) => write!(f, "{:?}", c.params()),
            LayerDensity::Image(map) => {
                write!(f, "Image {{ {:?}, scale: {}, .. }}", map.image, map.scale)
            }
            LayerDensity::Custom(_) => write!(f, "Custom(..)"),
        }
    }
}

impl LayerDensity {
    /// The image this density reads, if any.
    pub fn image(&self) -> Option<&Handle<Image>> {
        match self {
            LayerDensity::Image(map) => Some(&map.image),
            _ => None,
        }
    }

    /// The ground rectangle a painted map covers, if this density is one.
    pub(crate) fn image_rect(&self) -> Option<rwt_core::Rect> {
        match self {
            LayerDensity::Image(map) => map.rect(),
            _ => None,
        }
    }

    /// A thread-safe snapshot for generation tasks; `None` while a painted map is loading.
    pub fn resolve(&self, images: &Assets<Image>) -> Option<SharedDensity> {
        Some(match self {
            LayerDensity::Constant(v) => Arc::new(Constant(*v)),
            LayerDensity::Noise(n) => Arc::new(n.clone()),
            LayerDensity::Clumps(c) => Arc::new(c.clone()),
            LayerDensity::Image(map) => Arc::new(map.density(images)?),
            LayerDensity::Custom(d) => d.clone(),
        })
    }
}

/// One kind of instance in a layer: its own density (the layer's classes share one blue-noise
/// point set, paper section 6.3) and how it looks.
#[derive(Clone, Debug, Reflect)]
#[reflect(Clone, Debug)]
pub struct ScatterClass {
    /// Where and how densely this class grows.
    pub density: LayerDensity,
    /// What its instances are made of.
    pub look: ClassLook,
    /// Base scale of the instances.
    pub scale: f32,
    /// Random scale variation, hashed per instance: scale in `scale * (1 +- variation)`.
    pub scale_variation: f32,
    /// A cheaper look from some distance on (for [`ClassLook::Mesh`] classes).
    pub lod: Option<MeshLod>,
    /// Bounds (min, max) of one instance at scale 1, for picking
    /// ([`crate::picking::ScatterPicking`]); `None` uses the class mesh's bounds, or for a
    /// [`ClassLook::Custom`] class a unit box standing on the ground.
    pub pick_bounds: Option<(Vec3, Vec3)>,
    /// For a [`ClassLook::Instanced`] class: its instances near a viewer become entities
    /// (colliders, game logic), drawn exactly as before.
    pub promotion: Option<Promotion>,
    /// How its instances stand on their surface: upright, along its normal, or between.
    pub stance: Stance,
    /// Far instances drawn as impostors (for [`ClassLook::Mesh`] and
    /// [`ClassLook::Instanced`] classes).
    pub impostor: Option<Impostor>,
}

/// Near instances of an instanced class become entities: within `distance` (on the ground)
/// of any viewer, an instance leaves its chunk's buffer for an entity with a
/// [`ScatterEntity`], its `Transform` as drawn and what `insert` puts on it (a collider),
/// drawn by a child with the same instance; a little beyond the distance
/// ([`Promotion::HYSTERESIS`]) it goes back to the buffer. Both happen within one frame,
/// so the instance is never drawn twice or missing.
#[derive(Clone, Reflect)]
#[reflect(Clone, Debug)]
pub struct Promotion {
    /// Ground distance to the nearest viewer within which instances are entities.
    pub distance: f32,
    /// What a promoted instance gets. Code, not data: reflection does not see it (and
    /// inserts nothing when it builds a promotion).
    #[reflect(ignore, default = "crate::look::insert_nothing")]
    pub insert: InstanceInserter,
}

impl Promotion {
    /// Instances go back to the buffer beyond `distance` times this (so that one standing
    /// at the distance does not change every frame).
    pub const HYSTERESIS: f32 = 1.1;
}

impl std::fmt::Debug for Promotion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Promotion")
            .field("distance", &self.distance)
            .finish_non_exhaustive()
    }
}

impl ScatterClass {
    /// A class of one shared mesh and material, unit scale and 20 % variation.
    pub fn new(
        density: LayerDensity,
        mesh: Handle<Mesh>,
        material: Handle<StandardMaterial>,
    ) -> Self {
        Self::with_look(density, ClassLook::Mesh { mesh, material })
    }

    /// A class whose instances get what `insert` puts on them, e.g. a glTF scene (in a game
    /// with Bevy's `bevy_gltf` feature, which this crate does not enable):
    ///
    /// ```ignore
    /// let tree = asset_server.load(GltfAssetLabel::Scene(0).from_asset("tree.glb"));
    /// ScatterClass::custom(LayerDensity::Constant(0.05), move |e| {
    ///     e.insert(WorldAssetRoot(tree.clone()));
    /// })
    /// ```
    pub fn custom(
        density: LayerDensity,
        insert: impl Fn(&mut EntityCommands) + Send + Sync + 'static,
    ) -> Self {
        Self::with_look(density, ClassLook::Custom(Arc::new(insert)))
    }

    /// A class drawn from a glTF asset, instanced (see [`ClassLook::Asset`]).
    #[cfg(feature = "gltf")]
    pub fn asset(density: LayerDensity, look: crate::look::asset::AssetLook) -> Self {
        Self::with_look(density, ClassLook::Asset(look))
    }

    /// A class drawn from per-chunk instance buffers, without an entity per instance.
    pub fn instanced(
        density: LayerDensity,
        mesh: Handle<Mesh>,
        material: InstancedShading,
    ) -> Self {
        Self::with_look(
            density,
            ClassLook::Instanced(InstancedLook {
                mesh,
                material,
                far: None,
            }),
        )
    }

    /// An instanced class draws `mesh` instead in chunks farther than `distance` from every
    /// camera (see [`InstancedFar`]); other classes are returned unchanged.
    pub fn with_instanced_far(mut self, mesh: Handle<Mesh>, distance: f32) -> Self {
        if let ClassLook::Instanced(look) = &mut self.look {
            look.far = Some(InstancedFar { mesh, distance });
        }
        self
    }

    /// Shows `mesh` and `material` instead from `distance` on, crossfading over a tenth of
    /// the distance (see [`MeshLod`]). Only [`ClassLook::Mesh`] classes have levels of detail.
    pub fn with_lod(
        mut self,
        mesh: Handle<Mesh>,
        material: Handle<StandardMaterial>,
        distance: f32,
    ) -> Self {
        self.lod = Some(MeshLod {
            mesh,
            material,
            distance,
            crossfade: 0.1 * distance,
        });
        self
    }

    fn with_look(density: LayerDensity, look: ClassLook) -> Self {
        Self {
            density,
            look,
            scale: 1.0,
            scale_variation: DEFAULT_SCALE_VARIATION,
            lod: None,
            pick_bounds: None,
            promotion: None,
            stance: Stance::UPRIGHT,
            impostor: None,
        }
    }

    /// Draws the instances of this class (a mesh or an instanced class) from
    /// `impostor.distance` on as impostors baked from its look (see [`Impostor`]).
    pub fn with_impostor(mut self, impostor: Impostor) -> Self {
        self.impostor = Some(impostor);
        self
    }

    /// Stands instances between upright (`align` 0) and along the surface normal (1), sunk
    /// `sink` world units into the surface along their up axis.
    pub fn with_stance(mut self, align: f32, sink: f32) -> Self {
        self.stance = Stance { align, sink };
        self
    }

    /// Makes the instances of this instanced class within `distance` of a viewer entities
    /// with what `insert` puts on them (see [`Promotion`]).
    pub fn with_promotion(
        mut self,
        distance: f32,
        insert: impl Fn(&mut EntityCommands) + Send + Sync + 'static,
    ) -> Self {
        self.promotion = Some(Promotion {
            distance,
            insert: Arc::new(insert),
        });
        self
    }

    /// Picks instances by these bounds (min, max) at scale 1 (e.g. a tree's trunk and
    /// crown), instead of the mesh's.
    pub fn with_pick_bounds(mut self, min: Vec3, max: Vec3) -> Self {
        self.pick_bounds = Some((min, max));
        self
    }
}

/// The ground a layer's instances stand on.
#[derive(Clone, Reflect)]
#[reflect(Clone, Debug)]
pub enum HeightSource {
    /// Flat ground at this height.
    Constant(f32),
    /// A function of the ground position (x, z). Code, not data: reflection does not see it
    /// (and makes flat ground at 0 when it builds this variant).
    Function(#[reflect(ignore, default = "flat_ground")] Arc<dyn Fn(Vec2) -> f32 + Send + Sync>),
    /// A heightmap: its scale is the height where it is white; 0 outside.
    Image(GroundMap),
    /// The meshes of entities marked [`crate::ground::ScatterSurface`] for this layer (a terrain, a glTF
    /// level): no mesh above a point, no instance there.
    Surfaces,
    /// Any [`crate::ground::Ground`] (a terrain crate's). Code, not data: reflection does
    /// not see it (and makes flat ground at 0 when it builds this variant).
    Custom(#[reflect(ignore, default = "flat_custom")] SharedGround),
}

/// What reflection puts in a [`HeightSource::Custom`] it builds: flat ground at 0.
fn flat_custom() -> SharedGround {
    Arc::new(FlatGround(0.0))
}

/// A thread-safe height function, as [`HeightSource::Function`] holds it.
pub type HeightFn = Arc<dyn Fn(Vec2) -> f32 + Send + Sync>;

impl std::fmt::Debug for HeightSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            HeightSource::Constant(h) => write!(f, "Constant({h})"),
            HeightSource::Function(_) => write!(f, "Function(..)"),
            HeightSource::Image(map) => {
                write!(f, "Image {{ {:?}, scale: {}, .. }}", map.image, map.scale)
            }
            HeightSource::Surfaces => write!(f, "Surfaces"),
            HeightSource::Custom(_) => write!(f, "Custom(..)"),
        }
    }
}

impl HeightSource {
    /// The image this height source reads, with the ground rectangle it covers.
    pub(crate) fn image(&self) -> Option<(&Handle<Image>, Option<rwt_core::Rect>)> {
        match self {
            HeightSource::Image(map) => Some((&map.image, map.rect())),
            _ => None,
        }
    }

    /// A thread-safe snapshot; `None` while a heightmap is loading, and for
    /// [`HeightSource::Surfaces`] (the streaming plugin gathers those meshes).
    pub fn resolve(&self, images: &Assets<Image>) -> Option<SharedGround> {
        Some(match self {
            HeightSource::Constant(h) => Arc::new(FlatGround(*h)),
            HeightSource::Function(f) => Arc::new(FunctionGround::new(f.clone())),
            HeightSource::Image(map) => {
                Arc::new(HeightmapGround::new(map.density(images)?, map.size))
            }
            HeightSource::Surfaces => return None,
            HeightSource::Custom(ground) => ground.clone(),
        })
    }
}

/// A scatter layer: instances of its classes, streamed around every [`crate::RwtViewer`].
/// Removing the component (or despawning its entity) despawns all its instances. Changing
/// it in place (an inspector, a `Mut<ScatterLayer>` dereferenced mutably) streams it anew
/// with the new settings, as inserting a new one does: touch it mutably only to change it.
#[derive(Component, Clone, Debug, Reflect)]
#[reflect(Component, Clone, Debug)]
#[require(Transform, Visibility, ScatterLayerStatus, ScatterEdits)]
pub struct ScatterLayer {
    /// Classes sharing the layer's point set.
    pub classes: Vec<ScatterClass>,
    /// Width of a base Wang tile in world units. Aim for at least ~100 instances per tile
    /// where the layer is dense.
    pub tile_size: f64,
    /// Tiling seed: different seeds give unrelated layouts.
    pub seed: u64,
    /// How the seed places the tile lattice: [`Lattice::Seeded`] (the default; layers of
    /// different seeds share no lattice), or [`Lattice::Aligned`], where worlds saved
    /// before seeded lattices keep their places (layer files and edits of format 1).
    pub lattice: Lattice,
    /// Chunk size and load / unload distances.
    pub streaming: StreamingConfig,
    /// Level of detail by density: full density near the viewers, fading to none farther
    /// away. Approaching adds instances between the existing ones.
    pub falloff: Option<Falloff>,
    /// The plane the layer lies on: the x-z ground of a 3-D world (default) or the x-y plane
    /// of a 2-D one.
    pub plane: GroundPlane,
    /// The ground instances stand on.
    pub height: HeightSource,
    /// Which surfaces above a point the layer grows on: the top-most (default) or every
    /// upward-facing one.
    pub surfaces: SurfacePolicy,
    /// Whether densities count per unit of surface area (default): a 60 degree slope gets
    /// twice the instances of its shadow on the plane, as much per square metre of ground
    /// as a meadow. Otherwise per unit of the plane.
    pub per_area: bool,
    /// Instances only where the ground height is within this range.
    pub height_range: Option<(f32, f32)>,
    /// Instances only where the ground slope (rise over run) is at most this; surfaces
    /// steeper than about 75 degrees grow nothing in any case (see
    /// [`crate::ground::MAX_AREA_FACTOR`]).
    pub max_slope: Option<f32>,
    /// No instances where this density is 0.5 or more (a painted exclusion map: roads,
    /// clearings, water). Repainting it re-queries the chunks it covers, like a class map.
    pub exclusion: Option<LayerDensity>,
    /// Other layers whose instances clear this one around them (see [`KeepOut`]).
    pub keep_out: Vec<KeepOut>,
}

/// Instances of another layer clear this one around them: no instance of this layer lies
/// within `radii[c]` (world units, on the ground) of an instance of class `c` of `layer`
/// (trees clearing grass 1.2 m around their trunks, rocks clearing bushes). It follows that
/// layer's points at full detail and its edits (removing a tree gives the grass back), not
/// its own keep-outs or footprints.
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct KeepOut {
    /// The layer whose instances clear this layer.
    pub layer: LayerRef,
    /// Per class of that layer, how far its instances clear (0 or missing: not at all).
    pub radii: Vec<f32>,
}

/// Another layer: its entity, or the [`Name`] of its entity (what layer files write).
#[derive(Clone, Debug, PartialEq, Eq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub enum LayerRef {
    /// The layer entity.
    Entity(Entity),
    /// The layer entity that has this `Name`.
    Named(String),
}

impl From<Entity> for LayerRef {
    fn from(e: Entity) -> Self {
        Self::Entity(e)
    }
}

impl From<&str> for LayerRef {
    fn from(name: &str) -> Self {
        Self::Named(name.to_string())
    }
}

/// A layer's tile size (world units per base tile) unless set: in code and in layer files.
pub const DEFAULT_TILE_SIZE: f64 = 8.0;

/// A class's hashed scale variation unless set: in code and in layer files.
pub const DEFAULT_SCALE_VARIATION: f32 = 0.2;

impl ScatterLayer {
    /// A layer of these classes (one point set: class 0 alone is its own blue-noise set),
    /// tiles of [`DEFAULT_TILE_SIZE`] units, default streaming and flat ground.
    pub fn new(classes: Vec<ScatterClass>) -> Self {
        Self {
            classes,
            tile_size: DEFAULT_TILE_SIZE,
            seed: 0,
            lattice: Lattice::Seeded,
            streaming: StreamingConfig::default(),
            falloff: None,
            plane: GroundPlane::Xz,
            height: HeightSource::Constant(0.0),
            surfaces: SurfacePolicy::TopMost,
            per_area: true,
            height_range: None,
            max_slope: None,
            exclusion: None,
            keep_out: Vec::new(),
        }
    }

    /// Sets the tile size.
    pub fn with_tile_size(mut self, size: f64) -> Self {
        self.tile_size = size;
        self
    }

    /// Sets the seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Sets how the seed places the tile lattice.
    pub fn with_lattice(mut self, lattice: Lattice) -> Self {
        self.lattice = lattice;
        self
    }

    /// Sets the streaming distances.
    pub fn with_streaming(mut self, streaming: StreamingConfig) -> Self {
        self.streaming = streaming;
        self
    }

    /// Sets the density fall-off with distance: full to `near`, none from `far` on.
    pub fn with_falloff(mut self, near: f64, far: f64) -> Self {
        self.falloff = Some(Falloff::new(near, far));
        self
    }

    /// Sets the density fall-off with distance: full to `near`, falling to `floor` (a
    /// fraction of the full density) at `far` and staying there to the load distance, so
    /// that distant hills keep a sparse forest instead of going bare.
    pub fn with_falloff_floor(mut self, near: f64, far: f64, floor: f64) -> Self {
        self.falloff = Some(Falloff::new(near, far).with_floor(floor));
        self
    }

    /// Sets the plane the layer lies on.
    pub fn on_plane(mut self, plane: GroundPlane) -> Self {
        self.plane = plane;
        self
    }

    /// Sets the ground.
    pub fn with_height(mut self, height: HeightSource) -> Self {
        self.height = height;
        self
    }

    /// Grows on the meshes marked [`crate::ground::ScatterSurface`] for this layer, by `policy`.
    pub fn on_surfaces(mut self, policy: SurfacePolicy) -> Self {
        self.height = HeightSource::Surfaces;
        self.surfaces = policy;
        self
    }

    /// Sets whether densities count per unit of surface area (`true`, the default) or per
    /// unit of the plane.
    pub fn with_per_area(mut self, per_area: bool) -> Self {
        self.per_area = per_area;
        self
    }

    /// Keeps instances where the ground height is in `min..=max`.
    pub fn with_height_range(mut self, min: f32, max: f32) -> Self {
        self.height_range = Some((min, max));
        self
    }

    /// Keeps instances where the ground slope is at most `max` (rise over run).
    pub fn with_max_slope(mut self, max: f32) -> Self {
        self.max_slope = Some(max);
        self
    }

    /// Keeps this layer out of the instances of `layer`: none within `radii[c]` of one of
    /// its class `c` (see [`KeepOut`]).
    pub fn with_keep_out(mut self, layer: impl Into<LayerRef>, radii: impl Into<Vec<f32>>) -> Self {
        self.keep_out.push(KeepOut {
            layer: layer.into(),
            radii: radii.into(),
        });
        self
    }

    /// Removes instances where `mask` is 0.5 or more (e.g. a painted map with `scale: 1.0`).
    pub fn with_exclusion(mut self, mask: LayerDensity) -> Self {
        self.exclusion = Some(mask);
        self
    }

    /// Where the instance of point `p` stands on `ground`: on the surface the layer grows on
    /// there, in its class's pose and stance. Every look of a point (an entity, an instanced
    /// copy, a pick, a promotion) is placed by this.
    pub(crate) fn place(&self, p: &Point, ground: &GroundRule) -> Transform {
        let class = &self.classes[(p.class as usize).min(self.classes.len().saturating_sub(1))];
        let pose = Pose::of(&p.id, self.seed, class.scale, class.scale_variation);
        let hit = ground.surface(p).unwrap_or_else(|| SurfaceHit::flat(0.0));
        let footing = class.stance.footing(hit.height, hit.normal);
        self.plane.place(p, footing, pose, self.seed)
    }

    /// Every density the layer reads: its classes', then its exclusion's.
    pub fn densities(&self) -> impl Iterator<Item = &LayerDensity> {
        self.classes
            .iter()
            .map(|c| &c.density)
            .chain(self.exclusion.iter())
    }
}

/// Marks an instance that is an entity: spawned by a layer's entity class, or promoted from
/// an instanced class near a viewer (see [`Promotion`]). Instances drawn from chunk buffers
/// have none.
#[derive(Component, Clone, Copy, Debug, PartialEq, Eq, Hash, Reflect)]
#[reflect(Component, Clone, Debug, PartialEq, Hash)]
pub struct ScatterEntity {
    /// The layer entity.
    pub layer: Entity,
    /// Stable identity of the point the instance stands on.
    pub id: rwt_core::query::PointId,
    /// Class index in the layer.
    pub class: u16,
}
