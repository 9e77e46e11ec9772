//! The impostor of a class: far instances drawn as camera-facing cards that show the class
//! as baked from its own mesh and material, seen from the nearest of several directions.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// Far instances of a class drawn as impostors: from `distance` to the camera on, each
/// instance is one camera-facing card showing the class's mesh and material as baked at
/// start-up (albedo and normals, so the scene's lights light it) from the nearest of
/// `views` directions around it in each of `rows` elevations, crossfading (dithered, as
/// Bevy's visibility ranges do) with the mesh over `crossfade` around `distance`.
///
/// A mesh class's entity instances are spawned only in chunks within reach of the
/// crossfade; farther ones are drawn from per-chunk instance buffers, so a forest costs one
/// instanced draw per chunk to the horizon instead of an entity per tree. An instanced
/// class's chunks draw both from one buffer, the meshes fading out as the cards fade in.
/// Impostors cast no shadow (far cascades rarely reach them) and stand upright (a class's
/// tilt is not applied).
///
/// In a layer file: `impostor: Some((distance: 400.0, crossfade: 40.0))`; fields left out
/// take [`Impostor::default`]'s values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, Reflect)]
#[serde(default, deny_unknown_fields)]
#[reflect(Clone, Debug, PartialEq, Default)]
pub struct Impostor {
    /// Distance from the camera (to an instance's root) where the impostor takes over.
    pub distance: f32,
    /// Width of the crossfade band centred on `distance`.
    pub crossfade: f32,
    /// Directions baked around the vertical axis (at least 3).
    pub views: u32,
    /// Elevations baked (at least 1): row `j` looks down at `j * 90 / rows` degrees.
    pub rows: u32,
    /// Texels along each side of one baked view (16 to 512).
    pub texels: u32,
}

impl Impostor {
    /// Impostors from `distance` on, crossfading over a tenth of it; 12 views in 3 rows of
    /// 128 texels.
    pub fn at(distance: f32) -> Self {
        Self {
            distance,
            crossfade: 0.1 * distance,
            views: 12,
            rows: 3,
            texels: 128,
        }
    }

    /// The crossfade band: where the mesh starts fading out and the impostor is whole.
    pub fn band(&self) -> (f32, f32) {
        let distance = self.distance.max(0.0);
        let half = (0.5 * self.crossfade).clamp(0.0, 0.99 * distance);
        (distance - half, distance + half)
    }

    /// The views, rows and texels the bake uses: the settings brought into their ranges.
    pub fn clamped(&self) -> (u32, u32, u32) {
        (
            self.views.clamp(3, 64),
            self.rows.clamp(1, 8),
            self.texels.clamp(16, 512).next_power_of_two(),
        )
    }
}

impl Default for Impostor {
    /// [`Impostor::at`] 300 metres.
    fn default() -> Self {
        Self::at(300.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_band_is_centred_on_the_distance_and_never_reaches_the_camera() {
        let i = Impostor::at(300.0);
        assert_eq!(i.band(), (285.0, 315.0));
        let wide = Impostor {
            crossfade: 1000.0,
            ..i
        };
        let (start, end) = wide.band();
        assert!(start > 0.0 && end < 600.0, "{start}..{end}");
        let odd = Impostor {
            views: 1,
            rows: 0,
            texels: 100,
            ..i
        };
        assert_eq!(odd.clamped(), (3, 1, 128));
    }
}
