//! Instanced classes: dense foliage (grass, flowers, pebbles) without an entity per instance.
//!
//! A class whose look is [`ClassLook::Instanced`](crate::ClassLook::Instanced) is packed,
//! in the chunk's generation task on the async compute pool, into one [`InstanceBuffer`] per
//! chunk: [`GpuInstance`]s of 24 bytes, positions relative to the chunk's corner so that
//! precision holds far from the origin. One entity per (chunk, class) carries it as an
//! [`InstancedChunk`] with an `Aabb` for frustum culling; the render plugin
//! ([`RwtInstancingPlugin`]) draws each with one instanced draw call.
//!
//! Each instance also stores the level-of-detail factor at which its point appears (its
//! rank over the local density). The vertex shader grows an instance in over a band of
//! that factor as the viewer approaches and shrinks it out as the viewer leaves, so a
//! layer with a [`Falloff`](rwt_core::streaming::Falloff) neither pops when chunks change
//! band nor at the streaming edge.

mod bend;
mod far;
mod mesh;
mod pack;
mod plugin;
mod promote;
mod queue;
mod render;

pub use bend::{BEND_FIELD_TEXELS, BEND_RECOVERY, BEND_TEXEL, BendField, Bender};
pub use mesh::InstancedMeshes;
pub(crate) use pack::{InstancedClasses, PackedClass};
pub use plugin::RwtInstancingPlugin;
pub use promote::PromotedInstance;
pub(crate) use queue::{InstancedQueue, Upload};

use crate::look::InstancedShading;
use bevy::camera::primitives::Aabb;
use bevy::camera::visibility::{self, VisibilityClass};
use bevy::prelude::*;
use bytemuck::{Pod, Zeroable};
use rwt_core::query::PointId;
use rwt_core::streaming::ChunkCoord;
use std::sync::Arc;

/// Wind for every instanced class: sway from a world-space noise field, coherent across
/// chunk borders.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Resource, Clone, Debug, PartialEq)]
pub struct RwtWind {
    /// Direction on the ground (x, z); normalized by the shader.
    pub direction: Vec2,
    /// Strength: 0 is still air, 1 a stiff breeze.
    pub strength: f32,
    /// Spatial frequency of the gusts, cycles per world unit.
    pub frequency: f32,
    /// How fast the gusts travel, world units per second.
    pub speed: f32,
}

impl Default for RwtWind {
    fn default() -> Self {
        Self {
            direction: Vec2::new(1.0, 0.3),
            strength: 0.5,
            frequency: 0.05,
            speed: 4.0,
        }
    }
}

/// Whether instanced classes grow in and out with the level of detail (the default) or
/// appear and vanish at full size: turn it off to see the popping the fade hides.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Eq, Reflect)]
#[reflect(Resource, Clone, Debug, PartialEq)]
pub struct RwtFadeIn(pub bool);

impl Default for RwtFadeIn {
    fn default() -> Self {
        Self(true)
    }
}

/// One instance as the GPU reads it: 24 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuInstance {
    /// Position relative to the chunk's corner (x, height, z).
    pub offset: [f32; 3],
    /// Uniform scale.
    pub scale: f32,
    /// Turn about y, as a fraction of a full turn (`u16::MAX` is one turn).
    pub yaw: u16,
    /// Level-of-detail factor at which the point appears, `0..=u16::MAX` for 0..=1.
    pub appear: u16,
    /// Colour variation hashed from the point, `0..=u16::MAX` for 0..=1.
    pub tint: u16,
    /// Padding (keeps the stride a multiple of 8).
    pub reserved: u16,
}

/// Bytes per instance on the GPU.
pub const GPU_BYTES_PER_INSTANCE: usize = std::mem::size_of::<GpuInstance>();

impl GpuInstance {
    /// The turn about y, radians in `[0, 2 pi)`.
    pub fn yaw_radians(&self) -> f32 {
        self.yaw as f32 / 65_536.0 * std::f32::consts::TAU
    }

    /// The level-of-detail factor at which the instance appears, 0..=1.
    pub fn appear_factor(&self) -> f32 {
        self.appear as f32 / u16::MAX as f32
    }
}

/// A chunk's instances of one class, packed for the GPU.
#[derive(Debug, Default)]
pub struct InstanceBuffer {
    /// The instances, in query order.
    pub instances: Vec<GpuInstance>,
    /// The identities of the instances, in the same order, when
    /// [`RwtSettings::keep_instance_ids`](crate::RwtSettings::keep_instance_ids) is set
    /// (tests and tools; 24 more bytes per instance on the CPU); empty otherwise.
    pub ids: Vec<PointId>,
    /// Bounds of the instances' positions relative to the chunk corner.
    pub bounds: (Vec3, Vec3),
}

/// One chunk's instances of one instanced class: drawn by [`RwtInstancingPlugin`] with one
/// instanced draw, culled by its `Aabb`.
#[derive(Component, Clone, Debug, Reflect)]
#[reflect(Component, Clone, Debug)]
#[require(Transform, Visibility, VisibilityClass)]
#[component(on_add = visibility::add_visibility_class::<InstancedChunk>)]
pub struct InstancedChunk {
    /// The layer entity.
    pub layer: Entity,
    /// The chunk.
    pub chunk: ChunkCoord,
    /// The class index in the layer.
    pub class: u16,
    /// The mesh every instance draws now: the class's, or its far mesh while the chunk is
    /// far from every camera (see [`InstancedFar`](crate::look::InstancedFar)).
    pub mesh: Handle<Mesh>,
    /// The class's meshes: near, and far with its distance.
    pub meshes: (Handle<Mesh>, Option<crate::look::InstancedFar>),
    /// The shading.
    pub material: InstancedShading,
    /// Height of the mesh's top above its origin (the tip, which sways most).
    pub mesh_top: f32,
    /// Largest scale of the class's instances (for the chunk's bounds).
    pub max_scale: f32,
    /// Level-of-detail fall-off of the layer (`near`, `far`, `floor`), for the shader's
    /// fade; `None` when the layer has none (instances stay at full size).
    pub falloff: Option<(f32, f32, f32)>,
    /// The instances (shared with the render world without copying). Reflection does not
    /// see them: bulk data, counted by [`InstancedChunk::len`].
    #[reflect(ignore)]
    pub buffer: Arc<InstanceBuffer>,
}

impl InstancedChunk {
    /// Instances in the chunk.
    pub fn len(&self) -> usize {
        self.buffer.instances.len()
    }

    /// Whether the chunk holds no instance.
    pub fn is_empty(&self) -> bool {
        self.buffer.instances.is_empty()
    }

    /// Bounds of the instances with `mesh` (min, max) around each (turned any way, at the
    /// largest scale, swaying up to its height), relative to the chunk corner.
    pub fn aabb(&self, mesh: (Vec3, Vec3)) -> Aabb {
        let (lo, hi) = self.buffer.bounds;
        let (mesh_lo, mesh_hi) = mesh;
        let reach = mesh_lo.abs().max(mesh_hi.abs());
        let s = self.max_scale;
        let horizontal = (reach.x.max(reach.z) * std::f32::consts::SQRT_2 + reach.y) * s;
        let min = lo + Vec3::new(-horizontal, mesh_lo.y.min(0.0) * s, -horizontal);
        let max = hi + Vec3::new(horizontal, mesh_hi.y.max(0.0) * s, horizontal);
        Aabb::from_min_max(min, max)
    }
}

/// Distance from `point` to the box `aabb` (0 inside).
pub(crate) fn distance_to_box(aabb: &Aabb, point: Vec3) -> f32 {
    let d = (Vec3::from(aabb.center) - point).abs() - Vec3::from(aabb.half_extents);
    d.max(Vec3::ZERO).length()
}
