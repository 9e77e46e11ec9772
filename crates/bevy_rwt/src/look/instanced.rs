//! The instanced look: one mesh for every instance, shaded by the instanced pipeline.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// Whether an instanced class casts shadows, into every shadow map (directional cascades,
/// point and spot lights) of the lights that cast them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, Reflect)]
#[reflect(Clone, Debug, Default, PartialEq)]
pub enum InstancedShadows {
    /// No shadow: the class costs nothing in shadow passes.
    Off,
    /// Every drawn chunk casts (like a Bevy mesh).
    #[default]
    On,
    /// Chunks whose bounds come within this distance (world units) of a camera cast; far
    /// chunks cost nothing in shadow passes. Grass under the player's feet shades itself and
    /// the ground; grass a hundred metres away does not need to.
    Within(f32),
}

impl InstancedShadows {
    /// Whether a chunk `distance` from the nearest camera casts.
    pub fn casts_at(self, distance: f32) -> bool {
        match self {
            Self::Off => false,
            Self::On => true,
            Self::Within(reach) => distance <= reach,
        }
    }
}

/// Far thinning of an instanced class ([`InstancedShading::thinning`]): beyond `from`
/// metres from the camera the class keeps the fraction `(from / distance)^2` of its
/// instances, never less than `floor`: those of lowest rank, a blue-noise subset, the rest
/// shrinking away over the fade band. Each kept instance is widened (across, not up) by
/// the inverse of the fraction, so that the far field, seen from the side, covers as it did
/// while its instances fall in number as the pixels they cover. With culling per instance
/// ([`InstanceCulling`](crate::InstanceCulling)) the thinned instances cost nothing;
/// drawn whole, they are shrunk to nothing in the vertex shader.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct InstancedThinning {
    /// Distance from the camera where thinning starts (metres).
    pub from: f32,
    /// Smallest fraction kept (0..=1), which bounds the widening (a floor of 0.25 widens by
    /// up to 4).
    pub floor: f32,
}

impl InstancedThinning {
    /// Thinning from `from` metres, down to a quarter of the instances.
    pub fn from(from: f32) -> Self {
        Self { from, floor: 0.25 }
    }

    /// The fraction of instances kept `distance` metres from the camera.
    pub fn kept_at(&self, distance: f32) -> f32 {
        let ratio = self.from / distance.max(1e-3);
        (ratio * ratio).clamp(self.floor.clamp(1e-3, 1.0), 1.0)
    }
}

/// [`InstancedShading::alpha_cutoff`]'s default.
pub const DEFAULT_ALPHA_CUTOFF: f32 = 0.5;

/// How an instanced class is shaded: a blade-like gradient from root to tip, lit by the
/// scene's lights, with a hashed colour variation per instance. Not a Bevy `Material`: the
/// instanced renderer draws it with its own pipeline (see [`crate::instancing`]).
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, Default, PartialEq)]
pub struct InstancedShading {
    /// Colour at the root (the mesh's lowest point).
    pub base_color: Color,
    /// Colour at the tip (the mesh's highest point).
    pub tip_color: Color,
    /// Strength of the per-instance colour variation, hashed from its point (0..1).
    pub color_variation: f32,
    /// Perceptual roughness of the surface.
    pub roughness: f32,
    /// How far the tip sways in the wind, in mesh heights per unit of wind strength; 0 for
    /// rigid instances (pebbles).
    pub wind_response: f32,
    /// Width of the fade-in band, as a fraction of the level-of-detail factor: an instance
    /// grows from nothing to full size while the factor rises by this much past the one at
    /// which its point appears.
    pub fade_band: f32,
    /// Height fraction (0..1) below which the colour is the base colour; the tip colour
    /// blends in above it. 0 for grass (a gradient from root to tip); near 1 for flowers (a
    /// green stem under a coloured head).
    pub tip_from: f32,
    /// Whether the class casts shadows.
    pub shadows: InstancedShadows,
    /// A base-colour texture (with alpha), read at the mesh's first UV coordinates and
    /// multiplied by the root-to-tip colour (white `base_color` and `tip_color` show it as
    /// it is): flower heads, fern fronds, leaf cards. Where its alpha is below
    /// `alpha_cutoff` the instance is cut out, in every pass (shadows and prepasses too).
    /// The mesh needs `Mesh::ATTRIBUTE_UV_0`; the image one 2-D layer of a filterable colour
    /// format (otherwise an [`InstancedClassError`](crate::look::InstancedClassError)).
    pub texture: Option<Handle<Image>>,
    /// Alpha below which a textured instance is cut out (0..1).
    pub alpha_cutoff: f32,
    /// How far instances lean where a [`Bender`](crate::instancing::Bender) passed, as a
    /// fraction of the field's lean (1 lays a blade flat where the field says so); 0 for
    /// instances that do not bend (pebbles).
    pub bend_response: f32,
    /// Far thinning (`None`: every instance drawn at every distance).
    pub thinning: Option<InstancedThinning>,
}

impl Default for InstancedShading {
    fn default() -> Self {
        Self {
            base_color: Color::srgb(0.10, 0.22, 0.04),
            tip_color: Color::srgb(0.45, 0.62, 0.20),
            color_variation: 0.25,
            roughness: 0.8,
            wind_response: 0.25,
            fade_band: 0.1,
            tip_from: 0.0,
            shadows: InstancedShadows::default(),
            bend_response: 1.0,
            texture: None,
            alpha_cutoff: DEFAULT_ALPHA_CUTOFF,
            thinning: None,
        }
    }
}

/// The look of an instanced class: one mesh drawn for every instance.
#[derive(Clone, Debug, Reflect)]
#[reflect(Clone, Debug)]
pub struct InstancedLook {
    /// The mesh (positions required; normals used when present). Its local y is up: the
    /// root is its lowest point and the tip its highest.
    pub mesh: Handle<Mesh>,
    /// Its shading.
    pub material: InstancedShading,
    /// A cheaper mesh for far chunks, if any.
    pub far: Option<InstancedFar>,
}

/// The far level of detail of an instanced class: chunks whose bounds lie farther than
/// `distance` from every camera draw `mesh` instead of the class's (chosen per chunk, with
/// [`InstancedFar::HYSTERESIS`] against flicker at the boundary). The fade-in by rank keeps
/// growing and shrinking instances across the change.
///
/// Culled per instance on the GPU, each instance draws the mesh its own distance from the
/// view's eye calls for (a chunk across the distance draws both meshes), where the far mesh
/// is as tall as the class's (the shader's reference for colour and sway) and draws under
/// the same pipeline (the same vertex attributes, topology and index format), as
/// [`far_blade_mesh`](crate::look::far_blade_mesh) and [`blade_mesh`](crate::look::blade_mesh)
/// do.
#[derive(Clone, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct InstancedFar {
    /// The far mesh (same conventions as the class's: y up, root at its lowest point).
    pub mesh: Handle<Mesh>,
    /// Distance from the camera to a chunk's bounds (culled per instance: to an instance's
    /// root) from which it draws the far mesh.
    pub distance: f32,
}

impl InstancedFar {
    /// A chunk turns far beyond `distance * HYSTERESIS` and near again within
    /// `distance / HYSTERESIS`.
    pub const HYSTERESIS: f32 = 1.05;

    /// Whether a chunk `distance` from the nearest camera draws the far mesh, given whether
    /// it does now.
    pub fn is_far(&self, distance: f32, far_now: bool) -> bool {
        if far_now {
            distance > self.distance / Self::HYSTERESIS
        } else {
            distance > self.distance * Self::HYSTERESIS
        }
    }
}
