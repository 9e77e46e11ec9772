//! A chunk's instances of one class, as the main world holds them: [`GpuInstance`]s packed
//! in an [`InstanceBuffer`], carried by an [`InstancedChunk`] entity.

use crate::look::InstancedShading;
use crate::look::asset::InstancedSurface;
use bevy::camera::primitives::Aabb;
use bevy::camera::visibility::{self, VisibilityClass};
use bevy::prelude::*;
use bytemuck::{Pod, Zeroable};
use rwt_core::query::PointId;
use rwt_core::streaming::ChunkCoord;
use std::sync::Arc;

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
    /// The instance's up axis, tilted from y (a class's [`crate::Stance`]): its x and z
    /// components as two signed bytes (low byte x, high byte z, in 127ths); 0 is upright.
    pub tilt: u16,
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

    /// The packed form of a unit up axis (see [`GpuInstance::tilt`]); the axis the shader
    /// and [`GpuInstance::up`] read back is within 1/127 of it in x and z.
    pub fn pack_up(up: Vec3) -> u16 {
        let byte = |c: f32| ((c.clamp(-1.0, 1.0) * 127.0).round() as i8) as u8 as u16;
        byte(up.x) | (byte(up.z) << 8)
    }

    /// The instance's up axis (unit), as the shader reads it.
    pub fn up(&self) -> Vec3 {
        let signed = |b: u16| (b as u8 as i8) as f32 / 127.0;
        let (x, z) = (signed(self.tilt & 0xff), signed(self.tilt >> 8));
        Vec3::new(x, (1.0 - x * x - z * z).max(0.0).sqrt(), z).normalize_or(Vec3::Y)
    }

    /// The instance's turn: its yaw about y, then its tilt onto its up axis.
    pub fn rotation(&self) -> Quat {
        Quat::from_rotation_arc(Vec3::Y, self.up()) * Quat::from_rotation_y(self.yaw_radians())
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

/// One chunk's instances of one instanced class: drawn by [`RwtInstancingPlugin`](super::RwtInstancingPlugin) with one
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
    /// Whether culling per instance may choose between the near and the far mesh by each
    /// instance's own distance rather than the chunk's: the class has a far mesh as tall
    /// as its near one (the shader's reference for the colours' gradient and the sway).
    pub far_per_instance: bool,
    /// The shading.
    pub material: InstancedShading,
    /// An asset's primitive: its material, lit as Bevy's PBR lights a glTF material (then
    /// `material` gives the colour variation, wind, bend, fade and shadows, and mirrors the
    /// surface's base colour, texture, roughness and cut-off).
    pub surface: Option<InstancedSurface>,
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
    /// Drawn as impostors: cards showing the atlas (the material's texture) from the
    /// nearest view, from the start of the band on.
    pub impostor: Option<ImpostorDraw>,
    /// The crossfade band (distance from the camera to an instance's root) over which the
    /// instances fade out, dithered, where the class's impostors take over.
    pub fade_out: Option<(f32, f32)>,
    /// The crossfade band over which the instances fade in, dithered, where a nearer level
    /// of detail of the class hands over to this one (the same band as that level's
    /// `fade_out`).
    pub fade_in: Option<(f32, f32)>,
}

/// How a chunk of impostors is drawn: where the atlas's views lie, and the crossfade band
/// (distance from the camera to an instance's root) over which the cards fade in,
/// dithered as Bevy's visibility ranges fade the meshes out.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct ImpostorDraw {
    /// Where the atlas's views lie.
    pub frames: crate::impostor::ImpostorFrames,
    /// The crossfade band (start, end).
    pub band: (f32, f32),
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
        let across = reach.x.max(reach.z) * std::f32::consts::SQRT_2;
        let horizontal = (across + reach.y) * s;
        // A tilted instance (up to 75.5 degrees) lowers its side by up to its reach across.
        let below = (mesh_lo.y.min(0.0) - across) * s;
        let min = lo + Vec3::new(-horizontal, below, -horizontal);
        let max = hi + Vec3::new(horizontal, mesh_hi.y.max(0.0) * s, horizontal);
        Aabb::from_min_max(min, max)
    }
}

/// Distance from `point` to the box `aabb` (0 inside).
pub(crate) fn distance_to_box(aabb: &Aabb, point: Vec3) -> f32 {
    let d = (Vec3::from(aabb.center) - point).abs() - Vec3::from(aabb.half_extents);
    d.max(Vec3::ZERO).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `instanced.wgsl`'s `tilt`, written out on the CPU.
    fn shader_tilt(v: Vec3, up: Vec3) -> Vec3 {
        let w = Vec3::new(up.z, 0.0, -up.x);
        let wv = w.cross(v);
        v + wv + w.cross(wv) / (1.0 + up.y)
    }

    #[test]
    fn a_packed_tilt_turns_as_the_entity_path_does() {
        for (i, up) in [
            Vec3::Y,
            Vec3::new(0.3, 1.0, -0.2),
            Vec3::new(-1.0, 0.4, 0.0),
            Vec3::new(0.0, 0.26, 0.97),
        ]
        .map(Vec3::normalize)
        .into_iter()
        .enumerate()
        {
            let g = GpuInstance {
                yaw: 12_000 * i as u16,
                tilt: GpuInstance::pack_up(up),
                ..default()
            };
            // Read back within a byte's step of the axis it packed.
            assert!(g.up().distance(up) < 0.02, "{up} read back as {}", g.up());
            // The shader's rotation of every axis is the promoted entity's rotation.
            let yaw = Quat::from_rotation_y(g.yaw_radians());
            for v in [Vec3::X, Vec3::Y, Vec3::Z, Vec3::new(0.3, 0.7, -0.2)] {
                let shader = shader_tilt(yaw * v, g.up());
                assert!(shader.distance(g.rotation() * v) < 1e-5, "{up}: {v}");
            }
        }
        assert_eq!(GpuInstance::pack_up(Vec3::Y), 0);
    }
}
