//! Where an impostor atlas's views lie and what each covers, and the axes of a card facing
//! the eye: what the bake writes by and the cards read by.

use bevy::prelude::*;

/// Where the baked views lie in the atlas and what they cover: the uniform data a card
/// needs to show them.
#[derive(Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Clone, Debug, PartialEq)]
pub struct ImpostorFrames {
    /// Views around the vertical axis (columns of each half).
    pub views: u32,
    /// Elevations (rows).
    pub rows: u32,
    /// Texels along the side of one view.
    pub texels: u32,
    /// Centre of the mesh's bounds, where every view looks.
    pub center: Vec3,
    /// Half the width and half the height each view covers (world units at scale 1).
    pub half: Vec2,
}

impl ImpostorFrames {
    /// The direction (unit, from the mesh towards the eye) of view `i` in row `j`.
    pub fn direction(&self, i: u32, j: u32) -> Vec3 {
        let azimuth = i as f32 / self.views as f32 * std::f32::consts::TAU;
        let elevation = self.elevation(j);
        Vec3::new(
            elevation.cos() * azimuth.sin(),
            elevation.sin(),
            elevation.cos() * azimuth.cos(),
        )
    }

    /// Elevation of row `j`, radians.
    pub fn elevation(&self, j: u32) -> f32 {
        j as f32 * std::f32::consts::FRAC_PI_2 / self.rows as f32
    }

    /// The atlas's size in texels: both halves side by side.
    pub fn size(&self) -> UVec2 {
        UVec2::new(2 * self.views * self.texels, self.rows * self.texels)
    }
}

/// The right and up axes of a card facing `direction` (unit, towards the eye).
pub fn card_axes(direction: Vec3) -> (Vec3, Vec3) {
    let right = Vec3::Y.cross(direction);
    let right = if right.length_squared() < 1e-8 {
        Vec3::X
    } else {
        right.normalize()
    };
    (right, direction.cross(right))
}
