//! What `cull.wgsl` reads of a view and of each chunk in it, and the same test on the CPU
//! (for the check and the unit tests).

#[cfg(any(test, feature = "testing"))]
use crate::instancing::chunk::GpuInstance;
use crate::instancing::render::uniforms::LodUniform;
use bevy::prelude::*;
use bevy::render::render_resource::ShaderType;

/// One view's dispatch, as `cull.wgsl` reads it (from a storage buffer, at a dynamic
/// offset): the view, its phase and its records.
#[derive(Clone, Copy, Debug, Default, ShaderType)]
pub(in crate::instancing) struct CullView {
    /// The view's half-spaces (normal, distance; inside where `dot(n, p) + d > 0`).
    pub planes: [Vec4; 6],
    /// In a directional light's cascade, the half-spaces of the region whose fragments read
    /// its shadows (grown by a margin;
    /// [`receivers`](crate::instancing::render::receivers)), and the direction the light
    /// travels (`w` 1; 0 where every caster counts).
    pub receivers: [Vec4; 6],
    pub light: Vec4,
    /// The view's clip space from world space: last frame's (early phase), this frame's
    /// (late phase).
    pub clip_from_world: Mat4,
    /// Where the level of detail is measured from: the view's camera, or the main camera
    /// for shadow views.
    pub eye: Vec3,
    /// Occlusion's phase: 0 none, 1 early, 2 late.
    pub phase: u32,
    /// The view's first record, and how many it has.
    pub first_record: u32,
    pub records: u32,
    /// The dispatch's workgroups, and how many along x.
    pub workgroups: u32,
    pub workgroups_x: u32,
}

/// One chunk in one view, as `cull.wgsl` reads it (an array of them in a storage buffer):
/// its level of detail, its instances and where it keeps them.
#[derive(Clone, Copy, Debug, Default, ShaderType)]
pub(in crate::instancing) struct CullRecord {
    /// The chunk's corner.
    pub origin: Vec3,
    /// The radius around its root of an instance of scale 1, its sway and any lean or
    /// tilt included.
    pub reach: f32,
    /// In a shadow view, the class's shadow distance from the eye; negative: none.
    pub shadow_distance: f32,
    /// Distance from the eye within which instances are not drawn (the start of an
    /// impostor's crossfade; 0 for other chunks).
    pub fade_in_from: f32,
    /// Distance from the eye beyond which instances are not drawn (the end of a mesh's
    /// crossfade with its impostors; 0: none).
    pub fade_out_to: f32,
    /// The chunk's level of detail, as its uniform has it.
    pub lod: LodUniform,
    /// Instances in the chunk, and the first of them in the slab.
    pub instances: u32,
    pub first_instance: u32,
    /// The view's first workgroup that tests this chunk.
    pub first_workgroup: u32,
    /// Where the chunk's kept instances go in the view's binding of the pool (instances):
    /// the early phase's, the late phase's.
    pub kept: u32,
    pub late_kept: u32,
    /// The words of the draw's instance counts in the indirect arguments: the early
    /// block's, the late block's.
    pub count_word: u32,
    pub late_count_word: u32,
    /// The chunk's first word of marks (occlusion).
    pub first_mark: u32,
}

#[cfg(any(test, feature = "testing"))]
impl CullRecord {
    /// Whether `view` may see `instance` of this chunk: `cull.wgsl`'s test, on the CPU.
    pub(in crate::instancing) fn keeps(&self, view: &CullView, instance: &GpuInstance) -> bool {
        let root = self.origin + Vec3::from(instance.offset);
        let appear = f32::from(instance.appear) / 65535.0;
        let from_eye = (root.xz() - view.eye.xz()).length();
        let kept = self.lod.kept_fraction(from_eye);
        let scale = instance.scale * self.lod.growth(from_eye, appear, kept);
        if scale <= 0.0 {
            return false;
        }
        let radius = self.reach * scale / kept;
        let distance = root.distance(view.eye);
        if self.shadow_distance >= 0.0 && distance - radius > self.shadow_distance {
            return false;
        }
        let beyond = self.fade_out_to > 0.0 && distance >= self.fade_out_to;
        if distance < self.fade_in_from || beyond {
            return false;
        }
        let casts = view.light.w == 0.0
            || crate::instancing::render::receivers::casts(
                &view.receivers,
                view.light.truncate(),
                root,
                radius,
            );
        casts
            && view
                .planes
                .iter()
                .all(|p| p.truncate().dot(root) + p.w + radius > 0.0)
    }
}
