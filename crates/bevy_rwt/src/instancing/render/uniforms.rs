//! The uniforms `instanced.wgsl` reads, as `ShaderType`s: laid out by encase, as WGSL lays
//! out its `Chunk` and `Frame` structs (the naga check compares the two).

use crate::instancing::chunk::ImpostorDraw;
use crate::look::InstancedShading;
use crate::look::asset::InstancedSurface;
use bevy::prelude::*;
use bevy::render::render_resource::ShaderType;
use bevy::render::render_resource::encase::UniformBuffer;
use bevy::render::render_resource::encase::internal::WriteInto;

/// One chunk's uniform: where it lies, and its class's look.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub(super) struct ChunkUniform {
    /// The chunk's corner.
    pub origin: Vec3,
    /// The mesh's top (its height at scale 1).
    pub mesh_top: f32,
    pub base_color: Vec4,
    pub tip_color: Vec4,
    pub color_variation: f32,
    pub roughness: f32,
    pub wind_response: f32,
    /// Height fraction where the tip colour starts.
    pub tip_from: f32,
    /// The level of detail (at an offset of 64 bytes: a uniform's struct member starts on
    /// 16).
    pub lod: LodUniform,
    /// The wind (`RwtWind`): its direction (x, z), strength, frequency and speed.
    pub wind_direction: Vec2,
    pub wind_strength: f32,
    pub wind_frequency: f32,
    pub wind_speed: f32,
    pub bend_response: f32,
    pub alpha_cutoff: f32,
    /// 1 when the class has a texture.
    pub textured: u32,
    /// The crossfade band (distance from the eye to a root) impostors fade in over; both 0
    /// for other chunks.
    pub fade_in_from: f32,
    pub fade_in_to: f32,
    /// The crossfade band a class's mesh fades out over where its impostors take over;
    /// both 0 for other chunks.
    pub fade_out_from: f32,
    pub fade_out_to: f32,
    /// Impostors: half the width and height of a baked view, at scale 1.
    pub impostor_half: Vec2,
    /// Impostors: where the views look, and how many there are around and up.
    pub impostor_center: Vec3,
    pub impostor_views: u32,
    pub impostor_rows: u32,
    /// An asset's surface: its metallic and reflectance factors, and the light it emits
    /// (linear, alpha unused).
    pub metallic: f32,
    pub reflectance: f32,
    pub emissive: Vec4,
}

impl ChunkUniform {
    /// The uniform of a chunk at `origin` of a class drawn with `mesh_top`, `material` and
    /// the fall-off `(near, far, floor)`; no wind yet (the render world adds it).
    pub fn new(
        origin: Vec3,
        mesh_top: f32,
        m: &InstancedShading,
        falloff: Option<(f32, f32, f32)>,
    ) -> Self {
        Self {
            origin,
            mesh_top,
            base_color: Vec4::from_array(m.base_color.to_linear().to_f32_array()),
            tip_color: Vec4::from_array(m.tip_color.to_linear().to_f32_array()),
            color_variation: m.color_variation,
            roughness: m.roughness,
            wind_response: m.wind_response,
            lod: LodUniform::new(m, falloff),
            tip_from: m.tip_from.clamp(0.0, 0.99),
            bend_response: m.bend_response,
            alpha_cutoff: m.alpha_cutoff,
            textured: u32::from(m.texture.is_some()),
            ..default()
        }
    }

    /// The uniform drawing a primitive of `surface` (its other factors are in the
    /// shading the uniform was made with).
    pub fn with_surface(self, surface: Option<&InstancedSurface>) -> Self {
        let Some(s) = surface else { return self };
        Self {
            metallic: s.metallic,
            reflectance: s.reflectance,
            emissive: Vec4::from_array(s.emissive.to_f32_array()),
            ..self
        }
    }

    /// The uniform drawing impostors as `draw` says, or a mesh fading in and out over the
    /// bands `fade_in` and `fade_out`.
    pub fn with_impostor(
        self,
        draw: Option<&ImpostorDraw>,
        fade_in: Option<(f32, f32)>,
        fade_out: Option<(f32, f32)>,
    ) -> Self {
        let (fade_in_from, fade_in_to) = fade_in.unwrap_or((0.0, 0.0));
        let (fade_out_from, fade_out_to) = fade_out.unwrap_or((0.0, 0.0));
        let this = Self {
            fade_in_from,
            fade_in_to,
            fade_out_from,
            fade_out_to,
            ..self
        };
        let Some(d) = draw else { return this };
        Self {
            fade_in_from: d.band.0,
            fade_in_to: d.band.1,
            impostor_half: d.frames.half,
            impostor_center: d.frames.center,
            impostor_views: d.frames.views,
            impostor_rows: d.frames.rows,
            ..this
        }
    }
}

/// A class's level of detail as both `instanced.wgsl` and culling read it (`Lod` in
/// `fade.wgsl`): the fall-off by distance, the band instances grow over, far thinning.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub(super) struct LodUniform {
    /// The fall-off: near, far, the factor's floor; 1 when the layer has one (and the fade
    /// is on).
    pub falloff_near: f32,
    pub falloff_far: f32,
    pub falloff_floor: f32,
    pub falloff_on: u32,
    /// The band of ranks an instance grows over (never 0).
    pub fade_band: f32,
    /// Far thinning: its distance, its floor; 1 when on.
    pub thinning_from: f32,
    pub thinning_floor: f32,
    pub thinning_on: u32,
}

impl LodUniform {
    /// The level of detail of a class drawn with `m` and the fall-off `(near, far, floor)`.
    fn new(m: &InstancedShading, falloff: Option<(f32, f32, f32)>) -> Self {
        let (falloff_near, falloff_far, falloff_floor) = falloff.unwrap_or((0.0, 1.0, 0.0));
        let thinning = m
            .thinning
            .map(|t| (t.from.max(0.0), t.floor.clamp(1e-3, 1.0)));
        Self {
            falloff_near,
            falloff_far,
            falloff_floor,
            falloff_on: u32::from(falloff.is_some()),
            fade_band: m.fade_band.max(1e-3),
            thinning_from: thinning.map_or(0.0, |t| t.0),
            thinning_floor: thinning.map_or(0.0, |t| t.1),
            thinning_on: u32::from(thinning.is_some()),
        }
    }

    /// `fade.wgsl`'s fraction kept by far thinning, `from_eye` from the eye across.
    #[cfg(any(test, feature = "testing"))]
    pub fn kept_fraction(&self, from_eye: f32) -> f32 {
        if self.thinning_on == 0 {
            return 1.0;
        }
        let ratio = self.thinning_from / from_eye.max(1e-3);
        (ratio * ratio).clamp(self.thinning_floor, 1.0)
    }

    /// `fade.wgsl`'s growth, `from_eye` from the eye across.
    #[cfg(any(test, feature = "testing"))]
    pub fn growth(&self, from_eye: f32, appear: f32, kept: f32) -> f32 {
        let band = self.fade_band;
        let thinned = ((kept * (1.0 + band) - appear) / band).clamp(0.0, 1.0);
        if self.falloff_on == 0 {
            return thinned;
        }
        let span = (self.falloff_far - self.falloff_near).max(1e-3);
        let near = (1.0 - (from_eye - self.falloff_near) / span).clamp(0.0, 1.0);
        let factor = self.falloff_floor.max(near);
        ((factor - appear) / band).clamp(0.0, 1.0) * thinned
    }
}

/// The uniform every chunk shares in a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, ShaderType)]
pub(super) struct FrameUniform {
    /// Where the main camera is: shadow passes grow instances as it sees them, not as the
    /// light does.
    pub viewer: Vec3,
    /// 1 when any blade leans in the bend field.
    pub bends: u32,
    /// The bend field's min corner (x, z).
    pub bend_min: Vec2,
    /// 1 / the bend field's side.
    pub bend_scale: f32,
}

/// `value`'s bytes as a uniform buffer holds them.
pub(super) fn uniform_bytes<T: ShaderType + WriteInto>(value: &T) -> Vec<u8> {
    let mut buffer = UniformBuffer::new(Vec::new());
    buffer
        .write(value)
        .expect("a uniform of fixed size writes into a growable vector");
    buffer.into_inner()
}
