//! How instances look, below every module that places or draws them: a class's look
//! ([`ClassLook`]: a shared mesh, a game's own components, instanced, or a glTF asset drawn
//! instanced), the instanced look's mesh and shading, the checks an instanced mesh must
//! pass, and the rule that turns a point into a transform ([`Pose`],
//! [`GroundPlane::place`]), which the entity and the instanced path share so that both put
//! one point in the same place.

pub mod asset;
mod blade;
mod check;
mod impostor;
mod instanced;

pub use blade::{blade_mesh, blade_mesh_with_rows, far_blade_mesh};
pub use check::{InstancedClassError, check_instanced_mesh};
pub(crate) use check::{check_texture, check_topology};
pub use impostor::Impostor;
pub use instanced::{
    DEFAULT_ALPHA_CUTOFF, InstancedFar, InstancedLook, InstancedShading, InstancedShadows,
    InstancedThinning,
};

use bevy::camera::visibility::VisibilityRange;
use bevy::prelude::*;
use rwt_core::query::{Point, PointId};
use std::sync::Arc;

/// Inserts a class's own components into every instance it spawns (after `Transform` and
/// [`crate::ScatterEntity`]).
pub type InstanceInserter = Arc<dyn Fn(&mut EntityCommands) + Send + Sync>;

/// What reflection puts in an [`InstanceInserter`] it builds: nothing.
pub(crate) fn insert_nothing() -> InstanceInserter {
    Arc::new(|_| {})
}

/// How the instances of a class look.
#[derive(Clone, Reflect)]
#[reflect(Clone)]
pub enum ClassLook {
    /// A mesh and a material shared by every instance, so Bevy batches them.
    Mesh {
        /// The mesh.
        mesh: Handle<Mesh>,
        /// The material.
        material: Handle<StandardMaterial>,
    },
    /// Whatever the function inserts: a glTF scene (`WorldAssetRoot(handle.clone())`,
    /// with Bevy's `bevy_gltf` feature in the game), another material type, colliders,
    /// markers. Code, not data: reflection does not see it (and inserts nothing when it
    /// builds this variant).
    Custom(#[reflect(ignore, default = "insert_nothing")] InstanceInserter),
    /// No entity per instance: each chunk's instances are packed into one GPU buffer and
    /// drawn with one instanced draw (grass, flowers, pebbles; see [`crate::instancing`]).
    /// Only on the [`GroundPlane::Xz`] plane.
    Instanced(InstancedLook),
    /// A game's own glTF asset, drawn instanced as [`ClassLook::Instanced`] is: one draw per
    /// primitive per chunk and view, each with its own material. Only on the
    /// [`GroundPlane::Xz`] plane.
    #[cfg(feature = "gltf")]
    Asset(asset::AssetLook),
}

impl ClassLook {
    /// Whether instances of this look are packed and drawn instanced rather than spawned.
    pub fn is_instanced(&self) -> bool {
        match self {
            ClassLook::Instanced(_) => true,
            #[cfg(feature = "gltf")]
            ClassLook::Asset(_) => true,
            ClassLook::Mesh { .. } | ClassLook::Custom(_) => false,
        }
    }

    /// Whether this look is a glTF asset's ([`ClassLook::Asset`]).
    pub fn is_asset(&self) -> bool {
        match self {
            #[cfg(feature = "gltf")]
            ClassLook::Asset(_) => true,
            _ => false,
        }
    }
}

impl std::fmt::Debug for ClassLook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ClassLook::Mesh { mesh, material } => f
                .debug_struct("Mesh")
                .field("mesh", mesh)
                .field("material", material)
                .finish(),
            ClassLook::Custom(_) => f.write_str("Custom(..)"),
            ClassLook::Instanced(look) => look.fmt(f),
            #[cfg(feature = "gltf")]
            ClassLook::Asset(look) => look.fmt(f),
        }
    }
}

/// The far level of detail of a mesh class: from `distance` to the camera on, instances show
/// this mesh and material instead of the class's, crossfading (Bevy's dithered
/// [`VisibilityRange`]) over `crossfade` around `distance`. Each instance then has one child
/// entity holding the far look.
#[derive(Clone, Debug, Reflect)]
#[reflect(Clone, Debug)]
pub struct MeshLod {
    /// The far mesh, standing on the same origin as the near one.
    pub mesh: Handle<Mesh>,
    /// The far material.
    pub material: Handle<StandardMaterial>,
    /// Distance of the switch.
    pub distance: f32,
    /// Width of the crossfade band centred on `distance`.
    pub crossfade: f32,
}

impl MeshLod {
    /// The visibility ranges of the near and the far look; the far look fades out over
    /// `until` (an impostor's crossfade band) when given.
    pub fn ranges(&self, until: Option<(f32, f32)>) -> (VisibilityRange, VisibilityRange) {
        let half = (0.5 * self.crossfade).clamp(0.0, 0.99 * self.distance.max(0.0));
        let switch = (self.distance - half).max(0.0)..self.distance + half;
        let near = VisibilityRange {
            start_margin: 0.0..0.0,
            end_margin: switch.clone(),
            use_aabb: false,
        };
        let far = VisibilityRange {
            start_margin: switch,
            end_margin: until.map_or(Self::NEVER..Self::NEVER, |(a, b)| a..b),
            use_aabb: false,
        };
        (near, far)
    }

    /// A distance no camera reaches (the far look never fades out).
    pub(crate) const NEVER: f32 = 1.0e9;
}

/// How a point's instance is turned and sized: hashed from its identity, so every look of
/// one point (an entity, an instanced copy) agrees.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct Pose {
    /// Turn about the plane's normal, radians in `[0, 2 pi)`.
    pub yaw: f64,
    /// Uniform scale: the class's scale times the point's hashed variation.
    pub scale: f32,
}

impl Pose {
    /// The pose of point `id` in a layer of `seed`, for a class of `scale` and
    /// `variation` (scale in `scale * (1 +- variation)`).
    pub fn of(id: &PointId, seed: u64, scale: f32, variation: f32) -> Self {
        Self {
            yaw: id.rotation(seed),
            scale: scale * id.scale(seed, variation as f64) as f32,
        }
    }
}

/// How a class's instances stand on their surface.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct Stance {
    /// 0: upright (along the plane's up), 1: along the surface normal; in between, the
    /// direction between them.
    pub align: f32,
    /// How far an instance sinks into its surface along its up axis, in world units.
    pub sink: f32,
}

impl Stance {
    /// Upright, standing on the surface.
    pub const UPRIGHT: Self = Self {
        align: 0.0,
        sink: 0.0,
    };

    /// Where an instance of this stance stands on a surface of `height` and unit `normal`
    /// (in the plane's frame: `y` up from the plane).
    pub fn footing(&self, height: f32, normal: Vec3) -> Footing {
        let align = if self.align.is_finite() {
            self.align.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let up = Vec3::Y.lerp(normal, align).normalize_or(Vec3::Y);
        let sink = if self.sink.is_finite() {
            self.sink
        } else {
            0.0
        };
        Footing { height, up, sink }
    }
}

impl Default for Stance {
    fn default() -> Self {
        Self::UPRIGHT
    }
}

/// Where one instance stands: its surface's height, its up axis and how far it sinks (in
/// the plane's frame: `y` up from the plane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footing {
    /// Height of the surface above the plane.
    pub height: f32,
    /// The instance's up axis (unit).
    pub up: Vec3,
    /// How far it sinks along `up`, in world units.
    pub sink: f32,
}

impl Footing {
    /// Upright on a surface of `height`.
    pub fn upright(height: f32) -> Self {
        Self {
            height,
            up: Vec3::Y,
            sink: 0.0,
        }
    }
}

/// Salt of the depth hash that keeps overlapping sprites of a [`GroundPlane::Xy`] layer in
/// a stable order.
const DEPTH_SALT: u64 = 0xde97;

/// The plane a layer lies on. Ground positions `(u, v)` of the point set and the height
/// `h` of the [`crate::HeightSource`] become these world positions.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize, Reflect,
)]
#[reflect(Clone, Debug, Default, PartialEq, Hash)]
pub enum GroundPlane {
    /// A 3-D world with y up: `(u, h, v)`, instances turned about y.
    #[default]
    Xz,
    /// A 2-D world (sprites): `(u, v, h + depth)`, instances turned about z. `depth` is a
    /// hash of the point in `[0, 0.001)`, so that overlapping sprites keep a stable order.
    Xy,
}

impl GroundPlane {
    /// The ground position of a world point: its (x, z) on the ground of a 3-D world, its
    /// (x, y) on a 2-D plane.
    pub fn ground_of(self, p: Vec3) -> Vec2 {
        match self {
            GroundPlane::Xz => p.xz(),
            GroundPlane::Xy => p.xy(),
        }
    }

    /// The world point at ground position `ground`, `height` above the plane (along y on
    /// the ground of a 3-D world, along z, towards a 2-D camera, on a 2-D plane).
    pub fn point_at(self, ground: Vec2, height: f32) -> Vec3 {
        match self {
            GroundPlane::Xz => Vec3::new(ground.x, height, ground.y),
            GroundPlane::Xy => Vec3::new(ground.x, ground.y, height),
        }
    }

    /// A vector of the plane's frame (`y` up from the plane) in the world.
    pub fn vector_of(self, v: Vec3) -> Vec3 {
        match self {
            GroundPlane::Xz => v,
            GroundPlane::Xy => Vec3::new(v.x, v.z, v.y),
        }
    }

    /// Where an instance of `p` stands: its ground position on `footing`, turned by the
    /// pose's yaw about the footing's up axis and scaled, with the sprite depth of the x-y
    /// plane hashed from its identity in a layer of `seed`.
    pub fn place(self, p: &Point, footing: Footing, pose: Pose, seed: u64) -> Transform {
        let ground = Vec2::new(p.position.x as f32, p.position.y as f32);
        let yaw = pose.yaw as f32;
        let up = self.vector_of(footing.up);
        let sunk = -up * footing.sink;
        let (translation, rotation) = match self {
            GroundPlane::Xz => (
                Vec3::new(ground.x, footing.height, ground.y),
                Quat::from_rotation_arc(Vec3::Y, up) * Quat::from_rotation_y(yaw),
            ),
            GroundPlane::Xy => {
                // Sprites of one height are ordered by a depth hashed from their identity.
                let depth = p.id.unit(seed, DEPTH_SALT) as f32;
                (
                    Vec3::new(ground.x, ground.y, footing.height + depth * 1e-3),
                    Quat::from_rotation_arc(Vec3::Z, up) * Quat::from_rotation_z(yaw),
                )
            }
        };
        Transform::from_translation(translation + sunk)
            .with_rotation(rotation)
            .with_scale(Vec3::splat(pose.scale))
    }
}
