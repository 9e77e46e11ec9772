//! The instanced look: one mesh for every instance, shaded by the instanced pipeline.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// Whether an instanced class casts shadows, into every shadow map (directional cascades,
/// point and spot lights) of the lights that cast them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
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

/// How an instanced class is shaded: a blade-like gradient from root to tip, lit by the
/// scene's lights, with a hashed colour variation per instance.
#[derive(Clone, Debug, PartialEq)]
pub struct InstancedMaterial {
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
    /// How far instances lean where a [`Bender`](crate::instancing::Bender) passed, as a
    /// fraction of the field's lean (1 lays a blade flat where the field says so); 0 for
    /// instances that do not bend (pebbles).
    pub bend_response: f32,
}

impl Default for InstancedMaterial {
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
        }
    }
}

/// The look of an instanced class: one mesh drawn for every instance.
#[derive(Clone, Debug)]
pub struct InstancedLook {
    /// The mesh (positions required; normals used when present). Its local y is up: the
    /// root is its lowest point and the tip its highest.
    pub mesh: Handle<Mesh>,
    /// Its shading.
    pub material: InstancedMaterial,
}
